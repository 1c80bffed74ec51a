// What is drawn, for the KRS family: the distance bound with the scene's distortions and the
// nearest kernel with its world normal; twin of reference/distortion.py. Without twist and
// empty zones this is Alg. 1 itself [KRS17 Alg. 1].
#include "krs.glsl"
#ifdef KRS_TWIST
#include "twist.glsl"
#endif
#ifdef KRS_EMPTY_ZONES
#include "empty_zones.glsl"
#endif

// Where the undistorted KRS is looked up for the world point p.
vec3 undistort(vec3 p) {
#ifdef KRS_TWIST
    if (EFFECT_ON(KRS_TWIST_BIT)) return untwist(p);
#endif
    return p;
}

// From the undistorted distance D at undistort(p) to a bound that never overshoots at p.
float distort_distance(vec3 p, float D) {
#ifdef KRS_TWIST
    if (EFFECT_ON(KRS_TWIST_BIT)) D = twist_step(p, D);
#endif
#ifdef KRS_EMPTY_ZONES
    int zone;
    if (EFFECT_ON(KRS_EMPTY_ZONES_BIT)) D = max(D, zone_depth(p, zone));
#endif
    return D;
}

float scene_distance(vec3 p) { return distort_distance(p, krs_distance(undistort(p))); }

// A ball is free of the geometry when the distance bound at its centre covers it.
bool is_unbounding(vec3 center, float radius) { return scene_distance(center) >= radius; }

// Nearest kernel level, its kernel-space point and the world normal at the hit point p, whose
// ray distance t sets the smoothing band (at least 2 pixel footprints, against aliasing).
void scene_nearest(vec3 p, float t, out int level, out vec3 normal, out vec3 xk) {
    vec3 q = undistort(p);
    float width = 0.0;
#ifdef KRS_SMOOTH_SHADING
    width = max(u_smooth_width, 2.0 * u_footprint * t);
#endif
    float D = krs_nearest(q, width, level, normal, xk);
#ifdef KRS_TWIST
    if (EFFECT_ON(KRS_TWIST_BIT)) normal = twist_normal(p, q, normal);
#endif
#ifdef KRS_EMPTY_ZONES
    int zone;   // on a cut face the zone's sphere is the surface
    if (EFFECT_ON(KRS_EMPTY_ZONES_BIT) && zone_depth(p, zone) > D)
        normal = normalize(u_empty_zones[zone].xyz - p);
#endif
}
