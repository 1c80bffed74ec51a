// Sphere tracing [Har96] or binary sphere tracing [KRS17 Alg. 2], with the LOD threshold
// ε = footprint × t × ε-scale [KRS17 §4]; twin of reference/trace.py. One tracer and one
// geometry family are compiled in.
#ifdef KRS_MOBIUS
#include "mokrs.glsl"
#else
#include "distance.glsl"
#endif

#ifdef KRS_TRACER_BINARY
#define INITIAL_PROBE 1.0

// Probe the ball of radius s touching the free point t: free → advance 2s, grow s;
// blocked → converged if s ≤ ε(t), else shrink s (see reference/trace.py for why).
bool trace_ray(vec3 origin, vec3 dir, out float t, out int iterations) {
    t = 0.0;
    float s = INITIAL_PROBE;
    for (iterations = 0; iterations < u_max_iterations;) {
        bool free = is_unbounding(origin + (t + s) * dir, s);
        ++iterations;
        if (free) {
            t += 2.0 * s;
            s *= u_xi_bonus;
            if (t > u_max_distance) return false;
        } else {
            if (s <= u_eps_per_t * t) return true;
            s *= u_xi_penalty;
        }
    }
    return false;
}
#else
bool trace_ray(vec3 origin, vec3 dir, out float t, out int iterations) {
    t = 0.0;
    for (iterations = 0; iterations < u_max_iterations;) {
        float d = scene_distance(origin + t * dir);
        ++iterations;
        if (d <= u_eps_per_t * t) return true;
        t += d;
        if (t > u_max_distance) return false;
    }
    return false;
}
#endif

// The kernel level nearest to a hit point at ray distance t, the world normal there, and the
// point in that kernel's own space (for kernel texture coordinates).
void nearest_kernel(vec3 p, float t, out int level, out vec3 normal, out vec3 xk) {
#ifdef KRS_MOBIUS
    mokrs_nearest(p, level, normal);
    xk = p;
#else
    scene_nearest(p, t, level, normal, xk);
#endif
}
