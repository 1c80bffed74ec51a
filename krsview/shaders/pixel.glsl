// One traced pixel shaded and written to the three render targets the reference's buffers
// come from: by render.frag right after tracing, and by deferred.frag from the compute
// path's G-buffer; or (write_trace) its tracing alone, for the passes after it.
#include "shade.glsl"

layout(location = 0) out vec4 out_color;      // rgb, hit
layout(location = 1) out vec4 out_normal;     // xyz, depth t
layout(location = 2) out vec4 out_iterations; // x; y: levels walked (KRS_COUNT_LEVELS)

void write_pixel(vec3r dir, bool hit, real t, int iterations, int slots) {
    out_iterations = vec4(float(iterations), 0.0, 0.0, 0.0);
    if (!hit) {
        out_color = vec4(encode(background(vec3(dir))), 0.0);
        out_normal = vec4(0.0);
        return;
    }
    int level;
    vec3 n, xk;
    nearest_kernel(t * dir, t, slots, level, n, xk);
    out_color = vec4(encode(shade(t * dir, vec3(dir), t, level, n, xk)), 1.0);
    out_normal = vec4(n, float(t));
}

// The tracing alone (KRS_TRACE_ONLY: bench split, the trace pass in gpu/passes.py): hit and
// depth, and with KRS_TRACE_KERNELS the hit's kernel point, level and normal, which the
// passes after it read instead of walking Alg. 1 again.
void write_trace(vec3r dir, bool hit, real t, int iterations, int slots) {
    out_color = vec4(0.0, 0.0, 0.0, hit ? 1.0 : 0.0);
    out_normal = vec4(0.0, 0.0, 0.0, float(t));
    out_iterations = vec4(float(iterations), 0.0, 0.0, 0.0);
#ifdef KRS_TRACE_KERNELS
    if (hit) {
        int level;
        vec3 n, xk;
        nearest_kernel(t * dir, t, slots, level, n, xk);
        out_color = vec4(xk, 1.0 + float(level));  // a > 0.5: a hit
        out_normal.xyz = n;
    }
#endif
}
