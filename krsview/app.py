"""The application shell: opens the window for ``krsview view`` or ``krsview edit`` and runs
its loop until it is closed."""

from __future__ import annotations

from pathlib import Path


def view(path: Path, **options) -> None:
    """Fly through the scene file at ``path``; ``options``: fields of
    :class:`krsview.scene.settings.ViewerSettings` (a bad one is a SceneError)."""
    from .viewer.window import Viewer

    viewer = Viewer(path, **options)
    print(
        f"krsview: viewing {viewer.path} — WASD/QE fly, right-drag look, scroll speed, "
        "O orbit, R reset, B bookmark, F5/F6 record/replay, F12 screenshot, F1 HUD, "
        "Ctrl+Z/Ctrl+Shift+Z undo/redo"
    )
    viewer.run()


def edit(path: Path, **options) -> None:
    """Shape the scene file at ``path``; ``options``: fields of
    :class:`krsview.scene.settings.ViewerSettings` (defaults: EDITOR_SETTINGS)."""
    from .editor.window import Editor

    editor = Editor(path, **options)
    print(
        f"krsview: editing {editor.path} — click a handle, an outline entry or the tree to "
        "select; drag the gizmo; Ctrl+Z/Ctrl+Shift+Z undo/redo, Ctrl+S save; right-drag "
        "looks, WASD/QE fly"
    )
    editor.run()


def drag_latency(path: Path, size: tuple[int, int], steps: int) -> list[dict]:
    """`krsview bench latency`: drag a fork of the scene at ``path`` in an editor window of
    ``size`` for ``steps`` turns; one row of medians and p90s (krsview.editor.latency)."""
    from .editor import latency

    return latency.summary(latency.drag_latency(path, size, steps))
