// Sphere tracing [Har96] or binary sphere tracing [KRS17 Alg. 2], with the LOD threshold
// ε = footprint × t × ε-scale [KRS17 §4]; twin of reference/trace.py. One tracer and one
// geometry family are compiled in. Each component c keeps its own free distance t_c along
// the ray; the one with the least t_c takes the step, and the ray converges when that step
// does: at the nearest of the components' own hits [KRS17 §5.1]. Each t_c starts at
// start[c]: 0, or the pre-pass's free distance of the pixel's tile (prepass.glsl).
#ifdef KRS_MOBIUS
#include "mokrs.glsl"
#else
#include "distance.glsl"
#endif

// The component with the least free distance (ties: the first).
int front(real tc[COMPONENT_SLOTS]) {
    int f = 0;
    for (int c = 1; c < COMPONENTS; ++c) if (tc[c] < tc[f]) f = c;
    return f;
}

#ifdef KRS_TRACER_BINARY
#define INITIAL_PROBE 1.0
#define MIN_PROBE 1e-30   // converged even where ε(t) = 0 (reference/trace.py)

// Probe the ball of radius s touching the free point t: free → advance 2s, grow s;
// blocked → converged if s ≤ ε(t), else shrink s (see reference/trace.py for why).
bool trace_ray(vec3r origin, vec3r dir, real start[COMPONENT_SLOTS], out real t,
               out int iterations) {
    real tc[COMPONENT_SLOTS] = start, sc[COMPONENT_SLOTS];
    for (int c = 0; c < COMPONENT_SLOTS; ++c) sc[c] = INITIAL_PROBE;
    for (iterations = 0; iterations < u_max_iterations;) {
        int c = front(tc);
        t = tc[c];
        if (t > u_max_distance) return false;
        real s = sc[c];
        bool free = is_unbounding(c, origin + (t + s) * dir, s);
        ++iterations;
        if (free) {
            tc[c] = t + 2.0 * s;
            sc[c] = s * u_xi_bonus;
        } else {
            if (s <= max(u_eps_per_t * t * lod_scale(origin + t * dir), MIN_PROBE)) return true;
            sc[c] = s * u_xi_penalty;
        }
    }
    return false;
}
#elif defined(KRS_TRACER_RELAXED)
// Over-relaxed sphere tracing [Keinert et al. 2014] of a single KRS: step ω·d from the last
// verified point (ts, ds); if the new free ball and the last one no longer cover [ts, t],
// go back to ts + ds and trace plainly (ω = 1). Twin of relaxed_trace in reference/trace.py.
bool trace_ray(vec3r origin, vec3r dir, real start[COMPONENT_SLOTS], out real t,
               out int iterations) {
    real ts = start[0], ds = 0.0, w = u_relaxation;
    t = ts;
    for (iterations = 0; iterations < u_max_iterations;) {
        if (t > u_max_distance) return false;
        real d = component_distance(0, origin + t * dir);
        ++iterations;
        if (w > 1.0 && ds + d < t - ts) {
            t = ts + ds;
            w = 1.0;
            continue;
        }
        if (d <= u_eps_per_t * t * lod_scale(origin + t * dir)) return true;
        ts = t;
        ds = d;
        t += w * d;
    }
    return false;
}
#else
bool trace_ray(vec3r origin, vec3r dir, real start[COMPONENT_SLOTS], out real t,
               out int iterations) {
    real tc[COMPONENT_SLOTS] = start;
    for (iterations = 0; iterations < u_max_iterations;) {
        int c = front(tc);
        t = tc[c];
        if (t > u_max_distance) return false;
        real d = component_distance(c, origin + t * dir);
        ++iterations;
        if (d <= u_eps_per_t * t * lod_scale(origin + t * dir)) return true;
        tc[c] = t + d;
    }
    return false;
}
#endif

// The kernel level nearest to a hit point at ray distance t, the world normal there, and the
// point in that kernel's own space (for kernel texture coordinates).
void nearest_kernel(vec3r p, real t, out int level, out vec3 normal, out vec3 xk) {
#ifdef KRS_MOBIUS
    mokrs_nearest(p, level, normal);
    xk = vec3(p);
#else
    scene_nearest(p, t, level, normal, xk);
#endif
}
