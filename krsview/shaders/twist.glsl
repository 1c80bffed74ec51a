// Twist around a vertical axis, a Lipschitz distance distortion [KRS17 §5.2, Har96];
// twin of reference/distortion.py. The axis passes through u_twist_center (camera-relative);
// a point at height h above it is turned by u_twist · h radians.
uniform float u_twist;         // radians per unit height
uniform vec3 u_twist_center;

vec2r turn(vec2r v, float a) {
    real c = cos(a), s = sin(a);
    return vec2r(v.x * c - v.y * s, v.x * s + v.y * c);
}

// g = f⁻¹: where the untwisted geometry is looked up for the world point p.
vec3r untwist(vec3r p) {
    vec3r r = p - u_twist_center;
    return u_twist_center + vec3r(turn(r.xz, -u_twist * float(r.y)), r.y).xzy;
}

// A safe step from the untwisted distance D: ‖Dg‖ ≤ 1 + |k|ρ at axis distance ρ, so over the
// ball of radius δ around p it is ≤ 1 + |k|(ρ + δ); δ(1 + |k|ρ + |k|δ) = D is solved by
// distance.glsl's safe_step.
real twist_step(vec3r p, real D) {
    return safe_step(D, abs(u_twist), length(p.xz - u_twist_center.xz));
}

// World normal from the gradient g at q = g(p): Dgᵀ g; only Dg's y column is not a rotation.
vec3 twist_normal(vec3 p, vec3 q, vec3 g) {
    vec3 r = p - u_twist_center, s = q - u_twist_center;
    float a = -u_twist * r.y;
    vec2 gxz = turn(g.xz, -a);   // Rᵀ g on the horizontal part
    float gy = g.y - u_twist * dot(vec2(-s.z, s.x), g.xz);
    return normalize(vec3(gxz.x, gy, gxz.y));
}
