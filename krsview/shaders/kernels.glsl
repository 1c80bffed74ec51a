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
// The arc's record (compile/krs.py): O and r, the quaternion P of its frame [e1 e2 n] (e1 the
// arc's bisector) scaled to |P|² = 1/R, and t = tan(phi/4). Alg. 1's level reads these 9
// numbers: on llvmpipe each is a gather that costs more than all the arithmetic here.

// P̄ q P: the offset q from O in the arc's frame, in units of R (twin of arc_local).
vec3r arc_local(vec4r P, vec3r q) {
    return (P.x * P.x - dot(P.yzw, P.yzw)) * q + 2.0 * dot(P.yzw, q) * P.yzw
           + 2.0 * P.x * cross(q, P.yzw);
}

// Its inverse: frame coordinates v in units of R as a world offset R·F v from O.
vec3r arc_world(vec4r P, vec3r v) {
    real k = dot(P, P);
    return arc_local(vec4r(P.x, -P.yzw), v) / (k * k);  // P v P̄: the sandwich by P̄
}

// cos and sin of phi/2 from t = tan(phi/4), rational and so accurate for every arc.
vec2r arc_half_angle(int i) {
    real t = kernel_rec(i, 3).x;
    return vec2r(1.0 - t * t, 2.0 * t) / (1.0 + t * t);
}

// Within phi/2 of the bisector: cos a = x/ρ ≥ cos(phi/2), one test for every arc angle.
bool in_wedge(real x, real rho, real c) { return x >= rho * c; }

// In the arc's frame (units of R) |p − core(p)|² = z² + w, w the squared distance in the
// arc's plane: to the unit circle inside the wedge (the arc is nearer than its ends there),
// else to the end on p's side, (c, ±s). Two square roots; z comes from the frame, not from
// |q|² − x² − y², so no cancellation.
real toroidal_capsule_distance(int i, vec3r p) {
    vec4r o = kernel_rec(i, 1), P = kernel_rec(i, 2);
    vec3r a = arc_local(P, p - o.xyz);
    vec2r cs = arc_half_angle(i);
    real rho = length(a.xy), w;
    if (in_wedge(a.x, rho, cs.x)) {
        w = (rho - 1.0) * (rho - 1.0);
    } else {
        vec2r e = vec2r(a.x, abs(a.y)) - cs;
        w = dot(e, e);
    }
    return sqrt(w + a.z * a.z) / dot(P, P) - o.w;
}

vec3r toroidal_capsule_core(int i, vec3r p) {
    vec4r o = kernel_rec(i, 1), P = kernel_rec(i, 2);
    vec3r a = arc_local(P, p - o.xyz);
    vec2r cs = arc_half_angle(i);
    real rho = length(a.xy);
    vec2r on = in_wedge(a.x, rho, cs.x) ? (rho > 0.0 ? a.xy / rho : vec2r(1.0, 0.0))
                                        : vec2r(cs.x, a.y >= 0.0 ? cs.y : -cs.y);
    return o.xyz + arc_world(P, vec3r(on, 0.0));
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
