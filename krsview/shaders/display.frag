// Shows the tracer's buffers in the window, upscaled from the internal resolution:
// shaded colour, an iteration heat map, depth or normals. A display choice, not a scene
// effect: a uniform of this cheap pass, so switching never recompiles the tracer. u_view is
// one of VIEW_SHADED, VIEW_ITERATIONS, VIEW_DEPTH, VIEW_NORMALS (compile/constants.py).

uniform sampler2D u_color;       // rgb, hit
uniform sampler2D u_normal;      // xyz, depth t
uniform sampler2D u_iterations;  // x
uniform int u_view;
uniform float u_iteration_cap;
uniform float u_depth_scale;     // depth shown as 1 − log(1 + t / scale) / 4
uniform vec2 u_window;           // size of the target in pixels

out vec4 frag_color;

// Black → purple → orange → white heat ramp for iteration counts [KRS17 Fig. 13]; twin of
// heatmap.py's heat.
vec3 heat(float x) {
    x = clamp(x, 0.0, 1.0);
    return clamp(vec3(1.6 * x, 1.15 * x * x - 0.15, 0.9 * sin(3.14159265 * x) + x * x * x),
                 0.0, 1.0);
}

void main() {
    vec2 uv = gl_FragCoord.xy / u_window;
    vec4 c = texture(u_color, uv);
    vec4 nd = texture(u_normal, uv);
    vec3 rgb = c.rgb;
    if (u_view == VIEW_ITERATIONS)
        rgb = heat(texture(u_iterations, uv).x / u_iteration_cap);
    else if (u_view == VIEW_DEPTH)
        rgb = c.a > 0.5 ? vec3(1.0 - log(1.0 + nd.w / u_depth_scale) / 4.0) : vec3(0.0);
    else if (u_view == VIEW_NORMALS)
        rgb = c.a > 0.5 ? nd.xyz * 0.5 + 0.5 : vec3(0.0);
    frag_color = vec4(rgb, 1.0);
}
