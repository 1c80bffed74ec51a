"""`krsview export html|shadertoy|mesh`: a scene taken out of krsview through
:mod:`krsview.export`."""

from __future__ import annotations

import argparse
import resource

from .. import export
from ..inputs import output_file
from ..messages import counted
from ..progress import Progress
from ..scene import MAX_LEVELS
from ..share.mesh import BRICK as MESH_BRICK
from ..share.mesh import FORMATS as MESH_FORMATS
from ..share.mesh import sampled_resolution
from . import options
from .options import SILENT_SECONDS

WEB = {  # format → (suffix, what it is); the text is the format's help and description
    "html": (
        (".html", ".htm"),
        "one self-contained page (no server, no network) that runs the "
        "scene's own specialised tracer in WebGL2: drag to orbit, wheel to zoom, "
        "double-click to reset. Open it in any current browser.",
    ),
    "shadertoy": (
        (".glsl",),
        "the same shader as one Shadertoy mainImage (scene baked "
        "in as constants; iResolution, iTime and iMouse drive the camera). Paste it into "
        "a new shader on shadertoy.com.",
    ),
}


def add(sub) -> None:
    x = sub.add_parser(
        "export",
        help="a web page, a Shadertoy shader or a mesh of a scene",
        description="Take a scene out of krsview. Examples: krsview export html tree -o "
        "tree.html; krsview export mesh sierpinski -o sierpinski.glb --resolution 128",
    )
    xsub = x.add_subparsers(dest="format", required=True, metavar="FORMAT")
    for fmt, (suffix, text) in WEB.items():
        xp = xsub.add_parser(
            fmt,
            help=text.split(" (")[0].split(":")[0],
            description=text + " Double precision cannot be exported "
            "(GLSL ES 3.00 has no fp64); the pre-pass and the compute path "
            "are left out (the same surfaces, one fragment pass).",
        )
        options.preset(xp)
        xp.add_argument(
            "-o", "--output", required=True, help=f"file to write, ending in {' or '.join(suffix)}"
        )
        options.scene_options(xp)
        xp.set_defaults(func=run_web, suffix=suffix)
    add_mesh(xsub)


def add_mesh(xsub) -> None:
    xm = xsub.add_parser(
        "mesh",
        help="a triangle mesh (.glb, .ply, .stl, .obj)",
        description="Sample the float64 reference near the surface only (an "
        "octree drops every box certified empty), extract it with marching "
        "cubes, place each vertex on the surface by bisection along its grid "
        "edge, and write it with vertex colours (not in .stl). A scene with a "
        "ground plane is unbounded: give --box.",
    )
    options.preset(xm)
    xm.add_argument(
        "-o", "--output", required=True, help="file to write, ending in " + ", ".join(MESH_FORMATS)
    )
    xm.add_argument(
        "--resolution",
        type=options.number_in("--resolution", 16, 2048),
        default=256,
        metavar="N",
        help="voxels along the side of the cube sampled, 16..2048, rounded up to 16·2^k "
        "(default 256)",
    )
    xm.add_argument(
        "--lod",
        type=options.number_in("--lod", 0.0, 4.0, float),
        default=0.5,
        metavar="VOXELS",
        help="mesh the level set this many voxels out, the "
        "renderer's level of detail: leaves thinner than a voxel thicken instead of "
        "vanishing, 0..4 (default 0.5; 0: the surface itself)",
    )
    xm.add_argument(
        "--box",
        type=options.box,
        metavar="XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX",
        help="the region to mesh (default: the scene's bounding ball)",
    )
    xm.add_argument(
        "--levels",
        type=options.number_in("--levels", 1, MAX_LEVELS),
        help="keep only the coarsest N levels",
    )
    options.time_option(xm)
    xm.set_defaults(func=run_mesh)


def run_web(args: argparse.Namespace) -> int:
    scene = options.scene_of(args)
    out = output_file(args.output, "-o", args.suffix)
    notes = (export.html if args.format == "html" else export.shadertoy)(scene, out)
    for note in notes:
        print(f"  note: {note}")
    print(f"krsview: {scene.name}: wrote {out.resolve()} ({out.stat().st_size / 1024:.0f} KiB)")
    return 0


def run_mesh(args: argparse.Namespace) -> int:
    options.require("skimage", "trimesh", extra="mesh", what="export mesh")
    scene = options.scene_of(args)
    out = output_file(args.output, "-o", MESH_FORMATS)
    print(
        f"krsview: {scene.name}: meshing at {sampled_resolution(args.resolution)} voxels a "
        "side, level set "
        f"{args.lod:g} voxel out …",
        flush=True,
    )
    bar = Progress(1, "  samples", SILENT_SECONDS)  # the bricks', then the vertices' bisections
    st = export.mesh(scene, out, args.resolution, args.lod, args.box, bar)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(
        f"  {st.triangles:,} triangles, {'watertight' if st.watertight else 'open'}; "
        f"{counted(st.bricks, 'brick')} of {(st.resolution // MESH_BRICK) ** 3} sampled, "
        f"{st.samples:,} reference samples (a dense grid: {(st.resolution + 1) ** 3:,}); "
        f"{st.seconds:.1f} s, peak memory {peak:.0f} MiB"
    )
    print(f"  wrote {out.resolve()}")
    return 0
