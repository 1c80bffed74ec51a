"""Fragment-shader path: one full-screen pass writes colour, normal+depth and iterations to
float32 render targets, read back as :class:`Frame` in image order (rows top → bottom).
With ``[render] prepass`` a coarse pass over tiles first writes each tile's free distances
(prepass.glsl), which the full pass starts its rays from; the pixels of tiles free past the
far limit are written by a small pass of their own, and the full pass skips them
(context.behind_mark)."""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import moderngl
import numpy as np

from ..compile.camera import view_of
from ..compile.constants import BINDING_KRS_BLOCK, PREPASS_TARGETS
from ..compile.geometry import Compiled, compile_geometry
from ..frame import Frame
from ..scene import Geometry, Scene, SceneError
from ..scene.render import PREPASS_RATIO
from .coarse import coarse_layout, coarse_quarter, quarters
from .compute import LANE_PROBES, ComputePath, Rounds, compute_passes, path_defines
from .context import behind_mark, headless_context, set_uniforms, texture_side
from .passes import PassImage, Targets, still_ratio
from .program import SHADER_DIR, ProgramCache
from .readback import read_buffers, read_plane
from .uniforms import krs_block, variant_defines, view_uniforms

PROGRESS_BANDS = 16  # bands of rows of a first frame drawn with progress
MAX_TARGETS = 8  # render-target sizes kept (least recently used released)


class Renderer:
    def __init__(self, ctx: moderngl.Context | None = None, shader_dir: Path = SHADER_DIR):
        self.ctx = ctx or headless_context()
        self.programs = ProgramCache(self.ctx, shader_dir)
        self._ubo: moderngl.Buffer | None = None
        self._targets: dict[tuple[int, int, int], moderngl.Framebuffer] = {}
        self._coarse: dict[moderngl.Program, tuple[moderngl.Program, int, int]] = {}  # pre-pass
        # its marking pass: the free tiles' (render.frag) or the misses' (deferred.frag)
        self._free: dict[moderngl.Program, moderngl.Program] = {}
        self._blank: moderngl.Texture | None = None  # bound where the coarsest pass's parent is
        self._compute: dict[moderngl.Program, Rounds] = {}  # deferred → its compute pass
        self._rays = ComputePath(self.ctx)  # the compute path's buffers
        self._vaos: dict[moderngl.Program, moderngl.VertexArray] = {}
        self._depth = 0
        self._compiled: tuple[Geometry, tuple, Compiled] | None = None  # last geometry
        self._expanded: tuple[Scene, Geometry] | None = None  # last scene's geometry()
        self._variant: dict[moderngl.Program, tuple[dict, dict]] = {}  # defines, uniforms
        self._pass_targets: Targets | None = None  # images drawn in passes (passes.py)

    @contextmanager
    def current(self) -> Iterator[None]:
        """Make the context current for the outermost entry point only: glcontext's
        enter/exit is not re-entrant, so a nested exit would leave no context current."""
        if self._depth == 0:
            self.ctx.__enter__()
        self._depth += 1
        try:
            yield
        finally:
            self._depth -= 1
            if self._depth == 0:
                self.ctx.__exit__(None, None, None)

    def _framebuffer(self, width: int, height: int, layers: int = 3) -> moderngl.Framebuffer:
        """Render targets per size, the most recently used MAX_TARGETS kept: the viewer's
        adaptive resolution and window resizes visit many sizes, and each holds 3 textures
        (a pre-pass's: PREPASS_TARGETS) and a depth buffer (which marks the free tiles)."""
        key = (width, height, layers)
        if key in self._targets:
            self._targets[key] = self._targets.pop(key)  # most recent last
        else:
            while len(self._targets) >= MAX_TARGETS:
                old = self._targets.pop(next(iter(self._targets)))
                for part in (*old.color_attachments, old.depth_attachment):
                    part.release()
                old.release()
            made = (texture_side(width), texture_side(height))
            tex = [self.ctx.texture(made, 4, dtype="f4") for _ in range(layers)]
            depth = self.ctx.depth_renderbuffer(made)
            self._targets[key] = self.ctx.framebuffer(color_attachments=tex, depth_attachment=depth)
        return self._targets[key]

    def prepare(
        self,
        scene: Scene,
        width: int,
        height: int,
        geometry: Geometry | None = None,
        all_effects: bool = False,
        probes: tuple[str, ...] = (),
        detail_height: int = 0,
    ) -> moderngl.Program:
        """Compile (or fetch) the scene's variant and upload its uniforms; ``all_effects``
        picks the variant with every effect compiled in and switched by uniforms,
        ``probes`` the defines of a measuring variant, drawn on the fragment path (the
        tracing alone by persistent lanes too, compute.LANE_PROBES): KRS_COUNT_LEVELS counts
        the levels Alg. 1 walks (:meth:`levels`), KRS_TRACE_ONLY traces without shading
        (bench split, the passes' trace pass); ``detail_height``: see compile/camera.View."""
        with self.current():
            return self._prepare(scene, width, height, geometry, all_effects, probes, detail_height)

    def _prepare(
        self,
        scene: Scene,
        width: int,
        height: int,
        geometry: Geometry | None,
        all_effects: bool,
        probes: tuple[str, ...] = (),
        detail_height: int = 0,
    ) -> moderngl.Program:
        scene = scene.posed()  # the static scene drawn at its time (tracks, sway)
        view = view_of(scene.camera, width, height, detail_height)
        geometry = geometry or self.geometry_of(scene)
        c = self.world(geometry, scene.material.albedo).relative_to(view.origin)
        block = krs_block(c, scene.render.precision)
        storage = scene.render.precision == "double"  # scene_block.glsl: a storage buffer
        limit = self.ctx.info[
            "GL_MAX_SHADER_STORAGE_BLOCK_SIZE" if storage else "GL_MAX_UNIFORM_BLOCK_SIZE"
        ]
        if len(block) > limit:
            raise SceneError(
                "compound",
                f"<a uniform block of {len(block)} bytes>",
                f"this GPU's uniform blocks hold at most {limit} bytes, too few "
                "for a compound's 8 × 64 level slots: render its components as "
                "separate scenes",
            )
        defines = variant_defines(scene, c, all_effects)
        if scene.render.path == "compute":  # persistent lanes: one ray per pixel, no tasks
            defines = path_defines(defines, scene.render)
        # before the probes: what companion passes compile with
        variant = {k: v for k, v in defines.items() if k != "KRS_LANES"}
        if probes:
            defines.update(dict.fromkeys(probes))
            if "KRS_LANES" not in defines or not LANE_PROBES.issuperset(probes):
                defines.pop("KRS_LANES", None)
                scene = replace(scene, render=replace(scene.render, path="fragment"))
        if scene.render.path == "compute":  # trace, then shade (the misses written apart)
            prog, mark, rounds = compute_passes(self.programs, scene.render, defines)
            self._compute[prog], self._free[prog] = rounds, mark
            progs = [prog, mark, rounds.comp]
        else:
            prog = self.programs.get("fullscreen.vert", "render.frag", defines)
            progs = [prog]
        if scene.render.prepass:
            coarse = self.programs.get("fullscreen.vert", "prepass.frag", defines)
            self._coarse[prog] = (coarse, scene.render.prepass, scene.render.prepass_levels)
            progs.append(coarse)
            if prog not in self._compute:  # render.frag: its free tiles written apart
                free = {**defines, "KRS_FREE_TILES": None}
                self._free[prog] = self.programs.get("fullscreen.vert", "render.frag", free)
                progs.append(self._free[prog])
            for p in progs:  # the finest coarse pass's output, and the coarser one's before it
                for k, name in enumerate(("u_free", "u_parent")):
                    if name in p:  # unused: compiled away; only its first elements used
                        units = range(k * PREPASS_TARGETS, (k + 1) * PREPASS_TARGETS)
                        p[name].write(np.array(units[: p[name].array_length], "i4").tobytes())
        if self._ubo is None or self._ubo.size != len(block):
            self._ubo = self.ctx.buffer(block)
        else:
            self._ubo.write(block)
        if storage:
            self._ubo.bind_to_storage_buffer(BINDING_KRS_BLOCK)
        else:
            self._ubo.bind_to_uniform_block(BINDING_KRS_BLOCK)
        uniforms = view_uniforms(scene, view, c)
        for p in progs:
            if not storage and "KRSBlock" in p:
                p["KRSBlock"].binding = BINDING_KRS_BLOCK
            set_uniforms(p, uniforms)
        self._variant[prog] = (variant, uniforms)
        return prog

    def companion(
        self, prog: moderngl.Program, fragment: str, defines: dict | None = None
    ) -> moderngl.Program:
        """The full-screen pass ``fragment`` compiled with the defines of ``prog``'s variant
        (plus ``defines``) and given the uniforms :meth:`prepare` last gave ``prog``: a
        further pass over the same frame (the viewer's reduced-resolution shadows)."""
        variant, uniforms = self._variant[prog]
        with self.current():
            p = self.programs.get("fullscreen.vert", fragment, {**variant, **(defines or {})})
            if "KRS_DOUBLE" not in variant and "KRSBlock" in p:
                p["KRSBlock"].binding = BINDING_KRS_BLOCK
            set_uniforms(p, uniforms)
            return p

    def geometry_of(self, scene: Scene) -> Geometry:
        """``scene.geometry()``, made once per scene (scenes are frozen): a tree is expanded
        anew by each call, which frames of the same scene need not pay."""
        if self._expanded is None or self._expanded[0] is not scene:
            self._expanded = (scene, scene.geometry())
        return self._expanded[1]

    def world(self, geometry: Geometry, albedo: tuple) -> Compiled:
        """The geometry compiled in world coordinates, redone only when it or the albedo
        changes (a moving camera only translates it: per-frame work stays per-frame); the
        viewer's picking and navigation share it, so an edit compiles once."""
        if (
            self._compiled is None
            or self._compiled[0] is not geometry
            or self._compiled[1] != albedo
        ):
            self._compiled = (geometry, albedo, compile_geometry(geometry, albedo))
        return self._compiled[2]

    def draw(
        self,
        prog: moderngl.Program,
        width: int,
        height: int,
        tile: tuple[int, int, int, int] | None = None,
    ) -> moderngl.Framebuffer:
        """Trace the whole image, or only ``tile`` = (x, y, w, h) in GL pixel coordinates, so a
        slow full-resolution frame can be spread over several event-loop turns."""
        with self.current():
            if prog in self._coarse:
                self._prepass(prog, width, height, tile)
            if prog in self._compute:
                self._rays.trace(self._compute[prog], (prog, self._free[prog]), width, height, tile)
            fbo = self._framebuffer(width, height)
            fbo.use()
            self.ctx.viewport = (0, 0, width, height)
            self.ctx.scissor = tile
            if prog in self._free:  # its marking variant marks the pixels to skip
                behind_mark(
                    self.ctx, lambda: self._full(self._free[prog]), lambda: self._full(prog)
                )
            else:
                self._full(prog)
            self.ctx.scissor = None
            return fbo

    def _prepass(
        self,
        prog: moderngl.Program,
        width: int,
        height: int,
        tile: tuple[int, int, int, int] | None,
    ) -> None:
        """The coarse passes of ``prog``'s pre-pass over the tiles under ``tile`` (or all),
        coarsest first, each reading the one before's free distances from the texture units
        after the first PREPASS_TARGETS; the finest's are left bound to those for the full
        pass. Each pass is drawn as its quarter images (coarse.py), one draw each."""
        coarse, size, levels = self._coarse[prog]
        passes: list[tuple[int, int, int]] = []  # (tile size, columns, rows), finest first
        for k in range(levels):
            t = size * PREPASS_RATIO**k
            grid = (t, -(-width // t), -(-height // t))
            if passes and passes[-1][1:] == grid[1:]:
                break  # as coarse as the image allows
            passes.append(grid)
        parent, parent_stride = None, (0, 0)
        for t, cw, ch in reversed(passes):
            stride, target = coarse_layout(cw, ch)
            fbo = self._framebuffer(*target, layers=PREPASS_TARGETS)
            fbo.use()
            coarse["u_tile"].value = t
            coarse["u_parent_ratio"].value = PREPASS_RATIO if parent else 0
            coarse["u_layout"].value = (*stride, *parent_stride)
            # the coarsest pass reads no parent: its samplers get a texture no pass draws
            # into, so no target is ever bound for sampling while it is drawn into
            for unit, tex in enumerate(
                parent.color_attachments if parent else (self._blank_texture(),) * PREPASS_TARGETS
            ):
                tex.use(PREPASS_TARGETS + unit)
            tiles = None
            if tile is not None:
                x, y, w, h = tile
                tiles = (x // t, y // t, -(-(x + w) // t), -(-(y + h) // t))
            for rect in quarters(cw, ch, tiles):  # one draw each: no texel between them
                self.ctx.viewport = rect
                self._full(coarse)
            parent, parent_stride = fbo, stride
        for unit, tex in enumerate(parent.color_attachments):
            tex.use(unit)

    def _blank_texture(self) -> moderngl.Texture:
        if self._blank is None:
            self._blank = self.ctx.texture((1, 1), 4, bytes(16), dtype="f4")
        return self._blank

    def _full(self, prog: moderngl.Program) -> None:
        """Draw ``prog`` over the viewport (one triangle, no vertex buffer)."""
        if prog not in self._vaos:
            self._vaos[prog] = self.ctx.vertex_array(prog, [])
        self._vaos[prog].render(moderngl.TRIANGLES, vertices=3)

    def render(
        self,
        scene: Scene,
        width: int,
        height: int,
        geometry: Geometry | None = None,
        progress: Callable[[int, int], None] | None = None,
        detail_height: int = 0,
    ) -> Frame:
        """The image; with ``progress`` it is drawn in PROGRESS_BANDS bands of rows, each
        finished before progress(done, total) is called (the same pixels either way). Where
        the scene's shadow rays are shared by pixel blocks (passes.still_ratio), the image is
        drawn in passes: trace, shadow rays per block, shade. ``detail_height``: see
        :meth:`prepare`."""
        with self.current():
            ratio = still_ratio(scene)
            if ratio:
                image = self._passes(scene, (width, height), geometry, ratio, detail_height)
                bands = PROGRESS_BANDS if progress else 1
                return read_buffers(image.draw_all(bands, progress), width, height)
            prog = self.prepare(scene, width, height, geometry, detail_height=detail_height)
            if progress is None:
                return read_buffers(self.draw(prog, width, height), width, height)
            bands = min(PROGRESS_BANDS, height)
            for k in range(bands):
                y0, y1 = height * k // bands, height * (k + 1) // bands
                fbo = self.draw(prog, width, height, (0, y0, width, y1 - y0))
                self.ctx.finish()
                progress(k + 1, bands)
            return read_buffers(fbo, width, height)

    def _passes(self, scene: Scene, size, geometry: Geometry | None, ratio: int, detail=0):
        """``scene`` as a PassImage (passes.py) of ``size``; ``detail``: its detail_height."""
        if self._pass_targets is None:
            self._pass_targets = Targets(self.ctx)
        scene = scene.posed()  # the static scene drawn at its time (tracks, sway)
        geometry = geometry or self.geometry_of(scene)
        return PassImage(
            self, self._pass_targets, scene, size, geometry, ratio, detail_height=detail
        )

    def levels(
        self, scene: Scene, width: int, height: int, geometry: Geometry | None = None
    ) -> np.ndarray:
        """Per pixel (rows top → bottom), the levels Alg. 1 walked while tracing the ray (not
        shading it), summed over its steps: with culling, fewer than steps × n. Counted by
        a variant of the fragment path (the compute path takes the same steps)."""
        with self.current():
            prog = self.prepare(scene, width, height, geometry, probes=("KRS_COUNT_LEVELS",))
            fbo = self.draw(prog, width, height)
            return read_plane(fbo, 2, width, height)[..., 1].astype(np.int64)

    def free_distances(self, scene: Scene, width: int, height: int) -> np.ndarray:
        """The pre-pass's free distance per tile and component, (rows top → bottom, columns,
        MAX_COMPONENTS), for a scene with ``[render] prepass`` > 0: what each of the tile's
        rays starts from."""
        if not scene.render.prepass:
            raise ValueError(f"{scene.name}: free distances need [render] prepass > 0")
        with self.current():
            prog = self.prepare(scene, width, height)
            size = self._coarse[prog][1]
            self._prepass(prog, width, height, None)
            cw, ch = -(-width // size), -(-height // size)
            (sx, sy), (w, h) = coarse_layout(cw, ch)
            fbo = self._framebuffer(w, h, layers=PREPASS_TARGETS)
            planes = [read_plane(fbo, k, w, h) for k in range(PREPASS_TARGETS)]
            x, y = (
                np.array([q * s + c for q, c in map(coarse_quarter, range(n))])
                for s, n in ((sx, cw), (sy, ch))
            )  # each tile's texel (coarse_texel)
            texels = np.concatenate(planes, axis=-1)[y[:, None], x]
            return texels.astype(np.float64)  # rows top → bottom

    def time_frame(
        self,
        scene: Scene,
        width: int,
        height: int,
        geometry: Geometry | None = None,
        repeats: int = 1,
        all_effects: bool = False,
        prepass_only: bool = False,
        probes: tuple[str, ...] = (),
    ) -> list[float]:
        """Wall time of each of ``repeats`` frames (seconds, GPU finished), after a warm-up,
        each with its uniforms' upload (``prepare``), as a rendered frame has it;
        ``prepass_only``: of the pre-pass's coarse passes alone; ``probes``: see prepare."""
        with self.current():
            ratio = 0 if prepass_only or probes or all_effects else still_ratio(scene)
            if ratio:  # as render() draws it
                image = self._passes(scene, (width, height), geometry, ratio)
                draw = image.draw_all
            else:  # each frame prepares its program (uniforms) as render() and the passes do
                prog = functools.partial(
                    self.prepare, scene, width, height, geometry, all_effects, probes
                )
                draw = (
                    (lambda: self._prepass(prog(), width, height, None))
                    if prepass_only
                    else (lambda: self.draw(prog(), width, height))
                )
            draw()
            self.ctx.finish()
            times = []
            for _ in range(repeats):
                t0 = time.perf_counter()
                draw()
                self.ctx.finish()
                times.append(time.perf_counter() - t0)
            return times
