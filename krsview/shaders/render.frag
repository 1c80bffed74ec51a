// Primary rays through pixel centres, traced and shaded; writes the reference's buffers.
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "prepass.glsl"
#include "shade.glsl"

layout(location = 0) out vec4 out_color;      // rgb, hit
layout(location = 1) out vec4 out_normal;     // xyz, depth t
layout(location = 2) out vec4 out_iterations; // x

void main() {
    vec3r dir = pixel_ray(gl_FragCoord.xy);
    real start[COMPONENT_SLOTS];
    ray_start(start);
    real t;
    int iterations;
    bool hit = trace_ray(vec3r(0.0), dir, start, t, iterations);
    out_iterations = vec4(float(iterations), 0.0, 0.0, 0.0);
    if (!hit) {
        out_color = vec4(encode(background(vec3(dir))), 0.0);
        out_normal = vec4(0.0);
        return;
    }
    int level;
    vec3 n, xk;
    nearest_kernel(t * dir, t, level, n, xk);
    out_color = vec4(encode(shade(t * dir, vec3(dir), t, level, n, xk)), 1.0);
    out_normal = vec4(n, float(t));
}
