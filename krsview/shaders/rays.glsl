// The compute path's rays (trace.glsl's Ray, one per pixel of the traced rectangle, row by
// row): written by compute.comp round after round, read by deferred.frag to shade.
layout(std430, binding = BINDING_RAYS) buffer Rays { Ray rays[]; };
uniform ivec4 u_tile_rect;   // x, y, width, height of the pixels traced

int ray_index(ivec2 pixel) {
    ivec2 q = pixel - u_tile_rect.xy;
    return q.y * u_tile_rect.z + q.x;
}

#ifdef KRS_LANES
// Pixel's ray as it starts, and false where it is done before its first step (its pre-pass
// tile is free past the far limit), left as ray_step would leave it: persistent lanes skip
// such pixels (lanes.glsl) and deferred.frag writes them.
bool starts_live(ivec2 pixel, out Ray r) {
    real start[COMPONENT_SLOTS];
    ray_start(pixel, start);
    return ray_starts_live(start, r);
}
#endif
