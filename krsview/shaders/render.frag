// Primary rays through pixel centres, traced and shaded (the fragment path); writes the
// reference's buffers. KRS_FREE_TILES (with a pre-pass): the variant that writes only the
// pixels whose tile the pre-pass found free past the far limit, as the tracing variant
// would (a miss before the first step), and marks them with depth 0 so the tracing variant,
// drawn behind a depth test, skips them (gpu/renderer.py); the other pixels get depth 1.
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "prepass.glsl"
#include "pixel.glsl"

void main() {
    vec3r dir = pixel_ray(gl_FragCoord.xy);
    real start[COMPONENT_SLOTS];
    ray_start(ivec2(gl_FragCoord.xy), start);
    real t;
    int iterations, slots;
#ifdef KRS_FREE_TILES
    Ray r;
    bool traced = ray_starts_live(start, r);  // false: done before a step, as trace_ray is
    gl_FragDepth = traced ? 1.0 : 0.0;
    t = r.t;
    iterations = r.iterations;
    slots = r.slots;
    const bool hit = false;  // the shading's code compiled away
#else
    bool hit = trace_ray(vec3r(0.0), dir, start, t, iterations, slots);
#endif
#ifdef KRS_COUNT_LEVELS
    int levels = g_levels;   // the tracing's, before shading walks more
#endif
#ifdef KRS_TRACE_ONLY   // the tracing alone, its result kept, nothing shaded
    write_trace(dir, hit, t, iterations, slots);
#else
    write_pixel(dir, hit, t, iterations, slots);
#endif
#ifdef KRS_COUNT_LEVELS
    out_iterations.y = float(levels);
#if defined(KRS_SHADOWS) || defined(KRS_SOFT_SHADOWS)  // and its shadow rays' (shadows.glsl)
    out_iterations.zw = vec2(float(g_shadow_steps), float(g_shadow_levels));
#endif
#endif
}
