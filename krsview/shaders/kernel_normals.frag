// The nearest kernel of each traced pixel's hit, found once for the passes that follow the
// trace-only pass (gpu/passes.py): coarse_visibility.frag reads the normal at its block's
// hit, upsampled.frag shades with normal, level and kernel-space point, so neither walks
// Alg. 1 again. Values as pixel.glsl's write_pixel finds them.
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"

uniform sampler2D u_traced_color;       // a: hit
uniform sampler2D u_traced_depth;       // w: ray distance t
uniform sampler2D u_traced_iterations;  // x

layout(location = 0) out vec4 out_normal;        // xyz, depth t (render.frag's target)
layout(location = 1) out vec4 out_iterations;    // x (render.frag's target)
layout(location = 2) out vec4 out_kernel_point;  // xyz: kernel-space point; w: level

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    out_iterations = vec4(texelFetch(u_traced_iterations, px, 0).x, 0.0, 0.0, 0.0);
    out_normal = vec4(0.0);
    out_kernel_point = vec4(0.0);
    if (texelFetch(u_traced_color, px, 0).a < 0.5) return;
    real t = real(texelFetch(u_traced_depth, px, 0).w);
    int level;
    vec3 n, xk;
    nearest_kernel(t * pixel_ray(gl_FragCoord.xy), t, level, n, xk);
    out_normal = vec4(n, float(t));
    out_kernel_point = vec4(xk, float(level));
}
