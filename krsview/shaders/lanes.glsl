// Persistent lanes [Aila & Laine 2009, "Understanding the efficiency of ray traversal on
// GPUs": persistent threads, dynamic fetch] (`[render] steps = 0`; included by compute.comp
// with KRS_LANES). llvmpipe runs 8 invocations in lockstep, as it runs a fragment group of
// 4×2 pixels, so a group of rays takes as many steps as its slowest; here a lane whose ray is
// done stores it and takes the next pixel at once, and its 8 lanes wait for their slowest only
// at the end. Three dispatches:
// - PHASE_START (list_block): the tile's blocks of u_block × u_block pixels (the pre-pass's
//   tiles, 4 × 4 without one) are listed in queue 0 (count[0] of them), but for those whose rays
//   are done before a step (free past the far limit: deferred.frag writes those), and the
//   lanes' dispatch is sized from the listed pixels (groups, for an indirect dispatch);
// - PHASE_LANES (lanes): the lanes take the listed blocks' pixels from a counter (`taken`),
//   block by block, and trace them with trace.glsl's ray_step, the fragment path's steps;
// - PHASE_ROUND (lanes_rest): the rays the lanes left live, then the pixels they never took,
//   each traced to its end, one per invocation.
// A subgroup of lanes takes at most u_steps steps (the iteration cap, the most one fragment
// group may take): llvmpipe ends every loop of an invocation after 65535 loop iterations in
// all, which a subgroup tracing pixel after pixel would reach, and a walk cut short would
// return a wrong distance. Its rays still live then are saved whole and queued (queue 1,
// count[1]), and the last lane to finish sizes lanes_rest's dispatch. llvmpipe's threads run
// workgroups one after another, so each subgroup takes pixels until its budget ends and saves
// the rays it holds then: at the zoom's stop 3 (320×180) 2,704 rays, 4.7 % of the pixels, at
// 16 to 48 steps per pixel alike; their round is 6 % of the fragment path's tracing there.
// The anchor of the walk restart (trace.glsl's Ray) is saved with the ray, and a lane drops
// it with its ray (ray_begin), so lanes take the fragment path's restarted steps too.

uniform uint u_lane_steps;  // steps per listed pixel that the lanes' dispatch holds
uniform int u_block;     // the side of the blocks: the pre-pass's tile (4 without one)
uniform uint u_blocks;   // blocks over u_tile_rect (u_block_grid.x × .y)
uniform ivec2 u_block_grid;  // blocks across and down

// Block k's first pixel; the blocks lie on the pre-pass's grid (a tile rectangle that does
// not start on it, a band of rows, is covered by the blocks it meets).
ivec2 block_corner(uint k) {
    ivec2 grid = u_tile_rect.xy / u_block;
    return u_block * (grid + ivec2(int(k) % u_block_grid.x, int(k) / u_block_grid.x));
}

// PHASE_START: block k is listed unless its rays are done before a step (rays.glsl); the
// lanes' dispatch holds u_lane_steps steps per listed pixel, u_steps per lane (the largest of
// the listing invocations' sizes is the whole list's). Sized by every pixel of the tile, it
// ran idle subgroups at whole views (74 % of tree's pixels free past the far limit).
void list_block(uint k) {
    if (k >= u_blocks) return;
    Ray r;
    bool traced = starts_live(block_corner(k), r);
    uint at = atomicAdd(count[0], traced ? 1u : 0u);   // atomics outside branches
    if (traced) queue[at] = k;
    uint per_group = uint(COMPUTE_GROUP * u_steps);
    uint steps = (at + 1u) * uint(u_block * u_block) * u_lane_steps;
    atomicMax(groups[0], traced ? (steps + per_group - 1u) / per_group : 0u);
}

// The p-th pixel the lanes take, p below count[0] · u_block²: pixel p % u_block² (row by
// row) of the (p / u_block²)-th listed block; false where it lies outside u_tile_rect.
bool lane_pixel(uint p, out ivec2 pixel) {
    uint size = uint(u_block * u_block), o = p % size;
    pixel = block_corner(queue[p / size]) + ivec2(int(o) % u_block, int(o) / u_block);
    return all(greaterThanEqual(pixel, u_tile_rect.xy)) &&
           all(lessThan(pixel, u_tile_rect.xy + u_tile_rect.zw));
}

// The p-th pixel's ray begins, and its index in the ray buffer; past the listed pixels
// (p ≥ listed) or outside the rectangle, an idle lane: a finished ray, index −1.
void lane_begin(uint p, uint listed, out Ray r, out vec3r dir, out int index) {
    ivec2 pixel;
    bool inside = lane_pixel(p < listed ? p : 0u, pixel) && p < listed;
    real start[COMPONENT_SLOTS];
    ray_start(pixel, start);
    r = ray_begin(start);
    dir = pixel_ray(vec2(pixel) + 0.5);
    index = inside ? ray_index(pixel) : -1;
    if (!inside) r.state = RAY_MISS;
}

// PHASE_LANES: each lane steps its ray; as soon as any lane of the subgroup is done, those
// that are store their rays and take the next pixels.
void lanes() {
    uint listed = count[0] * uint(u_block * u_block), p = atomicAdd(taken, 1u);
    Ray r;
    vec3r dir;
    int index;
    lane_begin(p, listed, r, dir, index);
    int budget = u_steps;
    while (anyInvocationARB(p < listed) && budget > 0) {
        bool done;
        do {
            if (r.state == RAY_LIVE) ray_step(r, vec3r(0.0), dir);
            done = r.state != RAY_LIVE && p < listed;
            --budget;
        } while (!anyInvocationARB(done) && anyInvocationARB(r.state == RAY_LIVE) && budget > 0);
        uint next = atomicAdd(taken, done ? 1u : 0u);   // atomics outside branches
        if (done && index >= 0) {
            rays[index].t = r.t;                         // what deferred.frag reads
            rays[index].iterations = r.iterations;
            rays[index].state = r.state;
            rays[index].slots = r.slots;
        }
        if (done) {
            p = next;
            lane_begin(p, listed, r, dir, index);
        }
    }
    bool left = r.state == RAY_LIVE;   // a ray not stored yet (index ≥ 0)
    uint slot = atomicAdd(count[1], left ? 1u : 0u);
    if (left) queue[u_queue + slot] = uint(index);
    if (index >= 0) rays[index] = r;
    memoryBarrierBuffer();
    uint lanes_n = gl_NumWorkGroups.x * uint(COMPUTE_GROUP);
    if (atomicAdd(lanes_done, 1u) == lanes_n - 1u) {   // the last lane sizes lanes_rest
        uint rest = count[1] + listed - min(taken, listed);
        groups[0] = (rest + uint(COMPUTE_GROUP) - 1u) / uint(COMPUTE_GROUP);
        groups[1] = 1u;
        groups[2] = 1u;
    }
}

// PHASE_ROUND after the lanes: the k-th of the rays they left live, then of the pixels they
// never took, traced to its end.
void lanes_rest(uint k) {
    uint left = count[1], listed = count[0] * uint(u_block * u_block);
    Ray r;
    vec3r dir;
    int index;
    if (k < left) {
        index = int(queue[u_queue + k]);
        r = rays[index];
        dir = pixel_ray(vec2(tile_pixel(uint(index))) + 0.5);
    } else {
        lane_begin(min(taken, listed) + (k - left), listed, r, dir, index);
    }
    if (index < 0) return;
    while (r.state == RAY_LIVE) ray_step(r, vec3r(0.0), dir);
    rays[index] = r;
}
