"""The dependency arrows of docs/architecture.md, checked from the imports: lower layers
never import higher ones, and no two modules import each other (directly or round a cycle)."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "krsview"

# room → the krsview rooms it may import (docs/architecture.md). A room is a
# package of krsview or a top-level module; one missing here fails the test, so a new room
# states its arrows. Arrows run one way: cli → app → editor → viewer → document → scene;
# viewer/editor → gpu → compile → scene → algebra; reference, oracle → compile;
# bench/share → gpu, reference; the public API (krsview/__init__.py) sits under the CLI, and
# checks its arguments by inputs → scene, as the benchmarks' functions check theirs.
BASE = {"algebra", "frame", "progress", "heatmap", "version", "messages", "files"}
ALLOWED = {
    "algebra": set(),
    "version": set(),
    "messages": set(),
    "files": set(),
    "frame": {"files", "messages"},
    "progress": set(),
    "heatmap": set(),
    "scene": {"algebra", "files", "messages"},
    "compile": {"scene", "algebra"},
    "document": {"scene", "files", "messages"},
    "reference": {"compile", "scene"} | BASE,
    "gpu": {"compile", "scene"} | BASE,
    "oracle": {"reference", "compile", "scene"} | BASE,
    "bench": {"inputs", "gpu", "reference", "oracle", "compile", "scene"} | BASE,
    "share": {"bench", "gpu", "reference", "compile", "scene"} | BASE,
    "viewer": {"document", "gpu", "reference", "compile", "scene"} | BASE,
    "editor": {"viewer", "document", "gpu", "reference", "compile", "scene"} | BASE,
    "app": {"viewer", "editor", "scene"},
    "inputs": {"scene", "messages"},
    "api": {"inputs", "share", "bench", "oracle", "gpu", "reference", "compile", "scene"} | BASE,
    "export": {"api", "inputs", "share", "scene"} | BASE,
    "": {"api", "export", "scene"} | BASE,
    "cli": {"", "api", "inputs", "export", "app", "share", "bench", "oracle", "gpu", "reference"}
    | {"compile", "scene"}
    | BASE,
    "__main__": {"cli"},
}


def imports(source: str, module: str, top_level_only: bool = False) -> set[str]:
    """krsview modules imported by ``source`` (module name like ``krsview.scene.tree``);
    ``top_level_only`` skips imports inside functions and ``if TYPE_CHECKING`` blocks."""
    tree = ast.parse(source)
    package = module.rsplit(".", 1)[0]
    out: set[str] = set()

    def visit(node: ast.AST, top: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                if not top_level_only:
                    visit(child, False)
                continue
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                if not top_level_only:
                    visit(child, top)
                continue
            if isinstance(child, ast.ImportFrom):
                base = package.split(".")
                if child.level:
                    base = base[: len(base) - child.level + 1]
                    name = ".".join(base + ([child.module] if child.module else []))
                else:
                    name = child.module or ""
                if name.startswith("krsview"):
                    out.add(name)
                    out.update(f"{name}.{a.name}" for a in child.names)
            elif isinstance(child, ast.Import):
                out.update(a.name for a in child.names if a.name.startswith("krsview"))
            visit(child, top)

    visit(tree, True)
    return out


def modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        name = ".".join(rel.parts)
        out[name.removesuffix(".__init__")] = path
    return out


def layer(module: str) -> str:
    """The room of a module: its package below krsview, or the top-level module's name; ''
    for the package face (krsview/__init__.py: the public API)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def violations(module: str, imported: set[str]) -> list[str]:
    room = layer(module)
    if room not in ALLOWED:
        return [f"{module}: room {room!r} is not in ALLOWED: state what it may import"]
    may = ALLOWED[room] | {room}
    mods = modules()
    found = set()
    for name in imported:
        # `from krsview import X`: X is a room when it is a module, else a name of the face
        target = layer(name) if name in mods or layer(name) in ALLOWED else ""
        if target not in may:
            found.add(f"{module} imports {name}")
    return sorted(found)


def test_lower_layers_never_import_higher_ones():
    found = []
    for name, path in modules().items():
        found += violations(
            name,
            imports(path.read_text(), name + (".__init__" if path.name == "__init__.py" else "")),
        )
    assert not found, "\n".join(found)


def test_the_check_catches_a_violation():
    """Negative controls: a scene module that reaches into the reference is flagged, lazily
    inside a function too; so are gpu → reference, viewer → editor and an unlisted room."""
    src = "def f():\n    from ..reference import mobius\n"
    assert violations("krsview.scene.mokrs", imports(src, "krsview.scene.mokrs")) == [
        "krsview.scene.mokrs imports krsview.reference",
        "krsview.scene.mokrs imports krsview.reference.mobius",
    ]
    src = "from ..reference.krs import distance\n"
    assert violations("krsview.gpu.renderer", imports(src, "krsview.gpu.renderer"))
    src = "from ..editor.window import Editor\n"
    assert violations("krsview.viewer.window", imports(src, "krsview.viewer.window"))
    assert violations("krsview.attic.x", set())


def type_checking_imports() -> list[str]:
    """Modules that import under ``if TYPE_CHECKING``: an arrow hidden from the run time, the
    usual cover of an import circle."""
    return sorted(
        name
        for name, path in modules().items()
        if any(
            isinstance(n, ast.If) and "TYPE_CHECKING" in ast.unparse(n.test)
            for n in ast.walk(ast.parse(path.read_text()))
        )
    )


def test_no_imports_hidden_behind_type_checking():
    assert type_checking_imports() == []


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle of the directed graph, as a path that returns to its start; None if acyclic."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def walk(n: str) -> list[str] | None:
        state[n] = 1
        stack.append(n)
        for m in sorted(graph.get(n, ())):
            if state.get(m) == 1:
                return stack[stack.index(m) :] + [m]
            if m not in state and (found := walk(m)):
                return found
        stack.pop()
        state[n] = 2
        return None

    for n in sorted(graph):
        if n not in state and (found := walk(n)):
            return found
    return None


def import_graph() -> dict[str, set[str]]:
    """module → the krsview modules it imports anywhere: at the top, inside functions and
    under ``TYPE_CHECKING`` alike (a circle closed lazily is still a circle). A module
    importing its own package's __init__, which re-exports the package's modules, is Python's
    usual layout and is not counted."""
    mods = modules()
    graph = {}
    for name, path in mods.items():
        me = name + (".__init__" if path.name == "__init__.py" else "")
        graph[name] = {
            m
            for m in imports(path.read_text(), me)
            if m in mods and m != name and not name.startswith(m + ".")
        }
    return graph


def test_no_import_cycles_between_modules():
    graph = import_graph()
    assert len(graph["krsview.viewer.window"]) > 5, "the import graph is empty: nothing is checked"
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " → ".join(cycle)


def test_the_cycle_check_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None
