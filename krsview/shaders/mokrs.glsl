// MöKRS: ISUNBOUNDING [KRS17 Alg. 3] and the nearest kernel with its world normal
// [KRS17 §8.1, App. C]; twin of reference/mokrs.py.
#include "kernels.glsl"
#include "mobius.glsl"
#include "lod.glsl"
#ifdef KRS_WIND
#include "wind.glsl"
#endif

bool reflects(int i) { return (int(mobius_rec(i, 4).w) & 2) != 0; }

// A probe holding level i's pole maps to the exterior of the ball (center, radius): it is
// free when everything at level i and below (the level's bounding ball) lies inside that
// ball; Alg. 3 rejects it outright, stopping rays that only pass near a pole.
bool exterior_is_free(int i, vec3r center, real radius) {
    vec4r bound = mobius_rec(i, 5);
    return bound.w >= 0.0 && length(bound.xyz - center) + bound.w < radius;
}

// The factor of the LOD threshold ε(t): 1, or in the wind its one factor for the frame.
real lod_scale(vec3r p) {
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) return wind_lod_scale();
#endif
    return 1.0;
}

#ifdef KRS_COUNT_LEVELS
int g_levels = 0;   // levels walked so far by this invocation (bench paths' measure)
#endif

// c: the component, always 0 (a MöKRS has no distance, so it joins no compound).
// Level of detail (lod.glsl): mapped into level i's space, the probe and the level's bound
// share a unit; a bound smaller than ρ in the probe's own scale (ρ / radius world units per
// unit of its radius: the map's local scale, to first order) stands for the levels below,
// and the probe is free exactly when it misses that bound (which holds them all).
// In the wind the world ball B(p, r) is free when it misses the swept ball, or when
// B(g(p), L·r) is free at rest, L = 1 + |a|(ρ + r) ≥ ‖Dg‖ over the ball (wind_rho with D = r):
// g maps the one into the other (reference/wind.py, rest_ball); ρ stays the world's.
// A probe that misses level i's bound (in level i's space it holds K_i and every level
// below) is free at once, the outermost first: a Möbius map takes balls to balls, so the world
// probe misses all that is left to test. Alg. 3 alone walks on and may still say "blocked"
// (a pole inside the probe further in, the mirror decided on the centre, a kernel's lower
// bound), so images may change, in the twin alike (reference/mokrs.py).
bool is_unbounding(int c, vec3r center, real radius) {
    real lod = lod_radius(length(center) + radius);
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) {
        if (wind_ball_distance(0, center) >= radius) return true;
        float a = wind_rate(0);
        real L = 1.0 + abs(a) * (wind_rho(0, center, radius, a) + radius);
        center = unwind(0, center, a);
        radius *= L;
    }
#endif
    real lod_per_radius = lod / radius;
    for (int i = u_n - 1; i >= 0; --i) {
#ifdef KRS_COUNT_LEVELS
        ++g_levels;
#endif
        if (!map_ball(i, center, radius)) return exterior_is_free(i, center, radius);
        vec4r b = mobius_rec(i, 5);
        if (b.w >= 0.0 && length(b.xyz - center) - b.w >= radius) return true;
#ifdef KRS_LOD  // a bound below ρ that the probe reaches stands for the levels below
        if (b.w >= 0.0 && b.w < lod_per_radius * radius) return false;
#endif
        if (reflects(i)) center.x = -abs(center.x);      // mirror decision on the centre
        if (kernel_distance(i, center) < radius) return false;
    }
    return true;
}

// Follow the point inwards accumulating J = d(world → level); k_i / |J e_x| is the world
// distance to first order; the winner's world normal is Jᵀ ∇k_j. In the wind the walk
// starts at the rest point g(xw), and the normal is the wind's Dgᵀ of that (wind_normal).
void mokrs_nearest(vec3r xw, out int level, out vec3 normal) {
    vec3r x = xw;
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) x = unwind(0, xw, wind_rate(0));
    vec3r q = x;
#endif
    vec3r xk = x;
    mat3r J = mat3r(1.0), Jk = mat3r(1.0);
    const mat3r FLIP = mat3r(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    real best = FAR_AWAY;
    level = 0;
    for (int i = u_n - 1; i >= 0; --i) {
        vec3r image = mobius_apply(i, x);
        J = mobius_jacobian(i, x, image) * J;
        x = image;
        if (reflects(i) && x.x > 0.0) { x.x = -x.x; J = FLIP * J; }
        real d = kernel_distance(i, x) / length(J[0]);
        if (d < best) { best = d; level = i; xk = x; Jk = J; }
    }
    vec3r g = kernel_gradient(level, xk), gw = transpose(Jk) * g;
    normal = vec3(length(gw) > 0.0 ? normalize(gw) : g);  // as krs_nearest where J degenerates
#ifdef KRS_WIND
    if (EFFECT_ON(KRS_WIND_BIT)) normal = wind_normal(0, vec3(xw), vec3(q), normal);
#endif
}
