// The viewer's shadow rays at reduced resolution [KRS17 §8.5 traces soft shadows at ¼
// resolution]: for each u_shadow_ratio × u_shadow_ratio block of the trace-only pass
// (render.frag with KRS_TRACE_ONLY), the block's nearest hit sends one shadow ray per light;
// its visibilities and depth are what upsampled.frag blends along depth. The uniforms are
// the full-resolution frame's, so the ray and its ε are those of that pixel; the hit's
// normal is the trace pass's (KRS_TRACE_KERNELS). Two passes (gpu/passes.py), so that the
// rays fill whole groups of lanes (llvmpipe runs 8 in lockstep, a group as long as its
// slowest ray: on tree a quarter of the blocks' groups hold a ray, and those ran 2.4
// lane-steps per step taken): KRS_SHADOW_LIST writes each block's depth, no visibility yet,
// and lists the blocks that face a light; KRS_SHADOW_RAYS traces the listed blocks' rays,
// eight neighbours to a group of lanes, and stores each one's visibilities at its block's
// texel. Each of llvmpipe's bins keeps a list of its own: one thread fills it, in the order
// it draws, so neighbours stay neighbours (one list for all, filled by two threads at once,
// put far blocks into a group: grove's rays took 1.25× as long, forest's 1.16×).
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "shadows.glsl"

uniform sampler2D u_traced_color;  // a: hit
uniform sampler2D u_traced_depth;  // xyz: the hit's normal; w: ray distance t
uniform ivec2 u_traced_size;  // the traced image's size (its textures may be a texel larger)
uniform int u_shadow_ratio;
uniform ivec2 u_coarse_origin;  // the coarse image's corner in its target (bin_origin)
uniform ivec3 u_bins;           // the coarse target's bins across, bins in all, a bin's side

layout(std430, binding = BINDING_BLOCK_LIST) buffer BlockList {
    // first, per bin of the coarse target (row by row), the blocks it listed; then per bin
    // room for a bin's blocks, each listed one's nearest hit as y · width + x in the trace
    // pass's image
    uint block_list[];
};

// Where bin b's k-th listed block is kept in block_list.
int list_entry(int b, uint k) {
    return u_bins.y + b * u_bins.z * u_bins.z + int(k);
}

#ifdef KRS_SHADOW_LIST
layout(location = 0) out vec4 out_visibility;  // per light (MAX_LIGHTS is 4); < 0: faces
                                               // away, no hit, or not traced yet
layout(location = 1) out vec4 out_depth;       // x: t of the block's pixel; < 0: no hit

void main() {
    ivec2 corner = (ivec2(gl_FragCoord.xy) - u_coarse_origin) * u_shadow_ratio;
    ivec2 size = u_traced_size;
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
    out_depth.x = t_best;
    bool lit = false;
    for (int k = 0; k < u_light_count; ++k) lit = lit || dot(n, u_light_dir[k]) > 0.0;
    if (!lit) return;
    ivec2 bin = ivec2(gl_FragCoord.xy) / u_bins.z;
    int b = bin.y * u_bins.x + bin.x;
    block_list[list_entry(b, atomicAdd(block_list[b], 1u))] = uint(best.y * size.x + best.x);
}
#endif

#ifdef KRS_SHADOW_RAYS
layout(rgba32f, binding = 0) uniform writeonly image2D u_visibility_image;  // the list pass's
uniform int u_packed_width;  // the pass's width (gpu/passes.py, packed)

void main() {
    uint i = packed_index(ivec2(gl_FragCoord.xy), u_packed_width), first = 0u;
    int b = 0;
    for (; b < u_bins.y; ++b) {  // the bin whose list holds the i-th block listed
        uint n = block_list[b];
        if (i < first + n) break;
        first += n;
    }
    if (b == u_bins.y) discard;
    int width = u_traced_size.x;
    int hit = int(block_list[list_entry(b, i - first)]);
    ivec2 best = ivec2(hit % width, hit / width);
    vec4 nt = texelFetch(u_traced_depth, best, 0);
    vec3r p = real(nt.w) * pixel_ray(vec2(best) + 0.5);
    vec4 visibility = vec4(-1.0);
    for (int k = 0; k < u_light_count; ++k)
        if (dot(nt.xyz, u_light_dir[k]) > 0.0)
            visibility[k] = shadow_visibility(p, nt.xyz, u_light_dir[k], u_eps_per_t * nt.w);
    imageStore(u_visibility_image, best / u_shadow_ratio + u_coarse_origin, visibility);
}
#endif
