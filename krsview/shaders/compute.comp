// The compute path [issue 17 §3]: rays live in a storage buffer (rays.glsl) and are traced
// in rounds. Each round advances every live ray by at most u_steps iterations (trace.glsl's
// ray_step: the same steps as the fragment path); a ray that is done stays in the buffer for
// the shading pass (deferred.frag) and leaves the queue, the others are appended to the next
// round's queue (an atomic counter: compaction), and the next round's dispatch size is
// written by the GPU (u_phase 2) for an indirect dispatch: no read-back between rounds. The
// queues alternate by u_parity.
// Shadow rays are tasks of their own (KRS_SHADOW_TASKS): once the primary rays are done,
// u_phase 3 starts one per hit pixel and light that shade() would trace (slot
// ray × LIGHT_SLOTS + light), and u_phase 4 runs their rounds through the same queues and
// sizing; deferred.frag then shades with their visibilities.
// A compound keeps a task per component (KRS_COMPONENT_TASKS): u_phase 0 starts one ray per
// pixel and component that steps that component alone (the others start past the far
// limit), the rounds run them, and u_phase 5 keeps each pixel's nearest hit [KRS17 §5.1].
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "prepass.glsl"
#include "rays.glsl"
#ifdef KRS_SHADOW_TASKS
#include "shadows.glsl"
layout(std430, binding = 4) buffer Shadows { Shadow shadows[]; };
#endif

#ifdef KRS_COMPONENT_TASKS
layout(std430, binding = 5) buffer Tasks { Ray tasks[]; };  // pixel × COMPONENT_SLOTS + c
#define TRACED tasks
#else
#define TRACED rays
#endif

#define GROUP 64
layout(local_size_x = GROUP) in;

layout(std430, binding = 2) buffer Queues { uint queue[]; };     // two of u_area entries
layout(std430, binding = 3) buffer Counts {
    uint count[2];       // live rays in each queue
    uint groups[3];      // the next dispatch's size (glDispatchComputeIndirect)
};

uniform int u_phase;     // 0: start the rays of the tile, 1: a round, 2: size the next
                         // round, 3: start the shadow tasks, 4: a round of shadow tasks,
                         // 5: each pixel's nearest component task (KRS_COMPONENT_TASKS)
uniform int u_parity;    // the queue this round reads
uniform int u_steps;     // iterations per ray per round
uniform uint u_area;     // width × height of u_tile_rect: the rays
uniform uint u_queue;    // the length of each queue: u_area, or u_area × LIGHT_SLOTS or
                         // × COMPONENT_SLOTS, whichever is longer
uniform uint u_tasks;    // rays traced in rounds: u_area, or u_area × COMPONENT_SLOTS

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (u_phase == 2) {                       // one invocation sizes the next round
        if (k == 0u) {
            uint next = count[1 - u_parity];
            groups[0] = (next + uint(GROUP) - 1u) / uint(GROUP);
            groups[1] = 1u;
            groups[2] = 1u;
            count[u_parity] = 0u;
        }
        return;
    }
    if (u_phase == 0) {
        if (k >= u_tasks) return;
#ifdef KRS_COMPONENT_TASKS
        uint p = k / uint(COMPONENT_SLOTS);
        int c = int(k % uint(COMPONENT_SLOTS));
#else
        uint p = k;
#endif
        ivec2 pixel = u_tile_rect.xy + ivec2(int(p) % u_tile_rect.z, int(p) / u_tile_rect.z);
        real start[COMPONENT_SLOTS];
        ray_start(pixel, start);
#ifdef KRS_COMPONENT_TASKS      // component c alone: the others start past the far limit
        for (int j = 0; j < COMPONENT_SLOTS; ++j) if (j != c) start[j] = FAR_AWAY;
        Ray r = ray_begin(start);
        if (c >= COMPONENTS) r.state = RAY_MISS;
        tasks[k] = r;
#else
        rays[k] = ray_begin(start);
#endif
        queue[k] = k;
        return;
    }
#ifdef KRS_COMPONENT_TASKS
    if (u_phase == 5) {                       // the pixel's ray: its nearest component's hit
        if (k >= u_area) return;
        Ray r = tasks[k * uint(COMPONENT_SLOTS)];
        int iterations = r.iterations;
        for (int c = 1; c < COMPONENTS; ++c) {
            Ray q = tasks[k * uint(COMPONENT_SLOTS) + uint(c)];
            iterations += q.iterations;
            if (q.state == RAY_HIT && (r.state != RAY_HIT || q.t < r.t)) r = q;
        }
        r.iterations = iterations;     // the work of all the pixel's tasks
        rays[k] = r;
        return;
    }
#endif
#ifdef KRS_SHADOW_TASKS
    if (u_phase == 3) {                       // the shadow rays shade() would trace
        if (k >= u_area) return;
        Ray r = rays[k];
        for (int j = 0; j < LIGHT_SLOTS; ++j) {
            shadows[k * uint(LIGHT_SLOTS) + uint(j)].vis = 1.0;
            shadows[k * uint(LIGHT_SLOTS) + uint(j)].state = SHADOW_DONE;
        }
        if (r.state != RAY_HIT || !shadows_on()) return;
        ivec2 pixel = u_tile_rect.xy + ivec2(int(k) % u_tile_rect.z, int(k) / u_tile_rect.z);
        vec3r dir = pixel_ray(vec2(pixel) + 0.5);
        int level;
        vec3 n, xk;
        nearest_kernel(r.t * dir, r.t, level, n, xk);     // as pixel.glsl, then shade()
        for (int j = 0; j < u_light_count; ++j) {
            if (max(dot(n, u_light_dir[j]), 0.0) <= 0.0) continue;
            uint slot = k * uint(LIGHT_SLOTS) + uint(j);
            shadows[slot] = shadow_begin(r.t * dir, n, u_light_dir[j],
                                         u_eps_per_t * float(r.t));
            queue[atomicAdd(count[0], 1u)] = slot;
        }
        return;
    }
    if (u_phase == 4) {
        if (k >= count[u_parity]) return;
        uint slot = queue[uint(u_parity) * u_queue + k];
        Shadow sh = shadows[slot];
        for (int i = 0; i < u_steps && sh.state == SHADOW_LIVE; ++i) shadow_step(sh);
        shadows[slot] = sh;
        if (sh.state == SHADOW_LIVE)
            queue[uint(1 - u_parity) * u_queue + atomicAdd(count[1 - u_parity], 1u)] = slot;
        return;
    }
#endif
    if (k >= count[u_parity]) return;
    uint ray = queue[uint(u_parity) * u_queue + k];
#ifdef KRS_COMPONENT_TASKS
    uint p = ray / uint(COMPONENT_SLOTS);
#else
    uint p = ray;
#endif
    ivec2 pixel = u_tile_rect.xy + ivec2(int(p) % u_tile_rect.z, int(p) / u_tile_rect.z);
    vec3r dir = pixel_ray(vec2(pixel) + 0.5);
    Ray r = TRACED[ray];
    for (int i = 0; i < u_steps && r.state == RAY_LIVE; ++i) ray_step(r, vec3r(0.0), dir);
    TRACED[ray] = r;
    if (r.state == RAY_LIVE) {
        queue[uint(1 - u_parity) * u_queue + atomicAdd(count[1 - u_parity], 1u)] = ray;
    }
}
