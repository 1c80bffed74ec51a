"""The compute path [issue 17 §3]: ``compute.comp`` traces a tile's rays in rounds, sized by
the GPU, or with persistent lanes (``steps = 0``, ``lanes.glsl``), into storage buffers that
the shading pass (``deferred.frag``) reads. The buffers' element sizes come from the structs
declared in ``compile/std430.py``; the bindings and the phases of a dispatch from
``compile/constants.py``."""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from ..compile.constants import (
    BINDING_COUNTS,
    BINDING_QUEUES,
    BINDING_RAYS,
    BINDING_SHADOWS,
    BINDING_TASKS,
    COMPUTE_GROUP,
    PHASE_LANES,
    PHASE_NEAREST,
    PHASE_ROUND,
    PHASE_SHADOW_ROUND,
    PHASE_SHADOW_START,
    PHASE_SIZE,
    PHASE_START,
)
from ..compile.std430 import COUNTS, RAY, SHADOW, base_type
from ..scene import MAX_COMPONENTS, Render
from ..scene.scene import MAX_LIGHTS
from .program import ProgramCache

# Persistent lanes: their dispatch, sized on the GPU from the pixels listed to trace, holds
# subgroups enough for this many steps per pixel, each subgroup taking at most the iteration
# cap (lanes.glsl); what they leave, a round finishes (8 left more to it: 0.89× the fragment
# path's frame inside the crown against 0.78×), and a subgroup with nothing left to take runs
# one masked step.
LANE_STEPS_PER_PIXEL = 16
LANE_BLOCK = 4  # without a pre-pass, the side of the pixel blocks the lanes take
# The measuring probes a lanes variant draws too (deferred.frag): the tracing alone, with the
# hits' kernels, as gpu/passes.py's trace pass asks for it.
LANE_PROBES = frozenset({"KRS_TRACE_ONLY", "KRS_TRACE_KERNELS"})


@dataclass(frozen=True)
class Rounds:
    """One variant's compute pass and what its buffers hold per ray."""

    comp: moderngl.ComputeShader
    steps: int  # iterations per ray per round; 0: persistent lanes
    cap: int  # the iteration cap: rounds enough for it are issued
    ray_bytes: int  # trace.glsl's Ray
    shadow_bytes: int  # shadows.glsl's Shadow; 0: no shadow tasks
    per_pixel: int  # tasks per pixel (KRS_COMPONENT_TASKS); 0: one ray per pixel
    block: int  # the side of the pixel blocks persistent lanes take: the pre-pass's tile

    @staticmethod
    def of(comp: moderngl.ComputeShader, render: Render, defines: dict) -> Rounds:
        components = MAX_COMPONENTS if "KRS_COMPOUND" in defines else 1
        real = render.precision
        return Rounds(
            comp,
            render.steps,
            render.max_iterations,
            RAY.size(real, COMPONENT_SLOTS=components),
            SHADOW.size(real, COMPONENT_SLOTS=components) if "KRS_SHADOW_TASKS" in defines else 0,
            components if "KRS_COMPONENT_TASKS" in defines else 0,
            render.prepass or LANE_BLOCK,
        )


class ComputePath:
    """The compute path's storage buffers, by binding, grown as tiles need."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.buffers: dict[int, moderngl.Buffer] = {}

    def _bind(self, sizes: dict[int, int]) -> None:
        """Bind a buffer of at least ``sizes[binding]`` bytes to each binding (0: none)."""
        for binding, size in sizes.items():
            if not size:
                continue
            if binding not in self.buffers or self.buffers[binding].size < size:
                if binding in self.buffers:
                    self.buffers[binding].release()
                self.buffers[binding] = self.ctx.buffer(reserve=max(size, 16))
            self.buffers[binding].bind_to_storage_buffer(binding)

    def trace(
        self,
        r: Rounds,
        readers: tuple[moderngl.Program, ...],
        width: int,
        height: int,
        tile: tuple[int, int, int, int] | None,
    ) -> None:
        """Trace the rays of ``tile`` (or all) and leave the ray buffer bound for the passes
        ``readers`` (deferred.frag's), in rounds or with persistent lanes (:meth:`_lanes`).
        Rounds: start the rays, run rounds of at most ``r.steps`` iterations, each sized by
        the GPU from the rays still live, enough for the iteration cap, without reading
        anything back. With a task per pixel and component, those are traced instead, and a
        last pass keeps each pixel's nearest hit in its ray."""
        comp = r.comp
        x, y, w, h = tile or (0, 0, width, height)
        area = w * h
        traced = area * max(r.per_pixel, 1)  # rays traced in rounds
        queue = max(traced, area * MAX_LIGHTS if r.shadow_bytes else area)  # the longest queue
        self._bind(
            {
                BINDING_RAYS: area * r.ray_bytes,
                BINDING_QUEUES: 2 * queue * base_type("uint")[0],
                BINDING_COUNTS: COUNTS.size(),
                BINDING_SHADOWS: area * MAX_LIGHTS * r.shadow_bytes,
                BINDING_TASKS: traced * r.ray_bytes if r.per_pixel else 0,
            }
        )
        for prog in readers:
            prog["u_tile_rect"].value = (x, y, w, h)
        self._set(
            comp,
            u_tile_rect=(x, y, w, h),
            u_area=area,
            u_queue=queue,
            u_tasks=traced,
            u_steps=r.steps or r.cap,
        )
        if not r.steps:
            self._lanes(r, (x, y, w, h))
            return
        groups = -(-area // COMPUTE_GROUP)
        self.buffers[BINDING_COUNTS].write(counts(traced, -(-traced // COMPUTE_GROUP)))
        comp["u_phase"].value = PHASE_START
        comp.run(-(-traced // COMPUTE_GROUP))
        rounds = -(-r.cap // r.steps) + 1
        self._rounds(comp, PHASE_ROUND, rounds)
        if r.per_pixel:  # each pixel's ray: the nearest of its components' hits
            self.ctx.memory_barrier()
            comp["u_phase"].value = PHASE_NEAREST
            comp.run(groups)
        if r.shadow_bytes:  # shadow rays as tasks of their own, through the same queues
            self.ctx.memory_barrier()
            self.buffers[BINDING_COUNTS].write(counts(0, 0))
            comp["u_phase"].value = PHASE_SHADOW_START
            comp.run(groups)
            self.ctx.memory_barrier()
            # size round 0 from queue 0
            comp["u_parity"].value, comp["u_phase"].value = 1, PHASE_SIZE
            comp.run(1)
            self._rounds(comp, PHASE_SHADOW_ROUND, rounds)
        self.ctx.memory_barrier()

    def _lanes(self, r: Rounds, rect: tuple[int, int, int, int]) -> None:
        """Persistent lanes (lanes.glsl) over ``rect``: list the blocks with rays to trace
        (which sizes the lanes' dispatch), let the lanes trace their pixels, then a round
        finishes what they left, sized by the last lane; nothing is read back."""
        comp, (x, y, w, h), b = r.comp, rect, r.block
        grid = ((x + w - 1) // b - x // b + 1, (y + h - 1) // b - y // b + 1)
        blocks = grid[0] * grid[1]
        self.buffers[BINDING_COUNTS].write(counts(0, 0))
        self._set(
            comp,
            u_block=b,
            u_block_grid=grid,
            u_blocks=blocks,
            u_lane_steps=LANE_STEPS_PER_PIXEL,
            u_phase=PHASE_START,
        )
        comp.run(-(-blocks // COMPUTE_GROUP))
        self.ctx.memory_barrier()
        comp["u_phase"].value = PHASE_LANES
        comp.run_indirect(self.buffers[BINDING_COUNTS], offset=COUNTS.offsets()["groups"])
        self.ctx.memory_barrier()
        comp["u_phase"].value = PHASE_ROUND
        comp.run_indirect(self.buffers[BINDING_COUNTS], offset=COUNTS.offsets()["groups"])
        self.ctx.memory_barrier()

    @staticmethod
    def _set(comp: moderngl.ComputeShader, **uniforms: object) -> None:
        """Give ``comp`` those of ``uniforms`` it uses (the compiler drops the others)."""
        for name, value in uniforms.items():
            if name in comp:
                comp[name].value = value

    def _rounds(self, comp: moderngl.ComputeShader, phase: int, rounds: int) -> None:
        """``rounds`` rounds of ``phase`` (PHASE_ROUND or PHASE_SHADOW_ROUND), each sized by
        the GPU from what the last one left live, with no read-back."""
        for k in range(rounds):
            self.ctx.memory_barrier()
            comp["u_parity"].value, comp["u_phase"].value = k % 2, phase
            comp.run_indirect(self.buffers[BINDING_COUNTS], offset=COUNTS.offsets()["groups"])
            self.ctx.memory_barrier()
            comp["u_phase"].value = PHASE_SIZE
            comp.run(1)


def compute_passes(
    programs: ProgramCache, render: Render, defines: dict
) -> tuple[moderngl.Program, moderngl.Program, Rounds]:
    """The compute path's shading pass (deferred.frag), its marking variant, which writes the
    misses so that the shading runs on the hits alone, and its tracing (compute.comp)."""
    prog = programs.get("fullscreen.vert", "deferred.frag", defines)
    mark = programs.get("fullscreen.vert", "deferred.frag", {**defines, "KRS_MISS_MARK": None})
    comp = programs.compute("compute.comp", defines)
    return prog, mark, Rounds.of(comp, render, defines)


def path_defines(defines: dict, render: Render) -> dict:
    """The compute variant's defines: with ``steps = 0``, persistent lanes (KRS_LANES) and no
    tasks, since the lanes trace one ray per pixel and the shading pass its shadow rays."""
    if render.steps:
        return defines
    tasks = ("KRS_SHADOW_TASKS", "KRS_COMPONENT_TASKS")
    return {**{k: v for k, v in defines.items() if k not in tasks}, "KRS_LANES": None}


def counts(live: int, groups: int) -> bytes:
    """compute.comp's Counts (compile/std430.py): ``live`` entries in queue 0, none in queue
    1, an indirect dispatch of ``groups`` × 1 × 1, and the lanes' counters at 0."""
    out = np.zeros(COUNTS.size() // 4, dtype=np.uint32)
    at = {name: offset // 4 for name, offset in COUNTS.offsets().items()}
    out[at["count"] : at["count"] + 2] = live, 0
    out[at["groups"] : at["groups"] + 3] = groups, 1, 1
    return out.tobytes()
