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

// A ray between steps: what the fragment path keeps in registers and the compute path
// saves in a storage buffer between dispatches (compute.comp). One step is one iteration;
// trace_ray takes steps until the ray is done, so both paths take the same steps.
#define RAY_LIVE 0
#define RAY_HIT 1
#define RAY_MISS 2
struct Ray {
    real tc[COMPONENT_SLOTS];   // free distance per component
    real sc[COMPONENT_SLOTS];   // binary: probe radius per component
    real ts, ds, w;             // relaxed: last verified point, its distance, ω
    real t;                     // the ray distance of the last step (the hit's, once hit)
    int iterations;
    int state;                  // RAY_LIVE, RAY_HIT or RAY_MISS
};

#define INITIAL_PROBE 1.0 // binary tracing's first probe radius (reference/trace.py)
#define MIN_PROBE 1e-30   // converged even where ε(t) = 0 (reference/trace.py)

Ray ray_begin(real start[COMPONENT_SLOTS]) {
    Ray r;
    r.tc = start;
    for (int c = 0; c < COMPONENT_SLOTS; ++c) r.sc[c] = INITIAL_PROBE;
    r.ts = start[0];
    r.ds = 0.0;
    r.w = real(u_relaxation);
    r.t = start[0];
    r.iterations = 0;
    r.state = RAY_LIVE;
    return r;
}

// The component that steps next and its free distance; false when the ray is done instead
// (a miss: the iteration cap, or past the far limit).
bool next_step(inout Ray r, out int c, out real t) {
    if (r.iterations >= u_max_iterations) { r.state = RAY_MISS; return false; }
    c = front(r.tc);
    t = r.tc[c];
    r.t = t;
    if (t > u_max_distance) { r.state = RAY_MISS; return false; }
    return true;
}

#ifdef KRS_TRACER_BINARY
// Probe the ball of radius s touching the free point t: free → advance 2s, grow s;
// blocked → converged if s ≤ ε(t), else shrink s (see reference/trace.py for why).
void ray_step(inout Ray r, vec3r origin, vec3r dir) {
    int c;
    real t;
    if (!next_step(r, c, t)) return;
    real s = r.sc[c];
    bool free = is_unbounding(c, origin + (t + s) * dir, s);
    ++r.iterations;
    if (free) {
        r.tc[c] = t + 2.0 * s;
        r.sc[c] = s * u_xi_bonus;
    } else {
        if (s <= max(u_eps_per_t * t * lod_scale(origin + t * dir), MIN_PROBE)) {
            r.state = RAY_HIT;
            return;
        }
        r.sc[c] = s * u_xi_penalty;
    }
}
#elif defined(KRS_TRACER_RELAXED)
// Over-relaxed sphere tracing [Keinert et al. 2014] of a single KRS: step ω·d from the last
// verified point (ts, ds); if the new free ball and the last one no longer cover [ts, t],
// go back to ts + ds and trace plainly (ω = 1). Twin of relaxed_trace in reference/trace.py.
void ray_step(inout Ray r, vec3r origin, vec3r dir) {
    if (r.iterations >= u_max_iterations) { r.state = RAY_MISS; return; }
    real t = r.t;
    if (t > u_max_distance) { r.state = RAY_MISS; return; }
    real d = component_distance(0, origin + t * dir);
    ++r.iterations;
    if (r.w > 1.0 && r.ds + d < t - r.ts) {
        r.t = r.ts + r.ds;
        r.w = 1.0;
        return;
    }
    if (d <= u_eps_per_t * t * lod_scale(origin + t * dir)) { r.state = RAY_HIT; return; }
    r.ts = t;
    r.ds = d;
    r.t = t + r.w * d;
}
#else
void ray_step(inout Ray r, vec3r origin, vec3r dir) {
    int c;
    real t;
    if (!next_step(r, c, t)) return;
    real d = component_distance(c, origin + t * dir);
    ++r.iterations;
    if (d <= u_eps_per_t * t * lod_scale(origin + t * dir)) { r.state = RAY_HIT; return; }
    r.tc[c] = t + d;
}
#endif

// The whole trace of one ray: steps until it hits, leaves or reaches the cap.
bool trace_ray(vec3r origin, vec3r dir, real start[COMPONENT_SLOTS], out real t,
               out int iterations) {
    Ray r = ray_begin(start);
    while (r.state == RAY_LIVE) ray_step(r, origin, dir);
    t = r.t;
    iterations = r.iterations;
    return r.state == RAY_HIT;
}

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
