// The compute path's shading pass: each pixel's ray as compute.comp left it in the ray
// buffer, shaded and written as render.frag writes it.
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "rays.glsl"
#include "pixel.glsl"

void main() {
    Ray r = rays[ray_index(ivec2(gl_FragCoord.xy))];
    write_pixel(pixel_ray(gl_FragCoord.xy), r.state == RAY_HIT, r.t, r.iterations);
}
