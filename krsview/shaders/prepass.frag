// The pre-pass (prepass.glsl): one cone per tile; per component the distance along the
// tile's centre ray over which all of its rays are free. A pass after the coarsest starts
// each cone at the free distance of the coarser tile around it: that tile's cone holds this
// one's rays, so they are free that far already. The pass is drawn quarter by quarter
// (prepass.glsl, coarse_texel).
#define KRS_PREPASS_COARSE
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "prepass.glsl"

uniform int u_parent_ratio;   // the coarser pass's tile over this one's (0: none before)
uniform ivec4 u_layout;       // this pass's quarter stride, and the coarser one's (coarse_texel)
// Free distances per component, 4 per target as u_free (prepass.glsl): the coarser pass's,
// and this one's.
uniform sampler2D u_parent[PREPASS_TARGETS];
layout(location = 0) out vec4 out_free[PREPASS_TARGETS];

void main() {
    ivec2 q = ivec2(gl_FragCoord.xy), quarter = ivec2(greaterThanEqual(q, u_layout.xy));
    ivec2 local = q - quarter * u_layout.xy;   // coarse_texel's inverse
    ivec2 tile = (local / PREPASS_BLOCK * 2 + quarter) * PREPASS_BLOCK + local % PREPASS_BLOCK;
    ivec2 parent = coarse_texel(tile / PREPASS_RATIO, u_layout.zw);
    vec2 corner = vec2(tile) * float(u_tile);
    vec3r centre = pixel_ray(corner + 0.5 * float(u_tile));
    real sigma = cone_spread(corner, centre);
    vec4 t[PREPASS_TARGETS], t0[PREPASS_TARGETS];
    for (int k = 0; k < PREPASS_TARGETS; ++k) {
        t[k] = vec4(0.0);
        t0[k] = u_parent_ratio > 0
            ? texelFetch(u_parent[k], parent, 0) : vec4(0.0);
    }
    // stored as float, shrunk first (a double t rounded up could pass the free part)
    for (int c = 0; c < COMPONENTS; ++c)
        t[c / 4][c % 4] = float(cone_free(c, centre, sigma, real(t0[c / 4][c % 4])) * (1.0 - 1e-6));
    for (int k = 0; k < PREPASS_TARGETS; ++k) out_free[k] = t[k];
}
