// Shadow rays [KRS17 §8.5]: hard (blocked or not), or soft, where the smallest free distance
// met along the ray, as a fraction k·free/t of the distance travelled, sets the penumbra
// (Fig. 11); twin of reference/occlusion.py. A KRS is sphere traced along the shadow ray
// (a compound with one free distance per component), a MöKRS probed with unbounding balls
// (its free distances are the free probe radii). With the shadow cone (render.shadow_cone),
// a component is stepped only from where its bounds meet the ray's cone (cone_entry).
uniform float u_shadow_softness;  // k
#ifdef KRS_COUNT_LEVELS
int g_shadow_steps = 0;    // steps of this invocation's shadow rays (bench split's measure)
int g_shadow_levels = 0;   // and the levels Alg. 1 walked in them
#endif

bool soft_shadows_on() {
#ifdef KRS_SOFT_SHADOWS
    return EFFECT_ON(KRS_SOFT_SHADOWS_BIT);
#else
    return false;
#endif
}

bool shadows_on() {
#ifdef KRS_SHADOWS
    if (EFFECT_ON(KRS_SHADOWS_BIT)) return true;
#endif
    return soft_shadows_on();
}

// A shadow ray between steps: what shadow_visibility keeps in registers and the compute
// path's shadow tasks keep in a storage buffer between rounds (compute.comp), so both take
// the same steps and reach the same visibility. Declared for Python in compile/std430.py
// (SHADOW).
#define SHADOW_LIVE 0
#define SHADOW_DONE 1
struct Shadow {
    vec4r o;                    // xyz: the start, lifted SHADOW_OFFSET ε off the surface
    vec4 l;                     // xyz: towards the light; w: ε, the primary ray's threshold
    real tc[COMPONENT_SLOTS];   // KRS: free distance per component; MöKRS: tc[0] only
    real s;                     // MöKRS: the probe radius
    float vis;                  // visibility so far (0 once blocked)
    int iterations;
    int state;                  // SHADOW_LIVE or SHADOW_DONE
};

#ifdef KRS_SHADOW_CONE  // bounded KRS components (uniforms.variant_defines)
#ifdef KRS_COMPOUND  // per component: a half-space u·x ≤ w holding it (u = 0: none)
uniform vec4 u_half_space[COMPONENT_SLOTS];
#define COMPONENT_HALF_SPACE(c) u_half_space[c]
#else
uniform vec4 u_half_space;
#define COMPONENT_HALF_SPACE(c) u_half_space
#endif

// Where the shadow ray o + t l first meets component c: the least t ≥ 0 at which c's ball or
// half-space, grown by ε, meets the cone of radius slope·t about the ray (slope 1/k for a
// soft shadow, 0 for a hard one); FAR_AWAY if neither does before the far limit. Before it
// c's distance exceeds ε + slope·t, so c can neither block the ray (d ≤ ε) nor lower its
// visibility (k·d/t > 1), and the ray need not step it from 0. Ball: |o + t l − C| ≤
// R + slope·t, a quadratic in t whose smaller root is taken cancellation-free; half-space:
// u·o − w + (u·l) t ≤ ε + slope·t. Each bound alone certifies the ray up to its own entry,
// so the later of the two is taken. Float: both give up the rounding of o's offsets, as
// bound_ahead's near does (twin: reference/occlusion.py, cone_entry).
real cone_entry(int c, vec3 o, vec3 l, float eps, float slope) {
    float t0 = 0.0, T = u_max_distance;
    vec4 ball = COMPONENT_BALL(c);
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) ball = u_wind_ball[c];  // the swept ball, as bound_ahead
#endif
    vec3 v = o - ball.xyz;
    float R = ball.w + eps + 1e-6 * (length(v) + length(o));
    float a = 1.0 - slope * slope, b = dot(l, v) - R * slope, q = dot(v, v) - R * R;
    float disc = b * b - a * q;
    if (ball.w >= 0.0 && q > 0.0 && a > 0.0)  // o outside the grown ball, a cone under 45°
        t0 = b >= 0.0 || disc < 0.0 ? FAR_AWAY : q / (sqrt(disc) - b);
    vec4 h = COMPONENT_HALF_SPACE(c);
    float s = dot(h.xyz, o) - h.w - eps - 1e-6 * (length(o) + abs(h.w)), g = dot(h.xyz, l) - slope;
    if (s > 0.0) t0 = max(t0, g >= 0.0 ? FAR_AWAY : s / -g);
    return t0 > T ? FAR_AWAY : real(t0);
}
#endif

// The shadow ray from the hit point p with normal n towards the light l; with the shadow
// cone each component's free distance starts at its cone_entry, and a ray that meets none
// is done before its first step.
Shadow shadow_begin(vec3r p, vec3 n, vec3 l, float eps) {
    Shadow sh;
    sh.o = vec4r(p + SHADOW_OFFSET * eps * n, 0.0);
    sh.l = vec4(l, eps);
    for (int c = 0; c < COMPONENT_SLOTS; ++c) sh.tc[c] = 0.0;
    sh.s = INITIAL_PROBE;
    sh.vis = 1.0;
    sh.iterations = 0;
    sh.state = SHADOW_LIVE;
#ifdef KRS_SHADOW_CONE
    float slope = soft_shadows_on() ? 1.0 / u_shadow_softness : 0.0;
    for (int c = 0; c < COMPONENT_SLOTS; ++c)
        sh.tc[c] = c < COMPONENTS ? cone_entry(c, vec3(sh.o.xyz), l, eps, slope) : FAR_AWAY;
    if (sh.tc[front(sh.tc)] > u_max_distance) sh.state = SHADOW_DONE;
#endif
    return sh;
}

// One iteration of a live shadow ray; done at the cap, past the far limit, blocked, or once
// every component has left it (bound_ahead in trace.glsl).
void shadow_step(inout Shadow sh) {
    if (sh.iterations >= u_max_iterations) { sh.state = SHADOW_DONE; return; }
    ++sh.iterations;
    bool soft = soft_shadows_on();
    vec3r o = sh.o.xyz;
    vec3 l = sh.l.xyz;
    float eps = sh.l.w;
#ifdef KRS_MOBIUS
    real t = sh.tc[0], s = sh.s;
    if (is_unbounding(0, o + (t + s) * l, s)) {
        if (soft) sh.vis = min(sh.vis, u_shadow_softness * float(s / (t + s)));
        sh.tc[0] = t + 2.0 * s;
        sh.s = s * u_xi_bonus;
        if (sh.tc[0] > u_max_distance) sh.state = SHADOW_DONE;
    } else {
        if (s <= max(eps, MIN_PROBE)) { sh.vis = 0.0; sh.state = SHADOW_DONE; return; }
        sh.s = s * u_xi_penalty;
    }
#else
    int c = front(sh.tc);
    real t = sh.tc[c];
    if (t > u_max_distance) { sh.state = SHADOW_DONE; return; }
    real d = component_distance(c, o + t * l);
    if (d <= eps * lod_scale(o + t * l)) { sh.vis = 0.0; sh.state = SHADOW_DONE; return; }
    if (soft && t > 0.0) sh.vis = min(sh.vis, u_shadow_softness * float(d / t));
    sh.tc[c] = t + d;
#ifdef KRS_BALL_EXIT
    // c leaves once it can neither block (L > ε) nor lower the visibility (vis only falls)
    vec3 b = bound_ahead(c, o + t * l, t, d, l);
    if (b.x > eps && (!soft || u_shadow_softness * min(b.x / b.y, b.z / u_max_distance)
                               >= sh.vis) && leave(sh.tc, c))
        sh.state = SHADOW_DONE;
#endif
#endif
}

// Visibility in [0, 1] of the light in direction l from the hit point p with normal n, where
// the primary ray stopped at threshold eps; the shadow ray stops at the same threshold.
float shadow_visibility(vec3r p, vec3 n, vec3 l, float eps) {
    Shadow sh = shadow_begin(p, n, l, eps);
#ifdef KRS_COUNT_LEVELS
    int levels = g_levels;
#endif
    while (sh.state == SHADOW_LIVE) shadow_step(sh);
#ifdef KRS_COUNT_LEVELS
    g_shadow_steps += sh.iterations;
    g_shadow_levels += g_levels - levels;
#endif
    return sh.vis;
}

// The entry of a list that pixel p of a pass `width` pixels wide (a multiple of 4) traces:
// eight consecutive entries to each 4 × 2 group of pixels, the lanes llvmpipe runs in
// lockstep, so that a group's rays are neighbours (gpu/passes.py, packed).
uint packed_index(ivec2 p, int width) {
    return uint(((p.y >> 1) * (width >> 2) + (p.x >> 2)) * 8 + (p.y & 1) * 4 + (p.x & 3));
}

#if defined(KRS_SHADOW_TASKS) || defined(KRS_SHADOW_UPSAMPLED)
float g_shadow[MAX_LIGHTS];    // the compute path: each light's visibility, traced as tasks
                               // (compute.comp) and loaded by deferred.frag before shading;
                               // the viewer's: upsampled by upsampled.frag (< 0: none)
#endif
#ifdef KRS_SHADOW_MARK
bool g_outline = false;        // a lit light that no block gave a visibility: upsampled.frag
                               // lists the pixel for the outline pass, which traces its ray
#endif

// The visibility of light k that shade() multiplies in. With KRS_SHADOW_MARK no shadow ray
// is compiled in (llvmpipe runs every branch's code for every pixel): a light without a
// block's visibility marks the pixel instead, and the colour it gets here is replaced.
float light_visibility(int k, vec3r p, vec3 n, float eps) {
#ifdef KRS_SHADOW_TASKS
    return g_shadow[k];
#else
#ifdef KRS_SHADOW_UPSAMPLED
    if (g_shadow[k] >= 0.0) return g_shadow[k];
#endif
#ifdef KRS_SHADOW_MARK
    g_outline = true;
    return 1.0;
#else
    return shadow_visibility(p, n, u_light_dir[k], eps);
#endif
#endif
}
