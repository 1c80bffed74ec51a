// Kernel distances k_i and gradients [KRS17 §3, §9.2]; twin of reference/kernels.py.
// Sphere, capsule, toroidal capsule = point, segment, arc swept by a ball of radius r:
// k(p) = |p - core(p)| - r never overshoots. Only the types a scene uses are compiled in.
#define TWO_PI 6.283185307179586

vec4 kernel_rec(int i, int k) { return u_kernels[i * KRS_RECORD + k]; }

#ifdef KRS_KERNEL_CAPSULE
vec3 capsule_core(int i, vec3 p) {
    vec3 a = kernel_rec(i, 1).xyz, ab = kernel_rec(i, 2).xyz - a;
    float h = clamp(dot(p - a, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
    return a + h * ab;
}
#endif

#ifdef KRS_KERNEL_TOROIDAL_CAPSULE
// Angle of p around the arc centre in [0, 2π), measured from e1 towards e2.
float arc_angle(vec3 q, vec3 e1, vec3 e2) {
    float a = atan(dot(q, e2), dot(q, e1));
    return a < 0.0 ? a + TWO_PI : a;
}

float toroidal_capsule_distance(int i, vec3 p) {
    vec4 c = kernel_rec(i, 3), e1 = kernel_rec(i, 4);
    vec3 e2 = kernel_rec(i, 5).xyz, q = p - c.xyz;
    float x = dot(q, e1.xyz), y = dot(q, e2);
    float z2 = max(dot(q, q) - x * x - y * y, 0.0);
    float d = min(length(p - kernel_rec(i, 1).xyz), length(p - kernel_rec(i, 2).xyz));
    if (arc_angle(q, e1.xyz, e2) <= e1.w) {
        float ring = length(vec2(x, y)) - c.w;
        d = min(d, sqrt(ring * ring + z2));
    }
    return d - kernel_rec(i, 1).w;
}

vec3 toroidal_capsule_core(int i, vec3 p) {
    vec4 c = kernel_rec(i, 3), e1 = kernel_rec(i, 4);
    vec3 e2 = kernel_rec(i, 5).xyz, q = p - c.xyz;
    vec3 A = kernel_rec(i, 1).xyz, B = kernel_rec(i, 2).xyz;
    float a = arc_angle(q, e1.xyz, e2);
    float dA = length(p - A), dB = length(p - B);
    vec3 best = dA <= dB ? A : B;
    if (a <= e1.w) {
        vec3 on_arc = c.xyz + c.w * (cos(a) * e1.xyz + sin(a) * e2);
        if (length(p - on_arc) < min(dA, dB)) best = on_arc;
    }
    return best;
}
#endif

float kernel_distance(int i, vec3 p) {
    int type = int(kernel_rec(i, 0).w);
#ifdef KRS_KERNEL_SPHERE
    if (type == KERNEL_SPHERE) return length(p - kernel_rec(i, 1).xyz) - kernel_rec(i, 1).w;
#endif
#ifdef KRS_KERNEL_CAPSULE
    if (type == KERNEL_CAPSULE) return length(p - capsule_core(i, p)) - kernel_rec(i, 1).w;
#endif
#ifdef KRS_KERNEL_TOROIDAL_CAPSULE
    if (type == KERNEL_TOROIDAL_CAPSULE) return toroidal_capsule_distance(i, p);
#endif
#ifdef KRS_KERNEL_PLANE
    if (type == KERNEL_PLANE) return dot(p, kernel_rec(i, 1).xyz) - kernel_rec(i, 1).w;
#endif
    return FAR_AWAY;  // empty kernel
}

vec3 kernel_gradient(int i, vec3 p) {
    int type = int(kernel_rec(i, 0).w);
    vec3 core = p;
#ifdef KRS_KERNEL_PLANE
    if (type == KERNEL_PLANE) return kernel_rec(i, 1).xyz;
#endif
#ifdef KRS_KERNEL_SPHERE
    if (type == KERNEL_SPHERE) core = kernel_rec(i, 1).xyz;
#endif
#ifdef KRS_KERNEL_CAPSULE
    if (type == KERNEL_CAPSULE) core = capsule_core(i, p);
#endif
#ifdef KRS_KERNEL_TOROIDAL_CAPSULE
    if (type == KERNEL_TOROIDAL_CAPSULE) core = toroidal_capsule_core(i, p);
#endif
    vec3 g = p - core;
    float len = length(g);
    return len > 0.0 ? g / len : vec3(0.0, 0.0, 1.0);
}
