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
uniform sampler2D u_parent0;  // its free distances: components 0..3
uniform sampler2D u_parent1;  // 4..7
layout(location = 0) out vec4 out_free0;   // components 0..3
layout(location = 1) out vec4 out_free1;   // components 4..7

void main() {
    vec2 corner = floor(gl_FragCoord.xy) * float(u_tile);
    vec3r centre = pixel_ray(corner + 0.5 * float(u_tile));
    real sigma = cone_spread(corner, centre);
    float t[8] = float[8](0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    float t0[8] = t;
    if (u_parent_ratio > 0) {
        ivec2 parent = ivec2(gl_FragCoord.xy) / u_parent_ratio;
        vec4 a = texelFetch(u_parent0, parent, 0), b = texelFetch(u_parent1, parent, 0);
        t0 = float[8](a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w);
    }
    // stored as float, shrunk first (a double t rounded up could pass the free part)
    for (int c = 0; c < COMPONENTS; ++c)
        t[c] = float(cone_free(c, centre, sigma, real(t0[c])) * (1.0 - 1e-6));
    out_free0 = vec4(t[0], t[1], t[2], t[3]);
    out_free1 = vec4(t[4], t[5], t[6], t[7]);
}
