// The compute path's shading pass: each pixel's ray as compute.comp left it in the ray
// buffer (and its shadow rays' visibilities, with KRS_SHADOW_TASKS), shaded and written as
// render.frag writes it. KRS_MISS_MARK: the variant that writes the misses (no shading code)
// and marks them with depth 0, so the shading variant, drawn behind a depth test, runs on the
// hits alone (gpu/context.py, behind_mark); with persistent lanes it also writes
// the rays they skip, done before their first step (rays.glsl, starts_live).
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "prepass.glsl"
#include "rays.glsl"
#include "pixel.glsl"

#ifdef KRS_SHADOW_TASKS
layout(std430, binding = BINDING_SHADOWS) readonly buffer Shadows { Shadow shadows[]; };
#endif

// The pixel written: shaded, or its tracing alone (KRS_TRACE_ONLY: the trace pass in
// gpu/passes.py; its shading passes follow).
void write_ray(bool hit, real t, int iterations, int slots) {
#ifdef KRS_TRACE_ONLY
    write_trace(pixel_ray(gl_FragCoord.xy), hit, t, iterations, slots);
#else
    write_pixel(pixel_ray(gl_FragCoord.xy), hit, t, iterations, slots);
#endif
}

void main() {
    int index = ray_index(ivec2(gl_FragCoord.xy));
    Ray r = rays[index];
#ifdef KRS_MISS_MARK
#ifdef KRS_LANES  // the lanes skip the rays that are done before a step: written here
    Ray first;
    if (!starts_live(ivec2(gl_FragCoord.xy), first)) r = first;
#endif
    gl_FragDepth = r.state == RAY_HIT ? 1.0 : 0.0;
    write_ray(false, r.t, r.iterations, r.slots);
#else
#ifdef KRS_SHADOW_TASKS
    for (int j = 0; j < MAX_LIGHTS; ++j) g_shadow[j] = shadows[index * MAX_LIGHTS + j].vis;
#endif
    write_ray(r.state == RAY_HIT, r.t, r.iterations, r.slots);
#endif
}
