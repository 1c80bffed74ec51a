// Primary rays through pixel centres, traced and shaded; writes the reference's buffers.
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "shade.glsl"

layout(location = 0) out vec4 out_color;      // rgb, hit
layout(location = 1) out vec4 out_normal;     // xyz, depth t
layout(location = 2) out vec4 out_iterations; // x

void main() {
    vec2 ndc = 2.0 * gl_FragCoord.xy / u_resolution - 1.0;
    float aspect = u_resolution.x / u_resolution.y;
    vec3r dir = normalize(u_forward + real(ndc.x * u_tan_half * aspect) * u_right
                          + real(ndc.y * u_tan_half) * u_up);
    real t;
    int iterations;
    bool hit = trace_ray(vec3r(0.0), dir, t, iterations);
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
