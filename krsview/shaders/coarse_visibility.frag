// The viewer's shadow rays at reduced resolution [KRS17 §8.5 traces soft shadows at ¼
// resolution]: for each u_shadow_ratio × u_shadow_ratio block of the trace-only pass
// (render.frag with KRS_TRACE_ONLY), the block's nearest hit sends one shadow ray per light;
// its visibilities and depth are what upsampled.frag blends along depth. The uniforms are
// the full-resolution frame's, so the ray and its ε are those of that pixel; the hit's
// normal is the trace pass's (KRS_TRACE_KERNELS).
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "shadows.glsl"

uniform sampler2D u_traced_color;  // a: hit
uniform sampler2D u_traced_depth;  // xyz: the hit's normal; w: ray distance t
uniform int u_shadow_ratio;
uniform ivec2 u_coarse_origin;  // the coarse image's corner in its target (bin_origin)

layout(location = 0) out vec4 out_visibility;  // per light (MAX_LIGHTS is 4); < 0: faces
                                               // away, or no hit
layout(location = 1) out vec4 out_depth;       // x: t of the block's pixel; < 0: no hit

void main() {
    ivec2 corner = (ivec2(gl_FragCoord.xy) - u_coarse_origin) * u_shadow_ratio;
    ivec2 size = textureSize(u_traced_depth, 0);
    ivec2 best = ivec2(-1);
    float t_best = 0.0;
    vec3 n = vec3(0.0);  // the best hit's normal
    for (int j = 0; j < u_shadow_ratio; ++j) {
        for (int i = 0; i < u_shadow_ratio; ++i) {
            ivec2 q = corner + ivec2(i, j);
            if (q.x >= size.x || q.y >= size.y || texelFetch(u_traced_color, q, 0).a < 0.5)
                continue;
            vec4 nt = texelFetch(u_traced_depth, q, 0);
            if (best.x < 0 || nt.w < t_best) { best = q; t_best = nt.w; n = nt.xyz; }
        }
    }
    out_visibility = vec4(-1.0);
    out_depth = vec4(-1.0);
    if (best.x < 0) return;
    real t = real(t_best);
    vec3r p = t * pixel_ray(vec2(best) + 0.5);
    for (int k = 0; k < u_light_count; ++k)
        if (dot(n, u_light_dir[k]) > 0.0)
            out_visibility[k] = shadow_visibility(p, n, u_light_dir[k], u_eps_per_t * t_best);
    out_depth.x = t_best;
}
