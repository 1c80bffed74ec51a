"""The dependency arrows of DESIGN.md, checked from the imports: lower layers never import
higher ones, and no two modules import each other (directly or round a cycle)."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "krsview"

# package → krsview packages it must not import (anything else in krsview is allowed)
FORBIDDEN = {
    "algebra": {"scene", "reference", "gpu", "app", "editor", "bench", "cli"},
    "scene": {"reference", "gpu", "app", "editor", "bench", "cli"},
    "reference": {"gpu", "app", "editor", "bench", "cli", "oracle"},
    "oracle": {"gpu", "app", "editor", "bench", "cli"},
    "gpu": {"app", "editor", "bench", "cli"},
    "bench": {"app", "editor", "cli"},
    "app": {"bench", "cli"},
    "editor": {"bench", "cli"},
    "share": {"app", "editor", "cli"},
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
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def violations(module: str, imported: set[str]) -> list[str]:
    banned = FORBIDDEN.get(layer(module), set())
    return sorted(f"{module} imports {name}" for name in imported if layer(name) in banned)


def test_lower_layers_never_import_higher_ones():
    found = []
    for name, path in modules().items():
        found += violations(
            name,
            imports(path.read_text(), name + (".__init__" if path.name == "__init__.py" else "")),
        )
    assert not found, "\n".join(found)


def test_the_check_catches_a_violation():
    """Negative control: a scene module that reaches into the reference is flagged, lazily
    inside a function too."""
    src = "def f():\n    from ..reference import mobius\n"
    assert violations("krsview.scene.mokrs", imports(src, "krsview.scene.mokrs")) == [
        "krsview.scene.mokrs imports krsview.reference",
        "krsview.scene.mokrs imports krsview.reference.mobius",
    ]


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


def test_no_import_cycles_between_modules():
    """(A module importing its own package's __init__, which re-exports the package's
    modules, is Python's usual layout and is not counted.)"""
    mods = modules()
    graph = {}
    for name, path in mods.items():
        me = name + (".__init__" if path.name == "__init__.py" else "")
        graph[name] = {
            m
            for m in imports(path.read_text(), me, top_level_only=True)
            if m in mods and m != name and not name.startswith(m + ".")
        }
    assert len(graph["krsview.app.window"]) > 5, "the import graph is empty: nothing is checked"
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " → ".join(cycle)


def test_the_cycle_check_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None
