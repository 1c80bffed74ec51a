// One traced pixel shaded and written to the three render targets the reference's buffers
// come from: by render.frag right after tracing, and by deferred.frag from the compute
// path's G-buffer.
#include "shade.glsl"

layout(location = 0) out vec4 out_color;      // rgb, hit
layout(location = 1) out vec4 out_normal;     // xyz, depth t
layout(location = 2) out vec4 out_iterations; // x; y: levels walked (KRS_COUNT_LEVELS)

void write_pixel(vec3r dir, bool hit, real t, int iterations) {
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
