"""Undo and redo over immutable scenes (the three.js editor's History, docs/architecture.md).

A step keeps the scene before and after it; scenes are frozen dataclasses that share every
unchanged part, so a step costs little. Consecutive steps of one interaction (a gizmo drag, a
slider drag) merge into one step: the merge is keyed on the interaction, never on a timer.
A step also keeps a memo of the caller's own state around it (the editor: what was
selected), so that undo and redo bring that back with the scene, as Blender's do.
"""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass, replace

from ..scene import Scene

MAX_STEPS = 2000  # older steps are forgotten first


@dataclass(frozen=True)
class Step:
    label: str
    before: Scene
    after: Scene
    interaction: Hashable | None = None  # steps of one interaction merge; None never merges
    memo_before: Hashable | None = None  # the caller's state when the step was taken
    memo_after: Hashable | None = None  # ... and when it was undone (what redo brings back)
    written: bool = False  # written to the file when taken (the viewer's bookmark): so are
    # its undo and redo (Document.undo)


class History:
    def __init__(self) -> None:
        self.steps: list[Step] = []
        self.index = 0  # steps[:index] are done, steps[index:] can be redone

    def push(self, step: Step) -> None:
        del self.steps[self.index :]
        last = self.steps[-1] if self.steps else None
        if (
            last is not None
            and step.interaction is not None
            and last.interaction == step.interaction
        ):
            step = Step(last.label, last.before, step.after, step.interaction, last.memo_before)
            self.steps[-1] = step
        else:
            self.steps.append(step)
        if len(self.steps) > MAX_STEPS:
            del self.steps[0]
        self.index = len(self.steps)

    @property
    def can_undo(self) -> bool:
        return self.index > 0

    @property
    def can_redo(self) -> bool:
        return self.index < len(self.steps)

    def undo(self, memo: Hashable | None = None) -> Step | None:
        """Step back: the step undone (its ``before`` is the scene now), which keeps
        ``memo``, the caller's state before undoing, for redo; None if there is none."""
        if not self.can_undo:
            return None
        self.index -= 1
        step = self.steps[self.index] = replace(self.steps[self.index], memo_after=memo)
        return step

    def redo(self) -> Step | None:
        """Step forward: the step redone (its ``after`` is the scene now); None if none."""
        if not self.can_redo:
            return None
        self.index += 1
        return self.steps[self.index - 1]

    def labels(self) -> tuple[list[str], list[str]]:
        """(done, undone) step labels, oldest first: for the history panel."""
        return (
            [s.label for s in self.steps[: self.index]],
            [s.label for s in self.steps[self.index :]],
        )
