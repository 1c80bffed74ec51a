// The pre-pass (prepass.glsl): one cone per tile; per component the distance along the
// tile's centre ray over which all of its rays are free. A pass after the coarsest starts
// each cone at the free distance of the coarser tile around it: that tile's cone holds this
// one's rays, so they are free that far already.
#define KRS_PREPASS_COARSE
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "prepass.glsl"

uniform int u_parent_ratio;   // the coarser pass's tile over this one's (0: none before)
// Free distances per component, 4 per target as u_free (prepass.glsl): the coarser pass's,
// and this one's.
uniform sampler2D u_parent[PREPASS_TARGETS];
layout(location = 0) out vec4 out_free[PREPASS_TARGETS];

void main() {
    vec2 corner = floor(gl_FragCoord.xy) * float(u_tile);
    vec3r centre = pixel_ray(corner + 0.5 * float(u_tile));
    real sigma = cone_spread(corner, centre);
    vec4 t[PREPASS_TARGETS], t0[PREPASS_TARGETS];
    for (int k = 0; k < PREPASS_TARGETS; ++k) {
        t[k] = vec4(0.0);
        t0[k] = u_parent_ratio > 0
            ? texelFetch(u_parent[k], ivec2(gl_FragCoord.xy) / u_parent_ratio, 0) : vec4(0.0);
    }
    // stored as float, shrunk first (a double t rounded up could pass the free part)
    for (int c = 0; c < COMPONENTS; ++c)
        t[c / 4][c % 4] = float(cone_free(c, centre, sigma, real(t0[c / 4][c % 4])) * (1.0 - 1e-6));
    for (int k = 0; k < PREPASS_TARGETS; ++k) out_free[k] = t[k];
}
