// Shadow rays [KRS17 §8.5]: hard (blocked or not), or soft, where the smallest free distance
// met along the ray, as a fraction k·free/t of the distance travelled, sets the penumbra
// (Fig. 11); twin of reference/occlusion.py. A KRS is sphere traced along the shadow ray
// (a compound with one free distance per component), a MöKRS probed with unbounding balls
// (its free distances are the free probe radii).
uniform float u_shadow_softness;  // k
#define SHADOW_OFFSET 2.0         // the ray starts this many ε off the surface, along the normal

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

// Visibility in [0, 1] of the light in direction l from the hit point p with normal n, where
// the primary ray stopped at threshold eps; the shadow ray stops at the same threshold.
float shadow_visibility(vec3r p, vec3 n, vec3 l, float eps) {
    bool soft = soft_shadows_on();
    vec3r o = p + SHADOW_OFFSET * eps * n;
    float vis = 1.0;
    real t = 0.0;
#ifdef KRS_MOBIUS
    real s = INITIAL_PROBE;
    for (int i = 0; i < u_max_iterations; ++i) {
        if (is_unbounding(0, o + (t + s) * l, s)) {
            if (soft) vis = min(vis, u_shadow_softness * float(s / (t + s)));
            t += 2.0 * s;
            s *= u_xi_bonus;
            if (t > u_max_distance) break;
        } else {
            if (s <= max(eps, MIN_PROBE)) return 0.0;
            s *= u_xi_penalty;
        }
    }
#else
    real tc[COMPONENT_SLOTS];  // one free distance per component, as in trace.glsl
    for (int c = 0; c < COMPONENT_SLOTS; ++c) tc[c] = 0.0;
    for (int i = 0; i < u_max_iterations; ++i) {
        int c = front(tc);
        t = tc[c];
        if (t > u_max_distance) break;
        real d = component_distance(c, o + t * l);
        if (d <= eps * lod_scale(o + t * l)) return 0.0;
        if (soft && t > 0.0) vis = min(vis, u_shadow_softness * float(d / t));
        tc[c] = t + d;
    }
#endif
    return vis;
}
