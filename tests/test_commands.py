"""Commands are typed: every command class has a handler in the window that receives it (the
viewer's HANDLERS, or the editor's EDITOR_HANDLERS, which hands the rest to the viewer), every
key is bound to a command, and the viewer's own options have one declaration (ViewerSettings)
whose ranges the HUD and the checks read. No window is opened here."""

from __future__ import annotations

from dataclasses import dataclass, fields

import pytest

from krsview.editor import commands as editor_commands
from krsview.editor.handlers import EDITOR_HANDLERS
from krsview.editor.window import EDITOR_KEYS
from krsview.scene import SceneError
from krsview.scene.schema import check_value, describe_range
from krsview.scene.settings import EDITOR_SETTINGS, ViewerSettings, make_settings, settings_meta
from krsview.viewer import commands as viewer_commands
from krsview.viewer.controls import MOVES, VIEWER_KEYS
from krsview.viewer.window import HANDLERS


def missing(module: str, table: dict) -> list[str]:
    """The command classes of ``module`` that ``table`` has no handler for."""
    classes = viewer_commands.command_classes()
    return [c.__name__ for c in classes if c.__module__ == module and c not in table]


def test_every_command_class_is_handled():
    classes = viewer_commands.command_classes()
    mine = {c.__module__ for c in classes}
    assert mine == {viewer_commands.__name__, editor_commands.__name__}, mine
    assert len(classes) > 30, "the enumeration found too few commands: nothing is checked"
    assert missing(viewer_commands.__name__, HANDLERS) == []
    assert missing(editor_commands.__name__, EDITOR_HANDLERS) == []
    # the viewer takes only its own; the editor also decides some of the viewer's itself
    assert {c.__module__ for c in HANDLERS} == {viewer_commands.__name__}
    assert set(EDITOR_HANDLERS) <= set(classes)


def test_an_unhandled_command_class_is_found_and_refused():
    """Negative control: a new command nobody handles is listed, and executing it is an
    error, not a silent no-op."""

    @dataclass(frozen=True)
    class Forgotten(viewer_commands.Command):
        pass

    try:
        assert missing(__name__, HANDLERS) == ["Forgotten"]
        from krsview.viewer.window import Viewer

        v = Viewer.__new__(Viewer)  # execute needs no window to refuse
        with pytest.raises(TypeError, match="no handler for Forgotten"):
            v.execute([Forgotten()])
    finally:
        del Forgotten
        import gc

        gc.collect()


def test_every_key_gives_a_handled_command_and_keys_do_not_clash():
    for keymap, tables in ((VIEWER_KEYS, (HANDLERS,)), (EDITOR_KEYS, (HANDLERS, EDITOR_HANDLERS))):
        for key, command in keymap.items():
            assert any(type(command) in t for t in tables), key
            assert key not in MOVES, f"{key} both moves the camera and gives a command"
    assert EDITOR_KEYS.items() >= VIEWER_KEYS.items(), "the editor lost a viewer key"
    assert type(EDITOR_KEYS["ctrl+S"]) is editor_commands.Save


def test_viewer_settings_are_declared_once_with_ranges_the_schema_checks():
    names = [f.name for f in fields(ViewerSettings)]
    assert names == ["size", "target_fps", "prepass", "hud", "moving_effects"]
    defaults = ViewerSettings()
    assert (defaults.size, defaults.target_fps, defaults.prepass) == ((960, 540), 30.0, None)
    assert (defaults.hud, defaults.moving_effects) == (True, False)
    assert EDITOR_SETTINGS.size == (1280, 720) and EDITOR_SETTINGS.target_fps == 30.0
    for name in names:
        assert settings_meta(name)["help"], f"{name} has no help"
    assert describe_range(settings_meta("target_fps")) == "allowed: 1 ≤ value ≤ 240 frames/s"
    assert check_value(int | None, 64, "prepass", settings_meta("prepass")) == 64
    with pytest.raises(SceneError, match="prepass = 65: allowed: 0 ≤ value ≤ 64 pixels"):
        check_value(int | None, 65, "prepass", settings_meta("prepass"))
    s = make_settings(size=(320, 200), target_fps=60, prepass=0)
    assert (s.size, s.target_fps, s.prepass, s.hud) == ((320, 200), 60.0, 0, True)
    assert make_settings(EDITOR_SETTINGS, hud=False).size == (1280, 720)


@pytest.mark.parametrize(
    "options, message",
    [
        (dict(target_fps=0.5), "target_fps = 0.5: allowed: 1 ≤ value ≤ 240 frames/s"),
        (dict(size=(0, 100)), "size[0] = 0: allowed: 48 ≤ value ≤ 8192 pixels"),
        (dict(size=(100,)), "size = (100,): expected (width, height)"),
        (dict(hud="yes"), "hud = 'yes': expected true or false"),
        (dict(fps=30), "fps = 30: unknown option; allowed: hud, moving_effects, prepass"),
    ],
)
def test_a_bad_viewer_option_is_a_one_line_error(options, message):
    with pytest.raises(SceneError) as e:
        make_settings(**options)
    assert message in str(e.value) and "\n" not in str(e.value)
