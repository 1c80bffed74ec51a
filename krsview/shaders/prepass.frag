// The pre-pass (prepass.glsl): one cone per tile; per component the distance along the
// tile's centre ray over which all of its rays are free.
#define KRS_PREPASS_COARSE
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "prepass.glsl"

layout(location = 0) out vec4 out_free0;   // components 0..3
layout(location = 1) out vec4 out_free1;   // components 4..7

void main() {
    vec2 corner = floor(gl_FragCoord.xy) * float(u_tile);
    vec3r centre = pixel_ray(corner + 0.5 * float(u_tile));
    real sigma = cone_spread(corner, centre);
    float t[8] = float[8](0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    // stored as float, shrunk first (a double t rounded up could pass the free part)
    for (int c = 0; c < COMPONENTS; ++c)
        t[c] = float(cone_free(c, centre, sigma) * (1.0 - 1e-6));
    out_free0 = vec4(t[0], t[1], t[2], t[3]);
    out_free1 = vec4(t[4], t[5], t[6], t[7]);
}
