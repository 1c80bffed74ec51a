// The trace-only pass (render.frag with KRS_TRACE_ONLY and KRS_TRACE_KERNELS: each hit's
// kernel found there) shaded as render.frag shades it. Without KRS_SHADOW_UPSAMPLED every
// pixel traces its own shadow rays: render.frag's image, in two passes. With it each
// light's visibility comes from coarse_visibility.frag's blocks around the pixel whose depth
// is within u_depth_slack footprints of its own (bilinear weights), which may be an
// earlier, smaller image's of the same view (gpu/passes.py, ``blocks``). Where no block is
// (an outline), the pixel traces its own ray, in a pass apart so that only those pixels
// run shadow-ray code (llvmpipe runs every branch's code for every pixel): KRS_SHADOW_MARK
// compiles none and lists such a pixel; KRS_SHADOW_OUTLINE shades the listed pixels, eight
// consecutive ones to each group of lanes (shadows.glsl, packed_index), so that they fill
// whole groups, and stores each one's colour in the image's.
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "pixel.glsl"

uniform sampler2D u_traced_color;       // rgb: the hit's kernel-space point; a: 1 + its
                                        // level (< 0.5: no hit)
uniform sampler2D u_traced_depth;       // xyz: the hit's normal; w: ray distance t
uniform sampler2D u_traced_iterations;  // x
uniform ivec2 u_traced_size;            // the image's size (its textures may be a texel larger)

#ifdef KRS_SHADOW_UPSAMPLED
uniform sampler2D u_coarse_visibility;  // per light; < 0: none
uniform sampler2D u_coarse_depth;       // x: t; < 0: no hit
uniform vec2 u_block;                   // a block's side in this image's pixels (an earlier,
                                        // smaller image's blocks are wider than its ratio)
uniform float u_depth_slack;            // block footprints of depth a block may differ
uniform ivec2 u_coarse_origin;          // the coarse image's corner in its target
uniform ivec2 u_coarse_size;            // and its size

// g_shadow: each light's visibility blended from the blocks near pixel px at depth t.
void upsample_visibility(ivec2 px, float t) {
    vec2 c = (vec2(px) + 0.5) / u_block - 0.5;
    ivec2 c0 = ivec2(floor(c));
    vec2 f = c - vec2(c0);
    ivec2 last = u_coarse_origin + u_coarse_size - 1;
    float slack = u_depth_slack * u_footprint * u_block.x * t;
    vec4 sum = vec4(0.0), weight = vec4(0.0);
    for (int j = 0; j < 2; ++j) {
        for (int i = 0; i < 2; ++i) {
            ivec2 q = clamp(c0 + ivec2(i, j) + u_coarse_origin, u_coarse_origin, last);
            float tq = texelFetch(u_coarse_depth, q, 0).x;
            if (tq < 0.0 || abs(tq - t) > slack) continue;
            float w = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y) + 1e-3;
            vec4 v = texelFetch(u_coarse_visibility, q, 0);
            for (int k = 0; k < MAX_LIGHTS; ++k) {
                if (v[k] >= 0.0) { sum[k] += w * v[k]; weight[k] += w; }
            }
        }
    }
    for (int k = 0; k < MAX_LIGHTS; ++k) g_shadow[k] = weight[k] > 0.0 ? sum[k] / weight[k] : -1.0;
}
#endif

#if defined(KRS_SHADOW_MARK) || defined(KRS_SHADOW_OUTLINE)
layout(std430, binding = BINDING_OUTLINE) buffer Outline {
    uint outline_count;     // pixels listed
    uint outline_pixels[];  // y · width + x
};
#endif
#ifdef KRS_SHADOW_OUTLINE
layout(rgba32f, binding = 0) uniform writeonly image2D u_color_image;  // the image's colour
uniform int u_packed_width;  // the pass's width (gpu/passes.py, packed)
#endif

#ifndef KRS_HIT_DEPTH  // (which writes the depth the others are tested against)
layout(early_fragment_tests) in;  // groups of pixels the depth test leaves out never run
#endif

// Pixel px's colour as write_pixel shades it, from the kernel the trace pass found.
vec4 traced_color(ivec2 px) {
    vec3r dir = pixel_ray(vec2(px) + 0.5);
#ifdef KRS_SHADE_SKY  // the depth test passes the pixels without a hit alone
    return vec4(encode(background(vec3(dir))), 0.0);
#else
    vec4 xk = texelFetch(u_traced_color, px, 0);
    if (xk.a < 0.5) return vec4(encode(background(vec3(dir))), 0.0);
    vec4 nt = texelFetch(u_traced_depth, px, 0);
    real t = real(nt.w);
#ifdef KRS_SHADOW_UPSAMPLED
    upsample_visibility(px, nt.w);
#endif
    return vec4(encode(shade(t * dir, vec3(dir), t, int(xk.a) - 1, nt.xyz, xk.xyz)), 1.0);
#endif
}

void main() {
#if defined(KRS_HIT_DEPTH)
    gl_FragDepth = texelFetch(u_traced_color, ivec2(gl_FragCoord.xy), 0).a < 0.5 ? 1.0 : 0.0;
#elif defined(KRS_SHADOW_OUTLINE)
    uint width = uint(u_traced_size.x);
    uint i = packed_index(ivec2(gl_FragCoord.xy), u_packed_width);
    if (i >= outline_count) discard;
    ivec2 px = ivec2(outline_pixels[i] % width, outline_pixels[i] / width);
    imageStore(u_color_image, px, traced_color(px));
#else
    ivec2 px = ivec2(gl_FragCoord.xy);
    out_color = traced_color(px);  // an outline pixel's is stored over it by its own pass
    vec4 nt = texelFetch(u_traced_depth, px, 0);
    out_normal = out_color.a > 0.5 ? nt : vec4(0.0);
    out_iterations = vec4(texelFetch(u_traced_iterations, px, 0).x, 0.0, 0.0, 0.0);
#ifdef KRS_SHADOW_MARK
    if (g_outline) {
        uint width = uint(u_traced_size.x);
        outline_pixels[atomicAdd(outline_count, 1u)] = uint(px.y) * width + uint(px.x);
    }
#endif
#endif
}
