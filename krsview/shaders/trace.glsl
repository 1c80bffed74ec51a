// Sphere tracing [Har96] or binary sphere tracing [KRS17 Alg. 2], with the LOD threshold
// ε = footprint × t × ε-scale [KRS17 §4]; twin of reference/trace.py. One tracer and one
// geometry family are compiled in. Each component c keeps its own free distance t_c along
// the ray; the one with the least t_c takes the step, and the ray converges when that step
// does: at the nearest of the components' own hits [KRS17 §5.1]. Each t_c starts at
// start[c]: 0, or the pre-pass's free distance of the pixel's tile (prepass.glsl).

// What the last KRS walk found nearest (krs.glsl sets both): the slot of the least of the
// kernels it tested (−1: not known), and the slot of the level-of-detail ball where that ball
// was nearer still (−1: none). A hit hands them to the shading, whose walk then tests no
// kernel above the ball (krs_nearest). The Ray packs both into one int, so that they fill a
// padding word of its std430 layout and the ray buffer keeps its size: each slot + 1, the
// ball's in the bits from 16 on.
int g_slot = -1, g_cut = -1;

int packed_slots() { return (g_slot + 1) | ((g_cut + 1) << 16); }

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
// trace_ray takes steps until the ray is done, so both paths take the same steps. Its
// fields are declared for Python in compile/std430.py (RAY), which sizes the buffer.
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
    vec3r wx;                   // walk restart: the anchor's folded point,
    int slots;                  // (a hit's packed_slots(), in wx's padding)
    vec3r wdir;                 // the ray's direction folded alike,
    real wt, wm, wd;            // its ray distance, fold margin and distance above,
    int wj;                     // and its level slot (−1: none; krs.glsl, krs_restart)
};

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
    r.slots = 0;  // none known
    r.wx = r.wdir = vec3r(0.0);
    r.wt = r.wm = r.wd = 0.0;
    r.wj = -1;
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

// The ray starting at `start`, and false where it is done before its first step (its
// pre-pass tile free past the far limit), left as ray_step would leave it: the pixels the
// free tiles' variant of render.frag writes, and persistent lanes skip (rays.glsl).
bool ray_starts_live(real start[COMPONENT_SLOTS], out Ray r) {
    r = ray_begin(start);
    int c;
    real t;
    return next_step(r, c, t);
}

#ifdef KRS_BALL_EXIT  // COMPONENT_BALL: distance.glsl
// What is left of component c ahead on a ray from o along dir, now at x = o + t dir with
// c's distance d there: a component that can no longer stop the ray (nor, on a shadow ray,
// lower its visibility) leaves it, and the ray is done once every one has left [issue 17].
// For every t' in [t, T] (T: the far limit), d(t') ≥ L(t') = max(d − (t' − t), near +
// g (t' − t)): the distance is 1-Lipschitz, and past c's ball (C, R) it is at least
// |x + (t' − t) dir − C| − R, which lies above its tangent (near = |x − C| − R, g =
// dir·(x − C)/|x − C|). The first bound falls, the second rises (g ≥ 0) or falls more
// slowly, so L is least at their crossing t* or at T, and L(t')/t' is least at t* or at T.
// Returns (min(L(t*), L(T)), t*, L(T)); without a ball or at t = 0, −1: nothing is known.
// near is computed in float, so it gives up the rounding of x − C. In the wind, (C, R) is the
// swept ball, and the first bound falls from D/m at the rate Λ/m (the stepped distance is
// not 1-Lipschitz): g moves the rest point by at most s·Λ, Λ = 1 + |a|ρ, for s along the ray,
// so the undistorted distance stays ≥ E = D − sΛ, and the step δ ≥ E / (1 + |a|(ρ + s + E))
// ≥ E / m, m = 1 + |a|(ρ + D/Λ + D), while E ≥ 0 (reference/wind.py, exit_fall).
vec3 bound_ahead(int c, vec3r x, real t, real d, vec3 dir) {
    vec4 ball = COMPONENT_BALL(c);
    float d0 = float(d), fall = 1.0;  // the first bound: d0 − fall·(t' − t)
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) {  // the swept ball, and the wind's first bound
        ball = u_wind_ball[c];
        vec3 w = g_wind_step;
        float lam = 1.0 + w.y * w.z, m = 1.0 + w.y * (w.z + w.x / lam + w.x);
        d0 = w.x / m;
        fall = lam / m;
    }
#endif
    vec3 v = vec3(x) - ball.xyz;
    float rho = length(v), g = dot(dir, v) / rho;
    float near = rho - ball.w - 1e-6 * (rho + length(vec3(x)));  // float rounding of x − C
    float t0 = float(t), T = u_max_distance;
    float ts = min(t0 + max(d0 - near, 0.0) / max(fall + g, 1e-6), T);
    float Ls = max(d0 - fall * (ts - t0), near + g * (ts - t0));
    float LT = max(d0 - fall * (T - t0), near + g * (T - t0));
    return ball.w < 0.0 || t <= 0.0 ? vec3(-1.0, 1.0, -1.0) : vec3(min(Ls, LT), ts, LT);
}

// Component c has left the ray; the ray is done once all have.
bool leave(inout real tc[COMPONENT_SLOTS], int c) {
    tc[c] = FAR_AWAY;
    return tc[front(tc)] > u_max_distance;
}
#endif

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
    if (d <= u_eps_per_t * t * lod_scale(origin + t * dir)) {
        r.state = RAY_HIT;
        r.slots = packed_slots();
        return;
    }
    r.ts = t;
    r.ds = d;
    r.t = t + r.w * d;
}
#else
#ifdef KRS_WALK_RESTART  // a single KRS, undistorted (uniforms.variant_defines)
// Alg. 1's value at p = origin + t·dir, the walk restarted below the ray's anchor where its
// folds cannot have changed (krs.glsl, krs_restart); `last`: the last step's length.
// `bounded`: only a lower bound (the levels above the anchor limit it), no hit test.
real restart_distance(inout Ray r, vec3r p, vec3r dir, real t, real last, out bool bounded) {
    ivec2 k = component(0);
    bool saved;
    real d = krs_restart(k.x, k.y, p, dir, t - r.wt, krs_lod(0, k.x, k.y, lod_radius(length(p))),
                         RESTART_KEEP * last, r.wj, r.wx, r.wdir, r.wm, r.wd, saved, bounded);
    if (saved) r.wt = t;
    return d;
}
#endif

void ray_step(inout Ray r, vec3r origin, vec3r dir) {
    int c;
    real t, before = r.t;
    if (!next_step(r, c, t)) return;
#ifdef KRS_WALK_RESTART  // a bounded step is no hit test: the next step walks from the top
    bool bounded;
    real d = restart_distance(r, origin + t * dir, dir, t, r.iterations > 0 ? t - before : FAR_AWAY,
                              bounded);
    ++r.iterations;
    if (!bounded && d <= u_eps_per_t * t * lod_scale(origin + t * dir)) {
        r.state = RAY_HIT;
        r.slots = packed_slots();
        return;
    }
#else
    real d = component_distance(c, origin + t * dir);
    ++r.iterations;
    if (d <= u_eps_per_t * t * lod_scale(origin + t * dir)) {
        r.state = RAY_HIT;
        r.slots = packed_slots();
        return;
    }
#endif
    r.tc[c] = t + d;
#if defined(KRS_BALL_EXIT) && !defined(KRS_COMPOUND)
    // c leaves once d(t') > ε(t') = ε_per_t t' all the way to T: a miss, found early (in a
    // compound the test cost more than it spared: grove 0.95×, docs/speed.md)
    vec3 b = bound_ahead(c, origin + t * dir, t, d, vec3(dir));
    if (min(b.x / b.y, b.z / u_max_distance) > u_eps_per_t && leave(r.tc, c)) {
        r.t = r.tc[front(r.tc)];
        r.state = RAY_MISS;
    }
#endif
}
#endif

// The whole trace of one ray: steps until it hits, leaves or reaches the cap; `slots`: the
// hit's packed_slots(), for nearest_kernel.
bool trace_ray(vec3r origin, vec3r dir, real start[COMPONENT_SLOTS], out real t,
               out int iterations, out int slots) {
    Ray r = ray_begin(start);
    while (r.state == RAY_LIVE) ray_step(r, origin, dir);
    t = r.t;
    iterations = r.iterations;
    slots = r.slots;
    return r.state == RAY_HIT;
}

// The kernel level nearest to a hit point at ray distance t, the world normal there, and the
// point in that kernel's own space (for kernel texture coordinates); `slots`: what the trace
// handed on (the Ray's packed_slots()).
void nearest_kernel(vec3r p, real t, int slots, out int level, out vec3 normal, out vec3 xk) {
#ifdef KRS_MOBIUS
    mokrs_nearest(p, level, normal);
    xk = vec3(p);
#else
    scene_nearest(p, t, (slots & 0xffff) - 1, (slots >> 16) - 1, level, normal, xk);
#endif
}
