// Kernel distances k_i and gradients [KRS17 §3, §9.2]; twin of reference/kernels.py.
// Sphere, capsule, toroidal capsule = point, segment, arc swept by a ball of radius r:
// k(p) = |p - core(p)| - r never overshoots. Only the types a scene uses are compiled in.
vec4r kernel_rec(int i, int k) { return u_kernels[i * RECORD_VEC4 + k]; }
vec4 kernel_rec_float(int i, int k) { return vec4(kernel_rec(i, k)); }  // for shading

#ifdef KRS_KERNEL_CAPSULE
vec3r capsule_core(int i, vec3r p) {
    vec3r a = kernel_rec(i, 1).xyz, ab = kernel_rec(i, 2).xyz - a;
    real h = clamp(dot(p - a, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
    return a + h * ab;
}
#endif

#ifdef KRS_KERNEL_TOROIDAL_CAPSULE
// Is the angle of (x, y) from e1 towards e2 within [0, phi]? y = ρ sin a and
// s = x sin phi − y cos phi = ρ sin(phi − a); no trigonometry (twin of in_wedge).
bool in_wedge(int i, real x, real y) {
    real cos_phi = kernel_rec(i, 4).w, sin_phi = kernel_rec(i, 5).w;
    real s = x * sin_phi - y * cos_phi;
    return sin_phi >= 0.0 ? (y >= 0.0 && s >= 0.0) : (y >= 0.0 || s >= 0.0);
}

// In the arc's frame (x, y along e1, e2, z along their normal n), |p − core(p)|² = z² + w,
// where w is the squared distance in the arc's plane: to the circle inside the wedge (the arc
// is nearer than its ends there), else to the nearer end A = (R, 0), B = R (cos phi, sin phi).
// Two square roots in all; z comes from n, not from |q|² − x² − y², so no cancellation.
real toroidal_capsule_distance(int i, vec3r p) {
    vec4r c = kernel_rec(i, 3), f1 = kernel_rec(i, 4), f2 = kernel_rec(i, 5);
    vec3r q = p - c.xyz;
    real x = dot(q, f1.xyz), y = dot(q, f2.xyz), z = dot(q, cross(f1.xyz, f2.xyz));
    real w;
    if (in_wedge(i, x, y)) {
        real ring = length(vec2r(x, y)) - c.w;
        w = ring * ring;
    } else {
        vec2r a = vec2r(x - c.w, y), b = vec2r(x, y) - c.w * vec2r(f1.w, f2.w);
        w = min(dot(a, a), dot(b, b));
    }
    return sqrt(w + z * z) - kernel_rec(i, 1).w;
}

vec3r toroidal_capsule_core(int i, vec3r p) {
    vec4r c = kernel_rec(i, 3);
    vec3r e1 = kernel_rec(i, 4).xyz, e2 = kernel_rec(i, 5).xyz, q = p - c.xyz;
    real x = dot(q, e1), y = dot(q, e2), rho = length(vec2r(x, y));
    if (in_wedge(i, x, y))
        return c.xyz + c.w * (rho > 0.0 ? (x * e1 + y * e2) / rho : e1);
    vec3r A = kernel_rec(i, 1).xyz, B = kernel_rec(i, 2).xyz;
    return dot(p - A, p - A) <= dot(p - B, p - B) ? A : B;
}
#endif

// k_i(p) where kernel i is one of the kinds in the bit mask `kinds` (bit KERNEL_*, the empty
// kernel's included): the mask is a constant at each call, so no other kind's code is
// compiled there, and where it holds a single kind the type is not even read. llvmpipe runs
// every branch's code whether any pixel takes it or not (docs/speed.md): Alg. 1's level
// loop, which meets only the branches' kinds, no longer pays for the trunk's kind.
#define KERNEL_BIT(type) (1 << (type))
#ifndef KRS_TOP_KERNELS           // the kinds of each component's top kernel K_n (gpu/uniforms.py)
#define KRS_TOP_KERNELS (~0)
#endif
#ifndef KRS_LEVEL_KERNELS         // the kinds of the kernels below it, K_0..K_{n-1}
#define KRS_LEVEL_KERNELS (~0)
#endif
#define KIND_IS(kind) ((kinds & KERNEL_BIT(kind)) != 0 && \
                       (kinds == KERNEL_BIT(kind) || type == (kind)))
real kernel_distance_of(int i, vec3r p, int kinds) {
    int type = int(kernel_rec(i, 0).w);
#ifdef KRS_KERNEL_SPHERE
    if (KIND_IS(KERNEL_SPHERE)) return length(p - kernel_rec(i, 1).xyz) - kernel_rec(i, 1).w;
#endif
#ifdef KRS_KERNEL_CAPSULE
    if (KIND_IS(KERNEL_CAPSULE)) return length(p - capsule_core(i, p)) - kernel_rec(i, 1).w;
#endif
#ifdef KRS_KERNEL_TOROIDAL_CAPSULE
    if (KIND_IS(KERNEL_TOROIDAL_CAPSULE)) return toroidal_capsule_distance(i, p);
#endif
#ifdef KRS_KERNEL_PLANE
    if (KIND_IS(KERNEL_PLANE)) return dot(p, kernel_rec(i, 1).xyz) - kernel_rec(i, 1).w;
#endif
    return FAR_AWAY;  // empty kernel
}
#undef KIND_IS

// Any kind the scene uses.
real kernel_distance(int i, vec3r p) { return kernel_distance_of(i, p, ~0); }

vec3r kernel_gradient(int i, vec3r p) {
    int type = int(kernel_rec(i, 0).w);
    vec3r core = p;
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
    vec3r g = p - core;
    real len = length(g);
    return len > 0.0 ? g / len : vec3r(0.0, 0.0, 1.0);
}
