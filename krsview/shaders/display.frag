// Shows the tracer's buffers in the window, upscaled from the internal resolution:
// shaded colour, an iteration heat map, depth or normals. A display choice, not a scene
// effect: a variant of this cheap pass per view, so switching never recompiles the tracer.
// KRS_VIEW is VIEW_ITERATIONS, VIEW_DEPTH or VIEW_NORMALS (compile/constants.py), a constant
// the compiler folds; absent, the shaded colour. Variants, not a uniform: llvmpipe runs
// every branch's texture reads and maths for every window pixel (docs/speed.md).

uniform sampler2D u_color;       // rgb, hit
#include "window_image.glsl"

out vec4 frag_color;

#ifdef KRS_VIEW
uniform sampler2D u_normal;      // xyz, depth t
uniform sampler2D u_iterations;  // x
uniform float u_iteration_scale;  // white at this many
uniform float u_depth_scale;     // depth shown as 1 − log(1 + t / scale) / 4

// Black → purple → orange → white heat ramp for iteration counts [KRS17 Fig. 13]; twin of
// heatmap.py's heat.
vec3 heat(float x) {
    x = clamp(x, 0.0, 1.0);
    return clamp(vec3(1.6 * x, 1.15 * x * x - 0.15, 0.9 * sin(3.14159265 * x) + x * x * x),
                 0.0, 1.0);
}
#endif

void main() {
    vec2 uv = window_image_uv();
    vec4 c = texture(u_color, uv);
    vec3 rgb = c.rgb;
#ifdef KRS_VIEW
    vec4 nd = texture(u_normal, uv);  // the compiler drops what the view does not read
    if (KRS_VIEW == VIEW_ITERATIONS)
        rgb = heat(texture(u_iterations, uv).x / u_iteration_scale);
    else if (KRS_VIEW == VIEW_DEPTH)
        rgb = c.a > 0.5 ? vec3(1.0 - log(1.0 + nd.w / u_depth_scale) / 4.0) : vec3(0.0);
    else
        rgb = c.a > 0.5 ? nd.xyz * 0.5 + 0.5 : vec3(0.0);
#endif
    frag_color = vec4(rgb, 1.0);
}
