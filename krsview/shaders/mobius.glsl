// Möbius transformations H_i = G_i⁻¹ of the MöKRS levels [KRS17 §6.2, App. C]; twin of
// algebra/mobius.py (apply, map_ball, gradient). Record per level: a, b, c, d, then
// (pole.xyz, flags) with a pole, or (|a|/|d|, 0, 0, flags) for a similarity (c = 0);
// flags = has_pole + 2 · reflects; then the level's bounding ball (centre, radius; radius < 0:
// unbounded), in the level's own space (compile/mokrs.py, level_bounds).
#include "quaternion.glsl"

vec4r mobius_rec(int i, int k) { return u_mobius[i * MOBIUS_RECORD + k]; }

// L_H(p) = (a p + b)(c p + d)⁻¹ (Eq. 1).
vec3r mobius_apply(int i, vec3r p) {
    vec4r q = qpure(p);
    vec4r num = qmul(mobius_rec(i, 0), q) + mobius_rec(i, 1);
    vec4r den = qmul(mobius_rec(i, 2), q) + mobius_rec(i, 3);
    return qmul(num, qinv(den)).yzw;
}

// The image of a ball under L_H, from the diameter on the line through the pole (it maps
// to a diameter of the image); false if the ball holds the pole: then the image is the
// exterior of the returned ball.
// Float32-safe, unlike App. A's ρ² = |κ|² − γ. A similarity needs only the centre.
bool map_ball(int i, inout vec3r center, inout real radius) {
    vec4r pf = mobius_rec(i, 4);
    if ((int(pf.w) & 1) == 0) {  // a similarity: one point and a scale
        center = mobius_apply(i, center);
        radius *= pf.x;
        return true;
    }
    vec3r off = center - pf.xyz;
    real dist = length(off);
    bool outside = dist > radius;
    vec3r u = dist > 0.0 ? off / dist : vec3r(1.0, 0.0, 0.0);  // centred pole: any diameter
    vec3r x1 = mobius_apply(i, center + radius * u), x2 = mobius_apply(i, center - radius * u);
    center = 0.5 * (x1 + x2);
    radius = 0.5 * length(x1 - x2);
    return outside;
}

// dL_H at p as a matrix: columns (a − L_H(p) c) e_k (cp + d)⁻¹ [KRS17 App. C, Eq. 3].
mat3r mobius_jacobian(int i, vec3r p, vec3r image) {
    vec4r left = mobius_rec(i, 0) - qmul(qpure(image), mobius_rec(i, 2));
    vec4r right = qinv(qmul(mobius_rec(i, 2), qpure(p)) + mobius_rec(i, 3));
    return mat3r(qmul(qmul(left, vec4r(0, 1, 0, 0)), right).yzw,
                 qmul(qmul(left, vec4r(0, 0, 1, 0)), right).yzw,
                 qmul(qmul(left, vec4r(0, 0, 0, 1)), right).yzw);
}
