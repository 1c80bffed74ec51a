// What is drawn, for the KRS family: the distance bound with the scene's distortions and the
// nearest kernel with its world normal; twin of reference/geometry.py and reference/distortion.py.
// Without twist, wind and empty zones this is Alg. 1 itself [KRS17 Alg. 1]; in a compound,
// each component is a KRS of its own [KRS17 §5.1].
#include "krs.glsl"
#if defined(KRS_TWIST) || defined(KRS_WIND)
// The δ with δ(1 + k(ρ + δ)) = D, in its cancellation-free form: a step that stays in the free
// ball of radius D through a map whose Jacobian is at most 1 + k·(distance to its axis);
// δ = D when k = 0 (reference/distortion.py, safe_step).
real safe_step(real D, real k, real rho) {
    if (D <= 0.0) return D;
    real a = 1.0 + k * rho;
    return 2.0 * D / (a + sqrt(a * a + 4.0 * k * D));
}
#endif
#ifdef KRS_TWIST
#include "twist.glsl"
#endif
#ifdef KRS_WIND
#include "wind.glsl"
#endif
#ifdef KRS_EMPTY_ZONES
#include "empty_zones.glsl"
#endif

// Where component c's undistorted KRS is looked up for the world point p.
vec3r undistort(int c, vec3r p) {
#ifdef KRS_TWIST
    if (EFFECT_ON(KRS_TWIST_BIT)) return untwist(p);
#endif
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) return unwind(c, p, wind_rate(c));
#endif
    return p;
}

// The factor of the LOD threshold ε(t) at p: the twist's safe step is D / (1 + |k|ρ) to
// first order, so ε shrinks by the same factor and rays converge where the undistorted
// distance is within ε(t), not high above a twisted ground (reference/distortion.py, lod_scale).
// The wind's is one factor for the frame (wind.glsl, wind_lod_scale: a loop over the
// components per step cost the grove 12 %; a smaller ε where no bend shrinks the step costs
// it about 1 % of iterations).
real lod_scale(vec3r p) {
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) return wind_lod_scale();
#endif
#ifdef KRS_TWIST
    if (EFFECT_ON(KRS_TWIST_BIT))
        return 1.0 / (1.0 + abs(u_twist) * length(vec2(p.xz - u_twist_center.xz)));
#endif
    return 1.0;
}

// From the undistorted distance D at undistort(p) to a bound that never overshoots at p.
real distort_distance(vec3r p, real D) {
#ifdef KRS_TWIST
    if (EFFECT_ON(KRS_TWIST_BIT)) D = twist_step(p, D);
#endif
#ifdef KRS_EMPTY_ZONES
    int zone;
    if (EFFECT_ON(KRS_EMPTY_ZONES_BIT)) D = max(D, zone_depth(p, zone));
#endif
    return D;
}

#ifdef KRS_BALL_EXIT  // bounded KRS components, not twisted (uniforms.variant_defines)
#ifdef KRS_COMPOUND  // per component: centre (camera-relative), radius (< 0: none)
uniform vec4 u_bounding_ball[COMPONENT_SLOTS];
#define COMPONENT_BALL(c) u_bounding_ball[c]
#else
uniform vec4 u_bounding_ball;
#define COMPONENT_BALL(c) u_bounding_ball
#endif
#endif

// Component c's slots: (first, n).
ivec2 component(int c) {
#ifdef KRS_COMPOUND
    return u_component[c];
#else
    return ivec2(0, u_n);
#endif
}

real undistorted_distance(int c, vec3r q, real rho) {
    ivec2 k = component(c);
    return krs_distance(k.x, k.y, q, krs_lod(c, k.x, k.y, rho));
}

#ifdef KRS_WIND
// The last wind step's undistorted distance D, |a| and axis distance ρ, which the balls'
// exits read right after the step (trace.glsl, bound_ahead).
vec3 g_wind_step;
#endif

// Component c's distance bound with the level of detail ρ; the wind bends it about its own
// foot at its own rate a, and its step is safe for the bound 1 + |a|ρ, or is the distance to
// the ball that holds it at any time where that is larger (wind.glsl).
real component_distance_at(int c, vec3r p, real rho) {
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) {
        float a = wind_rate(c);
        real D = undistorted_distance(c, unwind(c, p, a), rho);
        g_wind_step = vec3(D, abs(a), length(cross(u_wind_axis, vec3(p) - u_wind_base[c].xyz)));
        D = safe_step(D, abs(a), wind_rho(c, p, D, a));
        return distort_distance(p, max(D, wind_ball_distance(c, p)));
    }
#endif
    return distort_distance(p, undistorted_distance(c, undistort(c, p), rho));
}

// The distance bound of component c, which the tracer steps by.
real component_distance(int c, vec3r p) {
    return component_distance_at(c, p, lod_radius(length(p)));
}

// The bound of everything drawn: the least over the components (a distortion is monotone in
// the distance, so it is applied once, after the minimum; the wind bends each component about
// its own foot, so there each component's bound is taken).
real scene_distance(vec3r p) {
#ifdef KRS_COMPOUND
    real rho = lod_radius(length(p));
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) {
        real D = component_distance_at(0, p, rho);
        for (int c = 1; c < COMPONENTS; ++c) D = min(D, component_distance_at(c, p, rho));
        return D;
    }
#endif
    vec3r q = undistort(0, p);
    real D = undistorted_distance(0, q, rho);
    for (int c = 1; c < COMPONENTS; ++c) D = min(D, undistorted_distance(c, q, rho));
    return distort_distance(p, D);
#else
    return component_distance(0, p);  // the loop above, though empty, costs llvmpipe 4 %
#endif
}

// A ball is free of component c when its distance bound at the centre covers it.
bool is_unbounding(int c, vec3r center, real radius) {
    return component_distance_at(c, center, lod_radius(length(center) + radius)) >= radius;
}

// The component nearest to the world point p, each asked where it is undistorted (ties: the
// first), without LOD. One whose ball (at rest, where q is) is no nearer than the best so far
// is not walked: its distance is at least the ball's, so it could only tie, and ties go to
// the first; the same winner, and a grove's hit walks one or two trees instead of seven.
int nearest_component(vec3r p) {
    int win = 0;
#ifdef KRS_COMPOUND
    real best = undistorted_distance(0, undistort(0, p), 0.0);
    for (int c = 1; c < COMPONENTS; ++c) {
        vec3r q = undistort(c, p);
#ifdef KRS_BALL_EXIT
        vec4 ball = COMPONENT_BALL(c);  // float: give up the rounding, as bound_ahead
        float near = length(vec3(q) - ball.xyz) - ball.w - 1e-6 * (length(vec3(q)) + ball.w);
        if (ball.w >= 0.0 && near >= best) continue;
#endif
        real d = undistorted_distance(c, q, 0.0);
        if (d < best) { best = d; win = c; }
    }
#endif
    return win;
}

// Nearest kernel's level slot, its kernel-space point and the world normal at the hit point
// p, whose ray distance t sets the smoothing band (at least 2 pixel footprints, against
// aliasing). In a compound, the component nearest to p is asked (ties: the first); what the
// trace handed on (`slot`, `cut`: trace.glsl) serves where it lies in that component.
void scene_nearest(vec3r p, real t, int slot, int cut, out int level, out vec3 normal,
                   out vec3 xk) {
    int c = nearest_component(p);
    vec3r q = undistort(c, p), xkr;
    float width = 0.0;
#ifdef KRS_SMOOTH_SHADING
    width = max(u_smooth_width, 2.0 * u_detail_footprint * float(t));
#endif
    ivec2 k = component(c);
    real D = krs_nearest(k.x, k.y, q, width, slot, cut, level, normal, xkr);
    xk = vec3(xkr);
#ifdef KRS_TWIST
    if (EFFECT_ON(KRS_TWIST_BIT)) normal = twist_normal(vec3(p), vec3(q), normal);
#endif
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) normal = wind_normal(c, vec3(p), vec3(q), normal);
#endif
#ifdef KRS_EMPTY_ZONES
    int zone;   // on a cut face the zone's sphere is the surface
    if (EFFECT_ON(KRS_EMPTY_ZONES_BIT) && zone_depth(p, zone) > D)
        normal = vec3(normalize(u_empty_zones[zone].xyz - p));
#endif
}
