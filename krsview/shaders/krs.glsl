// KRS distance [KRS17 Alg. 1] and nearest kernel with world normal [KRS14 §6.1];
// twin of reference/krs.py. Folding clips each level to its mirror's negative side.
#include "kernels.glsl"

// Reflect p if it lies behind mirror i (u·p − w > 0); returns whether it did.
bool fold(int i, inout vec3 p) {
    vec4 m = u_mirrors[i];
    float s = dot(p, m.xyz) - m.w;
    if (s > 0.0) { p -= 2.0 * s * m.xyz; return true; }
    return false;
}

float krs_distance(vec3 xw) {
    vec3 x = xw;
    float d = kernel_distance(u_n, x);
    for (int i = u_n - 1; i >= 0; --i) {
        fold(i, x);
        d = min(d, kernel_distance(i, x));
    }
    return d;
}

// Winning level j (ties to the coarser level) and the kernel gradient at x_j reflected back
// through every mirror that folded x at levels ≥ j (M_j first).
float krs_nearest(vec3 xw, out int level, out vec3 normal) {
    vec3 x = xw, xk = xw;
    float d = kernel_distance(u_n, x);
    level = u_n;
    uint flips[2] = uint[2](0u, 0u);
    for (int i = u_n - 1; i >= 0; --i) {
        if (fold(i, x)) flips[i >> 5] |= 1u << uint(i & 31);
        float di = kernel_distance(i, x);
        if (di < d) { d = di; level = i; xk = x; }
    }
    vec3 g = kernel_gradient(level, xk);
    for (int i = level; i < u_n; ++i) {
        if ((flips[i >> 5] & (1u << uint(i & 31))) != 0u) {
            vec3 u = u_mirrors[i].xyz;
            g -= 2.0 * dot(g, u) * u;
        }
    }
    normal = g;
    return d;
}

#ifdef KRS_TRACER_BINARY
// A ball is free of the KRS when the distance bound at its centre covers it.
bool is_unbounding(vec3 center, float radius) { return krs_distance(center) >= radius; }
#endif
