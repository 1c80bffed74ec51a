"""An image drawn in passes, each in bands of rows, so the viewer can spread it over event-loop
turns and trace its shadow rays at reduced resolution [KRS17 §8.5 traces soft shadows at ¼
resolution]. ``ratio`` picks the passes:

- 0: ``render``, render.frag with every effect in one pass (the renderer's own image);
- 1: ``trace``, the primary rays alone (render.frag with KRS_TRACE_ONLY; with
  KRS_TRACE_KERNELS it also finds each hit's kernel, which the passes after it read instead
  of walking Alg. 1 again), then ``shadows+shade``, upsampled.frag shading every pixel with
  its own shadow rays: render.frag's image in two passes, so a later image of the same view
  and size can reuse the tracing;
- r ≥ 2: ``trace``, then ``visibility``, one shadow ray per light from the nearest hit of
  each r × r block (coarse_visibility.frag: the blocks' depths, those facing a light listed
  per llvmpipe bin, then their rays alone, ``packed``), then ``shade``: each pixel takes the
  visibilities of the blocks near it at its depth, bilinearly weighted; one with none near
  its depth (an outline) traces its own. ``shade`` draws twice (llvmpipe runs every
  branch's code for every pixel): every pixel with no shadow-ray code compiled in, the
  outline pixels listed (an atomic counter), then the listed pixels alone (``packed``),
  shaded with their own rays and stored into the image;
- r ≥ 2 with ``blocks``, an earlier image of the same view with blocks of its own (a smaller
  one, or the last moving frame): ``trace``, then ``shade`` with that image's visibilities
  (its blocks mapped onto this image's pixels), so a full-resolution primary image shows
  at once, lit as the image before it, before its own shadow rays [issue 28 §5]; the image
  after it at the same size reuses its tracing and adds them.

The shading after ``trace`` (``shadows+shade``, ``shade``) is drawn by depth: the hits into a
depth buffer, then the sky's pixels with the sky's code alone and the hits with the
shading's, so that llvmpipe, which skips a group of pixels only where an early depth test
fails for all of it, never runs the shading over groups of sky (0.95× tree's frame)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import NamedTuple, Protocol

import moderngl

from ..compile.constants import BINDING_BLOCK_LIST, BINDING_OUTLINE
from ..scene import Geometry, Scene
from .bins import BIN, bin_origin, packed
from .context import behind_mark, texture_side

SHADOW_EFFECTS = frozenset({"shadows", "soft_shadows"})
DEPTH_SLACK = 3.0  # coarse pixel footprints of depth a block's sample may lie off a pixel
MAX_KEPT = 6  # targets kept (least recently used released)
SAMPLERS = (  # the passes' samplers by texture unit: the trace pass's targets, the blocks'
    *("u_traced_color", "u_traced_depth", "u_traced_iterations"),
    *("u_coarse_visibility", "u_coarse_depth"),
)


def splits_shadows(scene: Scene) -> bool:
    """Whether ``scene``'s shadow rays can be a pass of their own: it has shadows, on the
    fragment path or with persistent lanes (``steps = 0``, whose trace pass is deferred.frag's),
    in float (the trace pass hands each ray's distance on as a float)."""
    return (
        bool(SHADOW_EFFECTS & set(scene.effects))
        and (scene.render.path != "compute" or scene.render.steps == 0)
        and scene.render.precision == "float"
    )


def still_ratio(scene: Scene) -> int:
    """The passes a still image of ``scene`` is drawn in (the module's docstring): its
    ``[render] shadow_block`` where the shadows can be a pass of their own, else 0 (one pass,
    every pixel its own shadow rays)."""
    block = scene.render.shadow_block
    return block if block > 1 and splits_shadows(scene) else 0


class Tracer(Protocol):
    """What the passes need of the renderer (gpu/renderer.py): its context, its programs for
    a frame and further passes over it, and drawing a program's pass."""

    ctx: moderngl.Context

    def current(self) -> AbstractContextManager: ...

    def prepare(
        self,
        scene: Scene,
        width: int,
        height: int,
        geometry: Geometry | None = None,
        all_effects: bool = False,
        probes: tuple[str, ...] = (),
        detail_height: int = 0,
    ) -> moderngl.Program: ...

    def companion(
        self, prog: moderngl.Program, fragment: str, defines: dict | None = None
    ) -> moderngl.Program: ...

    def draw(
        self, prog: moderngl.Program, width: int, height: int, tile=None
    ) -> moderngl.Framebuffer: ...


class Outline(NamedTuple):
    """A finished image's list of outline pixels (upsampled.frag's Outline: a count, then
    the pixels), the depth that tells the shading passes hits from the sky, marked in
    ``scratch`` (no colour), and the image's colour with that depth (``shaded``)."""

    pixels: moderngl.Buffer
    scratch: moderngl.Framebuffer
    shaded: moderngl.Framebuffer
    depth: moderngl.Renderbuffer


class Targets:
    """The passes' float render targets by size, layers and slot, the MAX_KEPT most recently
    used kept. Finished images alternate between two slots, so the image on screen is never
    the one being drawn."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._kept: dict[tuple[int, int, int, int], moderngl.Framebuffer] = {}
        self._outlines: dict[moderngl.Framebuffer, Outline] = {}
        self._block_list: moderngl.Buffer | None = None
        self._lanes: moderngl.Framebuffer | None = None
        self._vaos: dict[moderngl.Program, moderngl.VertexArray] = {}
        self.flip = 0

    def get(self, size: tuple[int, int], layers: int, slot: int = 0) -> moderngl.Framebuffer:
        key = (*size, layers, slot)
        if key in self._kept:
            self._kept[key] = self._kept.pop(key)  # most recent last
            return self._kept[key]
        while len(self._kept) >= MAX_KEPT:
            old = self._kept.pop(next(iter(self._kept)))
            outline = self._outlines.pop(old, None)
            for thing in (*(outline or ()), *old.color_attachments):
                thing.release()
            old.release()
        made = tuple(map(texture_side, size))
        tex = [self.ctx.texture(made, 4, dtype="f4") for _ in range(layers)]
        self._kept[key] = self.ctx.framebuffer(color_attachments=tex)
        return self._kept[key]

    def output(self, size: tuple[int, int]) -> moderngl.Framebuffer:
        """A finished image's three targets, the other slot than the last image's."""
        self.flip ^= 1
        return self.get(size, 3, self.flip)

    def outline(self, output: moderngl.Framebuffer) -> Outline:
        """The outline list of ``output`` (made once)."""
        if output not in self._outlines:
            (w, h), depth = output.size, self.ctx.depth_renderbuffer(output.size)
            self._outlines[output] = Outline(
                self.ctx.buffer(reserve=4 * (w * h + 1)),
                self.ctx.framebuffer(depth_attachment=depth),
                self.ctx.framebuffer(output.color_attachments, depth),
                depth,
            )
        return self._outlines[output]

    def block_list(self, bins: int) -> moderngl.Buffer:
        """coarse_visibility.frag's lists of blocks, a count and room for a bin's blocks per
        bin of a coarse target (one buffer, grown for more bins)."""
        size = 4 * bins * (1 + BIN * BIN)
        if self._block_list is None or self._block_list.size < size:
            if self._block_list is not None:
                self._block_list.release()
            self._block_list = self.ctx.buffer(reserve=size)
        return self._block_list

    def lanes(self, size: tuple[int, int]) -> moderngl.Framebuffer:
        """The target of the ``packed`` passes over lists of an image of ``size``: no
        colour, room for every pixel in whole 4 × 2 groups (one target, grown as needed)."""
        w, h = -(-size[0] // 4) * 4, -(-size[1] // 2) * 2
        if self._lanes is None or self._lanes.size[0] < w or self._lanes.size[1] < h:
            if self._lanes is not None:
                w, h = max(w, self._lanes.size[0]), max(h, self._lanes.size[1])
                self._lanes.depth_attachment.release()
                self._lanes.release()
            self._lanes = self.ctx.framebuffer(depth_attachment=self.ctx.depth_renderbuffer((w, h)))
        return self._lanes

    def vao(self, prog: moderngl.Program) -> moderngl.VertexArray:
        if prog not in self._vaos:
            self._vaos[prog] = self.ctx.vertex_array(prog, [])
        return self._vaos[prog]


class PassImage:
    """One image of ``scene`` at ``size`` in passes (the module's docstring); ``traced``: an
    image of the same view and size whose trace pass this one reuses (it has none);
    ``blocks``: an image of the same view whose shadow blocks this one's shading blends (it
    traces no shadow rays but an outline's); ``detail_height``: the height of the image
    whose pixel sets the detail drawn (Renderer.prepare; 0: this one's)."""

    def __init__(
        self,
        renderer: Tracer,
        targets: Targets,
        scene: Scene,
        size: tuple[int, int],
        geometry: Geometry,
        ratio: int,
        traced: PassImage | None = None,
        blocks: PassImage | None = None,
        detail_height: int = 0,
    ):
        self.renderer, self.targets, self.detail_height = renderer, targets, detail_height
        self.scene, self.size, self.geometry, self.ratio = scene, size, geometry, ratio
        w, h = size
        self.coarse = (-(-w // max(ratio, 1)), -(-h // max(ratio, 1)))
        self.origin = bin_origin(self.coarse)  # the coarse image's corner in its target
        if ratio == 0:
            self.passes = [("render", w, h)]
        else:
            self.passes = [] if traced else [("trace", w, h)]
            if ratio > 1 and blocks is None:
                self.passes.append(("visibility", *self.coarse))
            self.passes.append(("shade" if ratio > 1 else "shadows+shade", w, h))
        self.traced = traced.traced if traced else None  # the trace pass's targets
        if blocks is not None and (blocks.ratio < 2 or ratio < 2):
            raise ValueError(f"shadow blocks of an image with ratio {blocks.ratio}: need ≥ 2")
        source = blocks or self
        # the blocks' images: their size, their coarse image, a block's side in pixels
        self.blocks = source.size, source.coarse, max(source.ratio, 1)
        self._blocks_image = source
        with renderer.current():
            self.output = targets.output(size) if ratio else None
        self._programs: dict[str, moderngl.Program] = {}

    def coarse_bins(self) -> tuple[int, int]:
        """llvmpipe's bins across the coarse target and in all: one list of blocks each."""
        (w, h), (x, y) = self.coarse, self.origin
        across = -(-(x + w) // BIN)
        return across, across * -(-(y + h) // BIN)

    def coarse_target(self) -> moderngl.Framebuffer:
        """The visibility pass's target: visibilities and depths, the coarse image at
        ``origin`` (bin_origin)."""
        (w, h), (x, y) = self.coarse, self.origin
        # a slot per origin: two coarse sizes may pad to the same target size
        return self.targets.get((x + w, y + h), 2, slot=x * BIN + y)

    def has_trace(self, size: tuple[int, int]) -> bool:
        """Whether a later image of this view at ``size`` can reuse this one's trace pass."""
        return self.ratio >= 1 and self.size == size and self.traced is not None

    def prepare(self) -> None:
        """Compile or fetch the passes' programs and upload the uniforms: at each turn's
        start, since other drawing may have happened in between."""
        probes = ("KRS_TRACE_ONLY", "KRS_TRACE_KERNELS") if self.ratio else ()
        main = self.renderer.prepare(
            self.scene, *self.size, self.geometry, probes=probes, detail_height=self.detail_height
        )
        self._programs = {"render" if not self.ratio else "trace": main}
        if self.ratio > 1:
            for name, define in (("visibility", "KRS_SHADOW_LIST"), ("rays", "KRS_SHADOW_RAYS")):
                vis = self.renderer.companion(main, "coarse_visibility.frag", {define: None})
                vis["u_shadow_ratio"].value = self.ratio
                vis["u_coarse_origin"].value = self.origin
                vis["u_bins"].value = (*self.coarse_bins(), BIN)
                self._programs[name] = vis
            (bw, bh), _, side = self.blocks
            for name, define in (("shade", "KRS_SHADOW_MARK"), ("outline", "KRS_SHADOW_OUTLINE")):
                shade = self.renderer.companion(
                    main,
                    "upsampled.frag",
                    {"KRS_SHADOW_UPSAMPLED": None, define: None},
                )
                shade["u_block"].value = (side * self.size[0] / bw, side * self.size[1] / bh)
                shade["u_depth_slack"].value = DEPTH_SLACK
                shade["u_coarse_origin"].value = self._blocks_image.origin
                shade["u_coarse_size"].value = self._blocks_image.coarse
                self._programs[name] = shade
        elif self.ratio == 1:
            self._programs["shadows+shade"] = self.renderer.companion(main, "upsampled.frag")
        if self.ratio:  # the shading's passes by depth (_shade_by_depth)
            for name, define in (("hits", "KRS_HIT_DEPTH"), ("sky", "KRS_SHADE_SKY")):
                self._programs[name] = self.renderer.companion(
                    main, "upsampled.frag", {define: None}
                )
        for prog in self._programs.values():  # the samplers' units, as draw binds them
            for unit, sampler in enumerate(SAMPLERS):
                if sampler in prog:
                    prog[sampler].value = unit
            if "u_traced_size" in prog:  # its textures may be a texel larger
                prog["u_traced_size"].value = self.size

    def draw(self, name: str, y0: int, rows: int) -> None:
        """Rows [y0, y0 + rows) (GL order) of pass ``name``; :meth:`prepare` first."""
        prog = self._programs[name]
        if name in ("render", "trace"):
            fbo = self.renderer.draw(prog, *self.size, (0, y0, self.size[0], rows))
            if name == "render":
                self.output = fbo
            else:
                self.traced = fbo
            return
        with self.renderer.current():
            for unit, tex in enumerate(self.traced.color_attachments):
                tex.use(unit)
            if name == "visibility":
                self._visibility(y0, rows)
            elif name == "shade":
                coarse = self._blocks_image.coarse_target()
                for k, tex in enumerate(coarse.color_attachments):
                    tex.use(len(self.traced.color_attachments) + k)
                self._shade_and_outline(y0, rows)
            else:
                self._shade_by_depth(self.targets.outline(self.output), y0, rows, name)

    def _fill(
        self,
        prog: moderngl.Program,
        target: moderngl.Framebuffer,
        size,
        y0: int,
        rows: int,
        origin: tuple[int, int] = (0, 0),
    ) -> None:
        """Draw ``prog`` over rows [y0, y0 + rows) of an image of ``size`` that lies at
        ``origin`` in ``target``."""
        ctx, (x, y) = self.renderer.ctx, origin
        target.use()
        ctx.viewport = (x, y, *size)
        ctx.scissor = (x, y + y0, size[0], min(rows, size[1] - y0))
        self.targets.vao(prog).render(moderngl.TRIANGLES, vertices=3)
        ctx.scissor = None

    def _visibility(self, y0: int, rows: int) -> None:
        """Rows [y0, y0 + rows) of the blocks: their depths, those facing a light listed per
        bin; then the listed blocks' shadow rays (``packed``), stored at their texels."""
        ctx, target, bins = self.renderer.ctx, self.coarse_target(), self.coarse_bins()[1]
        blocks = self.targets.block_list(bins)
        blocks.write(bytes(4 * bins))  # none listed
        blocks.bind_to_storage_buffer(BINDING_BLOCK_LIST)
        self._fill(self._programs["visibility"], target, self.coarse, y0, rows, self.origin)
        ctx.memory_barrier()  # the lists and the blocks' depths complete
        self._packed("rays", sum(memoryview(blocks.read(4 * bins)).cast("I")), target)

    def _shade_and_outline(self, y0: int, rows: int) -> None:
        """Rows [y0, y0 + rows) of the image: every pixel shaded without shadow-ray code, the
        outline pixels (those that lack a light's visibility) listed; then the listed pixels
        shaded anew with their own shadow rays (``packed``), stored over the image's."""
        ctx, outline = self.renderer.ctx, self.targets.outline(self.output)
        outline.pixels.write(bytes(4))  # none listed
        outline.pixels.bind_to_storage_buffer(BINDING_OUTLINE)
        self._shade_by_depth(outline, y0, rows, "shade")
        ctx.memory_barrier()  # the list and the shaded pixels complete
        self._packed("outline", int.from_bytes(outline.pixels.read(4), sys.byteorder), self.output)

    def _packed(self, name: str, listed: int, target: moderngl.Framebuffer) -> None:
        """Pass ``name`` over the ``listed`` entries of its list (``packed``), storing into
        ``target``'s first colour (then visible to whatever reads it)."""
        if listed:
            target.color_attachments[0].bind_to_image(0, read=False, write=True)
            prog, size = self._programs[name], packed(self.size, listed)
            prog["u_packed_width"].value = size[0]
            self._fill(prog, self.targets.lanes(self.size), size, 0, size[1])
            self.renderer.ctx.memory_barrier()

    def _shade_by_depth(self, outline: Outline, y0: int, rows: int, shading: str) -> None:
        """Rows [y0, y0 + rows) shaded by pass ``shading`` so that groups of pixels with no
        hit never run its code (llvmpipe runs a shader's every branch for each group it
        draws): the hits marked in the depth buffer (``hits``), then the sky's pixels with
        the sky's code alone and the hits with the shading's (context.behind_mark)."""

        def fill(name: str, target: moderngl.Framebuffer) -> Callable[[], None]:
            return lambda: self._fill(self._programs[name], target, self.size, y0, rows)

        behind_mark(
            self.renderer.ctx,
            fill("hits", outline.scratch),
            fill("sky", outline.shaded),
            fill(shading, outline.shaded),
        )

    def draw_all(
        self,
        bands: int = 1,
        progress: Callable[[int, int], None] | None = None,
        issued: Callable[[], None] | None = None,
    ) -> moderngl.Framebuffer:
        """Every pass (a moving frame, a headless one), each in ``bands`` bands of rows,
        ``progress(done, total)`` after each band (GPU finished), ``issued()`` once the first
        band is issued (not finished: the viewer's turn works on while it is drawn); the
        finished image's targets."""
        self.prepare()
        cuts = [(name, rows, min(bands, rows)) for name, _, rows in self.passes]
        total, done = sum(n for *_, n in cuts), 0
        for name, rows, n in cuts:
            for b in range(n):
                y0, y1 = rows * b // n, rows * (b + 1) // n
                self.draw(name, y0, y1 - y0)
                done += 1
                if done == 1 and issued is not None:
                    issued()
                if progress is not None:
                    self.renderer.ctx.finish()
                    progress(done, total)
        return self.output
