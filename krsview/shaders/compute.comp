// The compute path [issue 17 §3]: rays live in a storage buffer (rays.glsl) and are traced
// in rounds. Each round advances every live ray by at most u_steps iterations (trace.glsl's
// ray_step: the same steps as the fragment path); a ray that is done stays in the buffer for
// the shading pass (deferred.frag) and leaves the queue, the others are appended to the next
// round's queue (an atomic counter: compaction), and the next round's dispatch size is
// written by the GPU (PHASE_SIZE) for an indirect dispatch: no read-back between rounds. The
// queues alternate by u_parity.
// Shadow rays are tasks of their own (KRS_SHADOW_TASKS): once the primary rays are done,
// PHASE_SHADOW_START starts one per hit pixel and light that shade() would trace (slot
// ray × MAX_LIGHTS + light), and PHASE_SHADOW_ROUND runs their rounds through the same queues
// and sizing; deferred.frag then shades with their visibilities.
// A compound keeps a task per component (KRS_COMPONENT_TASKS): PHASE_START starts one ray per
// pixel and component that steps that component alone (the others start past the far
// limit), the rounds run them, and PHASE_NEAREST keeps each pixel's nearest hit [KRS17 §5.1].
// With KRS_LANES (`steps = 0`), persistent lanes trace the primary rays instead (lanes.glsl).
// The phases, bindings and COMPUTE_GROUP are compile/constants.py's; Counts is declared for
// Python in compile/std430.py (COUNTS).
#ifdef KRS_LANES
#extension GL_ARB_shader_group_vote : require
#endif
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "prepass.glsl"
#include "rays.glsl"
#ifdef KRS_SHADOW_TASKS
#include "shadows.glsl"
layout(std430, binding = BINDING_SHADOWS) buffer Shadows { Shadow shadows[]; };
#endif

#ifdef KRS_COMPONENT_TASKS
// pixel × COMPONENT_SLOTS + c
layout(std430, binding = BINDING_TASKS) buffer Tasks { Ray tasks[]; };
#define TRACED tasks
#else
#define TRACED rays
#endif

layout(local_size_x = COMPUTE_GROUP) in;

layout(std430, binding = BINDING_QUEUES) buffer Queues { uint queue[]; };  // two of u_queue
layout(std430, binding = BINDING_COUNTS) buffer Counts {
    uint count[2];       // live rays in each queue
    uint groups[3];      // the next dispatch's size (glDispatchComputeIndirect)
    uint taken;          // lanes.glsl: pixels the lanes took
    uint lanes_done;     // lanes.glsl: lanes that have finished
};

uniform int u_phase;     // PHASE_*: what this dispatch does
uniform int u_parity;    // the queue this round reads
uniform int u_steps;     // iterations per ray per round
uniform uint u_area;     // width × height of u_tile_rect: the rays
uniform uint u_queue;    // the length of each queue: u_area, or u_area × MAX_LIGHTS or
                         // × COMPONENT_SLOTS, whichever is longer
uniform uint u_tasks;    // rays traced in rounds: u_area, or u_area × COMPONENT_SLOTS

// The pixel of the p-th ray of the tile (row by row).
ivec2 tile_pixel(uint p) {
    return u_tile_rect.xy + ivec2(int(p) % u_tile_rect.z, int(p) / u_tile_rect.z);
}

// Entry k of the queue the next round reads: appended, the next free place taken atomically.
void requeue(uint k) {
    queue[uint(1 - u_parity) * u_queue + atomicAdd(count[1 - u_parity], 1u)] = k;
}

#ifdef KRS_LANES
#include "lanes.glsl"
#endif

// PHASE_SIZE: one invocation sizes the next round from the rays this one left live.
void size_next_round(uint k) {
    if (k != 0u) return;
    uint next = count[1 - u_parity];
    groups[0] = (next + uint(COMPUTE_GROUP) - 1u) / uint(COMPUTE_GROUP);
    groups[1] = 1u;
    groups[2] = 1u;
    count[u_parity] = 0u;
}

// PHASE_START: ray (or component task) k begins, queued for the first round.
void start_ray(uint k) {
    if (k >= u_tasks) return;
#ifdef KRS_COMPONENT_TASKS
    uint p = k / uint(COMPONENT_SLOTS);
    int c = int(k % uint(COMPONENT_SLOTS));
#else
    uint p = k;
#endif
    real start[COMPONENT_SLOTS];
    ray_start(tile_pixel(p), start);
#ifdef KRS_COMPONENT_TASKS      // component c alone: the others start past the far limit
    for (int j = 0; j < COMPONENT_SLOTS; ++j) if (j != c) start[j] = FAR_AWAY;
    Ray r = ray_begin(start);
    if (c >= COMPONENTS) r.state = RAY_MISS;
    tasks[k] = r;
#else
    rays[k] = ray_begin(start);
#endif
    queue[k] = k;
}

// PHASE_ROUND: the k-th live ray of this round takes up to u_steps steps.
void ray_round(uint k) {
    if (k >= count[u_parity]) return;
    uint ray = queue[uint(u_parity) * u_queue + k];
#ifdef KRS_COMPONENT_TASKS
    uint p = ray / uint(COMPONENT_SLOTS);
#else
    uint p = ray;
#endif
    vec3r dir = pixel_ray(vec2(tile_pixel(p)) + 0.5);
    Ray r = TRACED[ray];
    for (int i = 0; i < u_steps && r.state == RAY_LIVE; ++i) ray_step(r, vec3r(0.0), dir);
    TRACED[ray] = r;
    if (r.state == RAY_LIVE) requeue(ray);
}

#ifdef KRS_COMPONENT_TASKS
// PHASE_NEAREST: pixel k's ray is its nearest component's hit, with all its tasks' work.
void nearest_task(uint k) {
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
}
#endif

#ifdef KRS_SHADOW_TASKS
// PHASE_SHADOW_START: the shadow rays shade() would trace from pixel k's hit, queued.
void start_shadows(uint k) {
    if (k >= u_area) return;
    Ray r = rays[k];
    for (int j = 0; j < MAX_LIGHTS; ++j) {
        shadows[k * uint(MAX_LIGHTS) + uint(j)].vis = 1.0;
        shadows[k * uint(MAX_LIGHTS) + uint(j)].state = SHADOW_DONE;
    }
    if (r.state != RAY_HIT || !shadows_on()) return;
    vec3r dir = pixel_ray(vec2(tile_pixel(k)) + 0.5);
    int level;
    vec3 n, xk;
    nearest_kernel(r.t * dir, r.t, r.slots, level, n, xk);     // as pixel.glsl, then shade()
    for (int j = 0; j < u_light_count; ++j) {
        if (max(dot(n, u_light_dir[j]), 0.0) <= 0.0) continue;
        uint slot = k * uint(MAX_LIGHTS) + uint(j);
        shadows[slot] = shadow_begin(r.t * dir, n, u_light_dir[j], u_eps_per_t * float(r.t));
        queue[atomicAdd(count[0], 1u)] = slot;
    }
}

// PHASE_SHADOW_ROUND: the k-th live shadow ray of this round takes up to u_steps steps.
void shadow_round(uint k) {
    if (k >= count[u_parity]) return;
    uint slot = queue[uint(u_parity) * u_queue + k];
    Shadow sh = shadows[slot];
    for (int i = 0; i < u_steps && sh.state == SHADOW_LIVE; ++i) shadow_step(sh);
    shadows[slot] = sh;
    if (sh.state == SHADOW_LIVE) requeue(slot);
}
#endif

void main() {
    uint k = gl_GlobalInvocationID.x;
#ifdef KRS_LANES
    if (u_phase == PHASE_LANES) lanes();
    else if (u_phase == PHASE_START) list_block(k);
    else if (u_phase == PHASE_ROUND) lanes_rest(k);
    else
#endif
    if (u_phase == PHASE_SIZE) size_next_round(k);
    else if (u_phase == PHASE_START) start_ray(k);
#ifdef KRS_COMPONENT_TASKS
    else if (u_phase == PHASE_NEAREST) nearest_task(k);
#endif
#ifdef KRS_SHADOW_TASKS
    else if (u_phase == PHASE_SHADOW_START) start_shadows(k);
    else if (u_phase == PHASE_SHADOW_ROUND) shadow_round(k);
#endif
    else if (u_phase == PHASE_ROUND) ray_round(k);
}
