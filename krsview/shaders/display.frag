// Shows the tracer's buffers in the window, upscaled from the internal resolution:
// shaded colour, an iteration heat map, depth or normals. A display choice, not a scene
// effect: a variant of this cheap pass per view (KRS_VIEW_ITERATIONS, KRS_VIEW_DEPTH,
// KRS_VIEW_NORMALS; none: the shaded colour), so switching never recompiles the tracer.
// Specialised rather than branched on a uniform: llvmpipe runs every branch's texture reads
// and maths for every window pixel (docs/speed.md).

uniform sampler2D u_color;       // rgb, hit
uniform vec2 u_window;           // size of the target in pixels

out vec4 frag_color;

#if defined(KRS_VIEW_ITERATIONS)
uniform sampler2D u_iterations;  // x
uniform float u_iteration_cap;

// Black → purple → orange → white heat ramp for iteration counts [KRS17 Fig. 13]; twin of
// heatmap.py's heat.
vec3 heat(float x) {
    x = clamp(x, 0.0, 1.0);
    return clamp(vec3(1.6 * x, 1.15 * x * x - 0.15, 0.9 * sin(3.14159265 * x) + x * x * x),
                 0.0, 1.0);
}
#elif defined(KRS_VIEW_DEPTH) || defined(KRS_VIEW_NORMALS)
uniform sampler2D u_normal;      // xyz, depth t
uniform float u_depth_scale;     // depth shown as 1 − log(1 + t / scale) / 4
#endif

void main() {
    vec2 uv = gl_FragCoord.xy / u_window;
#if defined(KRS_VIEW_ITERATIONS)
    vec3 rgb = heat(texture(u_iterations, uv).x / u_iteration_cap);
#elif defined(KRS_VIEW_DEPTH)
    bool hit = texture(u_color, uv).a > 0.5;
    vec3 rgb = hit ? vec3(1.0 - log(1.0 + texture(u_normal, uv).w / u_depth_scale) / 4.0)
                   : vec3(0.0);
#elif defined(KRS_VIEW_NORMALS)
    vec3 rgb = texture(u_color, uv).a > 0.5 ? texture(u_normal, uv).xyz * 0.5 + 0.5 : vec3(0.0);
#else
    vec3 rgb = texture(u_color, uv).rgb;
#endif
    frag_color = vec4(rgb, 1.0);
}
