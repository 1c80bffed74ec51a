"""`krsview COMMAND`: the command line, a thin layer over the Python API (:mod:`krsview`,
:mod:`krsview.export`, :mod:`krsview.bench`). Each command group is a module with ``add``
(its parser) and the functions its parsers call; a command parses, calls the API and prints
what it returns."""

from __future__ import annotations

import argparse
import os
import re
import sys

from ..inputs import unmake_folders
from ..scene import SceneError
from ..scene.presets import preset_names
from ..version import __version__
from . import batch, bench, check, export, render, window

EXIT_SCENE, EXIT_GL = 2, 3  # a user's mistake (as argparse's usage errors); the environment
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports Ctrl+C

COMMANDS = (  # in the order `krsview --help` lists them
    render.add,  # render
    window.add,  # view, edit
    check.add,  # check
    export.add,  # export html|shadertoy|mesh
    batch.add,  # batch
    bench.add,  # bench levels|paths|split|tracers|effects|accuracy
)

EXAMPLES = """examples:
  krsview render tree -o tree.png --size 640x360
  krsview check grass
  krsview bench levels tree
  krsview render palm --view iterations --exact -o palm-iterations.png
  krsview bench tracers tree
  krsview view forest
  krsview export html tree -o tree.html

`krsview COMMAND --help` says more about each command."""


class Parser(argparse.ArgumentParser):
    """argparse's parser, whose mistakes are one line (not the usage block above them), as
    a scene file's are; ``--help`` has the usage. Its subcommands' parsers are of this
    class too."""

    def error(self, message: str):
        self.exit(EXIT_SCENE, f"{self.prog}: error: {message} (`{self.prog} --help` lists all)\n")


def build_parser() -> argparse.ArgumentParser:
    p = Parser(
        prog="krsview",
        description="Render, check and benchmark Kernel–Reflection Sequence scenes [KRS17]. "
        "A PRESET is a scene file (.toml) or the name of a shipped preset: "
        f"{', '.join(preset_names()) or 'none found'}.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--version", action="version", version=f"krsview {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in COMMANDS:
        add(sub)
    return p


_NEGATIVE = re.compile(r"^-(\d|\.\d|inf|nan)", re.IGNORECASE)


def join_negative_values(argv: list[str]) -> list[str]:
    """``--size -5x3`` → ``--size=-5x3``: argparse takes a value that starts with '-' for an
    option ("expected one argument"); joined, the option's own check says what is wrong."""
    out: list[str] = []
    for token in argv:
        if out and out[-1].startswith("--") and "=" not in out[-1] and _NEGATIVE.match(token):
            out[-1] += "=" + token
        else:
            out.append(token)
    return out


def main(argv: list[str] | None = None) -> int:
    argv = join_negative_values(sys.argv[1:] if argv is None else list(argv))
    args = build_parser().parse_args(argv)
    try:
        code = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, inside the try, not at exit
        return code
    except SceneError as e:
        unmake_folders()  # a refused command leaves no empty folder behind
        print(f"krsview: error: {e}", file=sys.stderr)
        return EXIT_SCENE
    except RuntimeError as e:  # ContextError, ShaderError, MissingExtra: the environment
        print(f"krsview: error: {e}", file=sys.stderr)
        return EXIT_GL
    except KeyboardInterrupt:  # Ctrl+C: what was written is whole (atomic writes)
        print("\nkrsview: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `krsview check tree | head`: the reader has gone
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as e:  # a disk full, a folder gone while writing: the environment
        where = f"{e.filename}: " if e.filename else ""
        print(f"krsview: error: {where}{e.strerror or e}", file=sys.stderr)
        return EXIT_GL
