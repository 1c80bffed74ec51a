"""The Python API's arguments (krsview/inputs.py): a scene built or changed in Python is
validated as a file would be, sizes and switches and paths are checked before any work,
NumPy values are numbers, a closed Renderer gives its GL objects back, and the moment and
the level count compose. Each refusal is one line naming the argument and what is allowed;
each is set beside the call that works (the control)."""

from __future__ import annotations

import dataclasses
import gc
import subprocess
import sys

import numpy as np
import pytest

import krsview
from krsview.scene import KRS, Camera, Level, Mirror, Scene, SceneError, Sphere
from krsview.scene.presets import resolve

SIZE = (24, 14)
BALL = {"krs": {"levels": [{"kernel": {"type": "sphere", "radius": 0.5}}]}}


def one_line(e: pytest.ExceptionInfo) -> str:
    text = str(e.value)
    assert "\n" not in text
    return text


def test_a_scene_built_from_the_classes_is_validated_where_the_api_takes_it(tmp_path):
    good = krsview.Scene(krs=KRS(levels=[Level(kernel=Sphere(radius=0.5))]))
    assert krsview.render(good, SIZE).hit.any()  # control: a valid one draws
    assert np.array_equal(
        krsview.render(good, SIZE).color, krsview.render(krsview.load_dict(BALL), SIZE).color
    )
    rock = krsview.load("rock")
    bad = {
        "krs.levels[0].kernel.radius = -1.0": krsview.Scene(
            krs=KRS(levels=[Level(kernel=Sphere(radius=-1.0))])
        ),
        "krs.levels[0].kernel.radius = nan": krsview.Scene(
            krs=KRS(levels=[Level(kernel=Sphere(radius=float("nan")))])
        ),
        "a scene has exactly one geometry": krsview.Scene(),
        "render.tracer = 'bogus'": dataclasses.replace(
            rock, render=dataclasses.replace(rock.render, tracer="bogus")
        ),
        "camera.target": krsview.Scene(
            krs=rock.krs, camera=Camera(position=(0, 1, 0), target=(0, 1, 0))
        ),
        "= <krs and tree>:": dataclasses.replace(rock, tree=krsview.load("tree").tree),
    }
    for said, scene in bad.items():
        for call in (
            lambda s: krsview.render(s, SIZE),
            krsview.check,
            lambda s: krsview.save(s, tmp_path / "x.toml"),
            lambda s: krsview.configure(s, epsilon_scale=2.0),
            lambda s: krsview.Renderer(*SIZE).time(s, 1),
        ):
            with pytest.raises(krsview.SceneError) as e:
                call(scene)
            assert said in one_line(e)
    assert not (tmp_path / "x.toml").exists()
    # a mirror normal must be a unit vector, as in a file (its offset is in its units)
    turned = krsview.Scene(
        krs=KRS(levels=[Level(kernel=Sphere()), Level(mirror=Mirror(normal=(3.0, 0, 0)))])
    )
    with pytest.raises(krsview.SceneError) as e:
        krsview.render(turned, SIZE)
    assert "krs.levels[1].mirror.normal = [3.0, 0, 0]: must be a unit vector" in one_line(e)


def test_a_scene_changed_in_place_is_drawn_as_it_is_now():
    """Its lists are Python lists: popped levels draw as the shorter scene a file would
    give (not the compiled geometry of before); an effect appended is checked."""
    s = krsview.load("rock")
    before = krsview.render(s, SIZE)
    for _ in range(6):
        s.krs.levels.pop()
    after = krsview.render(s, SIZE)
    fresh = krsview.render(krsview.load_dict(krsview.scene.schema.to_dict(s)), SIZE)
    assert np.array_equal(after.color, fresh.color)
    assert not np.array_equal(after.color, before.color), "control: the change shows"
    s.effects.append("bloom")
    with pytest.raises(krsview.SceneError) as e:
        krsview.render(s, SIZE)
    assert "'bloom': unknown effect" in one_line(e)


def test_a_closed_renderer_gives_its_gl_objects_back(monkeypatch):
    from krsview.gpu import context

    released = []
    real = context.release_dropped
    monkeypatch.setattr(context, "release_dropped", lambda ctx: released.append(real(ctx)))
    with krsview.Renderer(*SIZE) as r:
        r.render("rock")
    assert released and released[-1] > 10, "its programs, targets and buffers"
    gc.collect()
    assert not krsview.api._shared_context().objects, "nothing of it left for later"
    krsview.render("rock", SIZE)  # the shared renderer of render() stays
    shared = krsview.api._shared_gpu
    krsview.Renderer(*SIZE).close()
    assert krsview.api._shared_gpu is shared


def test_the_moment_and_the_level_count_compose():
    s = krsview.load("tree-sway")
    both = krsview.render(s, SIZE, time=0.6, levels=14)
    assert np.array_equal(both.color, krsview.render(s.at(0.6).with_levels(14), SIZE).color)
    start = krsview.render(s, SIZE, time=0.0, levels=14)
    assert not np.array_equal(both.color, start.color), "control: the tree sways"
    grown = krsview.configure("tree-growing", time=5.0)
    depth = grown.geometry().depth
    assert depth > krsview.load("tree-growing").geometry().depth  # it grows
    assert krsview.configure("tree-growing", time=5.0, levels=depth).geometry().depth == depth


def test_a_renderer_times_what_it_draws(monkeypatch):
    drawn, timed = [], []
    r = krsview.Renderer(*SIZE)
    monkeypatch.setattr(r.gpu, "render", lambda s, w, h, progress=None: drawn.append(s))
    monkeypatch.setattr(r.gpu, "time_frame", lambda s, w, h, repeats: timed.append(s) or [0.0])
    for kw in ({}, {"exact": True}, {"epsilon_scale": 2.0, "levels": 9}):
        r.render("tree", **kw)
        r.time("tree", 1, **kw)
    assert drawn == timed and len(set(map(id, timed))) == 3
    assert timed[0].render.prepass and not timed[1].render.prepass  # fast, then exact


def test_numpy_values_are_numbers():
    s = krsview.load("rock")
    assert s.edit("render.epsilon_scale", np.float32(0.5)).render.epsilon_scale == 0.5
    assert s.edit("render.max_iterations", np.int64(100)).render.max_iterations == 100
    assert s.edit("camera.position", np.array([1.0, 2.0, -8.0])).camera.position == (1, 2, -8)
    assert s.with_levels(np.int64(3)).geometry().depth == 3
    assert krsview.render(s, (np.int64(16), np.int64(9))).size == (16, 9)
    assert s.with_effects(("fog",)).effects == ["fog"]
    with pytest.raises(krsview.SceneError) as e:  # control: still checked
        s.edit("render.epsilon_scale", np.float32(-1))
    assert "render.epsilon_scale = -1.0: allowed" in one_line(e)


@pytest.mark.parametrize(
    "call, said",
    [
        (lambda: krsview.render("rock", "160x90"), "size = '160x90': expected (width, height)"),
        (lambda: krsview.render("rock", 160), "size = 160: expected (width, height)"),
        (lambda: krsview.render("rock", (16, 9, 3)), "size = (16, 9, 3): expected"),
        (lambda: krsview.render("rock", SIZE, reference="yes"), "reference = 'yes': expected"),
        (lambda: krsview.render("rock", SIZE, exact=1), "exact = 1: expected True or False"),
        (lambda: krsview.render("rock", SIZE, levels="5"), "levels = '5': expected a whole"),
        (lambda: krsview.load("rock").with_levels(3.0), "levels = 3.0: expected a whole"),
        (lambda: krsview.load(None), "name_or_path = None: expected a preset's name"),
        (lambda: krsview.render({"krs": {}}, SIZE), "a dict: krsview.load_dict"),
        (lambda: krsview.load_dict([1]), "<dict> = [1]: expected a dict"),
        (lambda: krsview.certify("rock", max_segments=-1), "max_segments = -1: allowed: a whole"),
        (lambda: krsview.stability("rock", "48x27"), "size = '48x27': expected"),
        (lambda: krsview.Renderer(16, 9).render("nope"), "'nope': not a file and not a preset"),
        (lambda: krsview.Renderer(16, 9).time("rock", 0), "repeats = 0: allowed"),
        (lambda: krsview.distance("palm", [0, 0, 0]), "a MöKRS has no distance function"),
        (lambda: krsview.distance("rock", [0, 0]), "expected points of coordinates within ±1e+09"),
        (
            lambda: krsview.load("tree").edit("route.levels[3].fork", (0, 1, 0)),
            "this scene has no [route] table",
        ),
        (
            lambda: krsview.load("rock").edit("krs.levels[99].kernel.radius", 1.0),
            "krs.levels has 13 items (0..12)",
        ),
        (
            lambda: krsview.load("rock").edit("render.nope", 1.0),
            "render has no field 'nope'; its fields: tracer,",
        ),
    ],
)
def test_bad_arguments_are_refused_in_one_line(call, said):
    with pytest.raises(krsview.SceneError) as e:
        call()
    assert said in one_line(e)


def test_files_are_checked_before_any_work(tmp_path):
    import krsview.export as export

    blocker = tmp_path / "a-file"
    blocker.write_text("")
    frames = tmp_path / "frames"
    frames.mkdir()
    cases = [
        (lambda: export.html("rock", blocker / "x.html"), "a-file' is a file, not a folder"),
        (lambda: export.html("rock", "/proc/no/x.html"), "cannot write there"),
        (lambda: export.html("rock", tmp_path / "x.txt"), "must end in .html"),
        (lambda: export.mesh("rock", tmp_path / "m.xyz"), "must end in .glb, .ply, .stl or .obj"),
        (lambda: export.mesh("rock", tmp_path / "m.ply", resolution=0), "resolution = 0"),
        (lambda: export.mesh("rock", tmp_path / "m.ply", resolution="64"), "resolution = '64'"),
        (lambda: export.mesh("rock", tmp_path / "m.ply", lod=float("nan")), "lod = nan"),
        (
            lambda: export.mesh("rock", tmp_path / "m.ply", box=(3, 3, 3, -3, -3, -3)),
            "each max (the last three) must exceed its min",
        ),
        (lambda: export.video(frames, tmp_path / "v.mp4"), "has no frame_00000.png"),
        (lambda: export.video(frames, tmp_path / "v.avi"), "must end in .mp4"),
        (lambda: krsview.save("rock", tmp_path / "r.json"), "must end in .toml"),
    ]
    for call, said in cases:
        with pytest.raises(krsview.SceneError) as e:
            call()
        assert said in one_line(e)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file", "frames"], "nothing written"
    frame = krsview.render("rock", SIZE)
    # a suffix Pillow does not know, one it reads but cannot write (FITS), one it writes
    # only in one bit per pixel (XBM): each refused before a byte is written (the last two
    # were raw KeyError and OSError half-way through the save)
    for suffix, said in (
        (".foo", "writes no .foo"),
        (".fits", "writes no .fits"),
        (".xbm", "mode RGB"),
    ):
        with pytest.raises(krsview.SceneError) as e:
            frame.save(tmp_path / f"x{suffix}")
        assert said in one_line(e) and "allowed: .png, .npz" in one_line(e), suffix
    with pytest.raises(krsview.SceneError, match="a file name of 304 bytes; allowed: at most"):
        frame.save(tmp_path / ("a" * 300 + ".png"))  # its temporary file's name, too
    with pytest.raises(krsview.SceneError, match="cannot hold a NUL"):
        frame.save(str(tmp_path / "x\0.png"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file", "frames"], "nothing written"
    png = frame.save(tmp_path / "x.png")  # control
    assert frame.save(tmp_path / "x.tif").exists()  # control: another format, in colour
    assert frame.save(tmp_path / ("b" * 230 + ".png")).exists()  # control: a long name fits
    # a link stays a link, and the file it names gets the image (the save replaced the link)
    (tmp_path / "frames" / "linked.png").write_bytes(b"old")
    (tmp_path / "link.png").symlink_to(tmp_path / "frames" / "linked.png")
    frame.save(tmp_path / "link.png")
    assert (tmp_path / "link.png").is_symlink()
    assert (tmp_path / "frames" / "linked.png").read_bytes() == png.read_bytes()
    # a folder, a place under a file, a place that cannot be written: one line, as the
    # API's other writers say (these were raw OSErrors), and no file left half written
    (tmp_path / "d.png").mkdir()
    (tmp_path / "saves").mkdir()
    for bad, said in (
        (tmp_path / "d.png", "is a folder; give a file name"),
        (tmp_path / "saves", "is a folder; give a file name"),  # said 'no suffix' before
        (tmp_path / "a-file" / "x.png", "a-file' is a file, not a folder"),
    ):
        with pytest.raises(krsview.SceneError) as e:
            frame.save(bad)
        assert said in one_line(e), bad
    with pytest.raises(OSError) as e:  # a write that fails names the file asked for
        frame.save("/proc/x.png")
    assert e.value.filename == "/proc/x.png" and ".tmp" not in one_line(e)
    assert not list(tmp_path.glob(".*.tmp*")) and png.exists()
    with pytest.raises(krsview.SceneError, match="not a frame written by Frame.save"):
        krsview.Frame.load(png)
    with pytest.raises(krsview.SceneError, match="cannot read: No such file"):
        krsview.Frame.load(tmp_path / "none.npz")


def test_save_writes_what_load_reads(tmp_path):
    built = krsview.Scene(krs=KRS(levels=[Level(kernel=Sphere(radius=0.25))]), name="ball")
    out = krsview.save(built, tmp_path / "sub" / "ball.toml")
    assert krsview.load(out) == built
    edited = krsview.load("bent-tree").edit("route.levels[2].fork", (0.1, 2.0, 0.3))
    assert krsview.load(krsview.save(edited, tmp_path / "b.toml")) == edited
    assert krsview.load(out) != edited  # control


def test_none_is_what_a_file_leaving_the_field_out_gets():
    """``edit(path, None)`` gives the field its default, as a file without it reads."""
    s = krsview.load("tree-sway")
    assert s.name != "untitled" and s.animation is not None  # control: what changes
    assert s.edit("name", None).name == "untitled" == krsview.Scene().name
    assert s.edit("animation", None).animation is None
    with pytest.raises(krsview.SceneError, match="exactly one geometry"):
        s.edit("tree", None)  # a table the scene needs: refused, not emptied


def test_distance_is_the_kernels_at_points():
    """One ball of radius 0.5 at the origin: |p| − 0.5, inside negative; a mirror at x = 0.8
    doubles it (the nearer copy counts)."""
    p = np.array([[0.0, 2.0, 0.0], [0.0, 0.0, 0.0], [3.0, 4.0, 0.0]])
    assert np.allclose(krsview.distance(krsview.load_dict(BALL), p), [1.5, -0.5, 4.5])
    two = {
        "krs": {
            "levels": [*BALL["krs"]["levels"], {"mirror": {"normal": [1, 0, 0], "offset": 0.8}}]
        }
    }
    d = krsview.distance(krsview.load_dict(two), [[1.6, 0.0, 0.0], [3.0, 0.0, 0.0]])
    assert np.allclose(d, [-0.5, 0.9]), "the mirrored copy at x = 1.6"
    assert krsview.distance("grove", np.zeros((2, 2, 3))).shape == (2, 2)


def test_export_and_bench_come_with_a_plain_import():
    code = "import krsview; print(krsview.export.html.__name__, krsview.bench.__name__)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.stdout.split() == ["html", "krsview.bench"], r.stderr


def test_a_files_prepass_0_is_off_and_none_given_is_the_fast_default(tmp_path):
    """`prepass = 0` in a file turns the pre-pass off for `render` and the viewer (it was
    taken for "not given" and drawn at VIEW_PREPASS); a file that gives none gets the fast
    default, and saving it writes none."""
    from krsview.api import fast_settings
    from krsview.scene.render import VIEW_PREPASS

    s = krsview.load("sierpinski")
    assert s.render.prepass is None and fast_settings(s).render.prepass == VIEW_PREPASS
    off = krsview.load(krsview.save(s.edit("render.prepass", 0), tmp_path / "off.toml"))
    assert off.render.prepass == 0 and fast_settings(off).render.prepass == 0
    given, fast = krsview.render(off, SIZE), krsview.render(s, SIZE)
    assert given.iterations.mean() > fast.iterations.mean(), "control: the pre-pass spares steps"
    assert "prepass =" not in krsview.save(s, tmp_path / "s.toml").read_text()


def test_a_second_round_of_misuse_is_refused_in_one_line(tmp_path):
    """What a second newcomer's review found: NumPy arrays inside the scene's classes,
    a string for the effect list, a NumPy time, malformed edit paths, a progress that is no
    function, points that are no points, an empty name; each has its control beside it."""
    import pickle

    import numpy as np

    ball = krsview.Scene(krs=KRS(levels=[Level(kernel=Sphere(center=np.zeros(3), radius=0.5))]))
    assert krsview.check(ball).instances == 1  # an array in a class field: a list of numbers
    plain = krsview.Scene(krs=KRS(levels=[Level(kernel=Sphere(radius=0.5))]))
    assert np.array_equal(krsview.render(ball, SIZE).color, krsview.render(plain, SIZE).color)
    assert krsview.api.scene_of(ball).krs.levels[0].kernel.center == (0.0, 0.0, 0.0)
    saved = krsview.save(ball.edit("render.epsilon_scale", np.float32(2.0)), tmp_path / "b.toml")
    assert krsview.load(saved).render.epsilon_scale == 2.0
    refusals = [
        (lambda: krsview.render("rock", SIZE, effects="sky"), "effects = 'sky': expected a list"),
        # the advice is one that works (it said "e.g. ['none']", itself refused)
        (lambda: krsview.render("rock", SIZE, effects="none"), "list of effect names; none is []"),
        (lambda: krsview.load("rock").with_effects(None), "effects = None: expected a list"),
        (lambda: krsview.load("rock").edit("krs.levels[0.kernel", 1), "expected field names and"),
        (lambda: krsview.load("rock").edit(None, 1), "path = None: expected a path"),
        (  # a knob the tracer ignores, refused as the command line refuses it
            lambda: krsview.render("rock", SIZE, relaxation=1.5),
            "relaxation = 1.5: applies to tracer='relaxed' (this traces sphere)",
        ),
        # a tuple path: -1 does not count from the end, True is no index (IndexError, or
        # silently level 1, before), and an empty path names nothing
        (
            lambda: krsview.load("bent-tree").edit(("route", "levels", -24, "fork"), (0, 2, 0)),
            "path = ('route', 'levels', -24, 'fork'): expected field names and list indices ≥ 0",
        ),
        (
            lambda: krsview.load("bent-tree").edit(("route", "levels", True, "fork"), (0, 2, 0)),
            "path = ('route', 'levels', True, 'fork'): expected field names",
        ),
        (lambda: krsview.load("rock").edit((), 1), "path = (): expected field names"),
        (lambda: krsview.load("rock").edit("", 1), "path = '': expected field names"),
        (
            lambda: krsview.load("bent-tree").edit("route.levels[-1].fork", (0, 2, 0)),
            "path = 'route.levels[-1].fork': expected field names and list indices ≥ 0",
        ),
        (lambda: krsview.render("rock", SIZE, progress=3), "progress = 3: expected a function"),
        (lambda: krsview.distance("rock", "abc"), "points = 'abc': expected"),  # not nan
        (
            lambda: krsview.distance("rock", ["a", "b", "c"]),
            "expected points of coordinates within ±1e+09",
        ),
        (
            lambda: krsview.distance("rock", [[1, 2, 3], [1, 2]]),
            "expected points of coordinates within ±1e+09",
        ),
        (
            lambda: krsview.distance("rock", [1j, 0, 0]),
            "expected points of coordinates within ±1e+09",
        ),
        # far beyond the scene's own limit the distance overflowed to NaN or ∞ [review]
        (lambda: krsview.distance("tree-wind", [1e155, 1, 0]), "within ±1e+09"),
        (lambda: krsview.load(""), "name_or_path = '': expected"),
        # a lone surrogate validated, then failed the save with a UnicodeEncodeError; a
        # newline or an escape in a name split or coloured the lines it is printed in
        (lambda: krsview.load("rock").edit("description", "\ud800"), "or lone surrogates"),
        (lambda: krsview.load("rock").edit("name", "a\nb"), "one line of text, without"),
        (lambda: krsview.load("rock").edit("name", "\x1b[31mred"), "without control"),
    ]
    for call, said in refusals:
        with pytest.raises(krsview.SceneError) as e:
            call()
        assert said in one_line(e)
    bent, fork = krsview.load("bent-tree"), (0.1, 2.0, 0.0)  # a NumPy index is an index
    by_numpy = bent.edit(("route", "levels", np.int64(3), "fork"), fork)
    assert by_numpy == bent.edit("route.levels[3].fork", fork) != bent
    named = krsview.load("rock").edit("description", "tabs\tand é ✓ 木")  # control: kept
    assert (
        krsview.load(krsview.save(named, tmp_path / "named.toml")).description == named.description
    )
    sway = krsview.load("tree-sway")
    assert sway.at(np.float32(0.6)).time == 0.6  # the decimal it shows
    error = pickle.loads(pickle.dumps(krsview.SceneError("a", 1, "b", "f.toml")))
    assert str(error) == "f.toml: a = 1: b"  # a pool's worker's error reaches it whole
    a, b = krsview.render("rock", SIZE), krsview.render("rock", SIZE)
    assert a != b and a == a  # identity, not an ambiguous array comparison
    assert b.save(tmp_path / "new" / "f.png").exists()


def test_a_prepass_knob_of_none_is_the_fast_default_and_a_dropped_renderer_is_given_back():
    from krsview.api import _shared_context, on_hardware
    from krsview.scene.render import HARDWARE_PREPASS, VIEW_PREPASS

    drawn = []
    r = krsview.Renderer(*SIZE)
    r.gpu.render = lambda s, w, h, progress=None: drawn.append(s.render.prepass)
    r.render("tree", prepass=None)
    r.render("tree", prepass=0)
    r.render("tree", exact=True, prepass=None)  # exact's own: none
    assert drawn == [HARDWARE_PREPASS if on_hardware() else VIEW_PREPASS, 0, 0]
    dropped = krsview.Renderer(*SIZE)
    dropped.render("rock")
    del dropped
    assert krsview.Renderer(*SIZE).gpu is not None  # a new one gives back the dropped's
    assert not _shared_context().objects


def test_saving_over_a_scene_file_keeps_its_comments(tmp_path):
    path = tmp_path / "tree.toml"
    text = "# my notes\n" + resolve("tree").read_text()
    path.write_text(text)
    krsview.save(krsview.load(path).edit("render.epsilon_scale", 2.0), path)
    now = path.read_text()
    assert now.startswith("# my notes\n") and "[0.5, 0.8, -0.35]" in now
    assert len(now.splitlines()) == len(text.splitlines())
    assert krsview.load(path).render.epsilon_scale == 2.0


def test_scenes_hash_by_value():
    a, b = krsview.load("tree"), krsview.load("tree")
    other = a.edit("render.lod", 1.0)
    assert hash(a) == hash(b) and len({a, b, other}) == 2
    assert {a: "tree"}[b] == "tree"
    # negative control: the hash follows the values, as == does
    assert hash(other) != hash(a) and other != a


def test_with_levels_validates_the_scene_first():
    with pytest.raises(SceneError, match="exactly one geometry"):
        Scene().with_levels(1)
    assert krsview.load("tree").with_levels(5).geometry().depth == 5


FORK = """
import krsview, multiprocessing as mp
def work(eps):
    try:
        return krsview.render("rock", (16, 9), epsilon_scale=eps).size
    except RuntimeError as e:
        return str(e)
if __name__ == "__main__":
    krsview.render("rock", (16, 9))
    for method in ("fork", "spawn"):
        with mp.get_context(method).Pool(1) as p:
            print(method, p.map(work, [0.5])[0])
"""


def test_a_process_forked_after_drawing_is_told_to_spawn(tmp_path):
    """A pool forked after the parent drew waited forever on the parent's rasteriser
    threads (a new context in the child waits alike): the child now says why in one line.
    The control: a spawned pool draws."""
    script = tmp_path / "pool.py"
    script.write_text(FORK)
    out = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=120
    ).stdout.splitlines()
    assert out[0].startswith("fork krsview: this process was forked after krsview had drawn")
    assert "get_context('spawn')" in out[0]
    assert out[1] == "spawn (16, 9)"


@pytest.mark.parametrize(
    "call, said",
    [
        (lambda b: b.bench_levels("sierpinski", (0, 0), rounds=1), "size = (0, 0): expected"),
        (lambda b: b.bench_levels("sierpinski", (16, 9), step=0), "step = 0: allowed"),
        (lambda b: b.bench_split("sierpinski", (16, 9), rounds=0), "rounds = 0: allowed"),
        (lambda b: b.bench_paths("no-such", (16, 9)), "scene = 'no-such': not a file"),
        (lambda b: b.bench_zoom("tree", (16, 9), stops_count=1), "stops_count = 1: allowed"),
        (lambda b: b.bench_peer("tree", (16, 0)), "size = (16, 0): expected"),
        (lambda b: b.bench_peer_zoom("tree", (16, 9), stops_count=1), "stops_count = 1: allowed"),
        (lambda b: b.bench_peer_zoom("tree", (16, 9), levels=0), "levels = 0: allowed"),
        (lambda b: b.bench_peer_zoom("palm", (16, 9)), "one KRS into triangles"),
    ],
)
def test_the_benchmarks_check_their_arguments_first(call, said):
    """``krsview.bench``'s functions crashed deep inside on a preset's name, a size of 0, a
    step or rounds of 0 (AttributeError, ZeroDivisionError, StatisticsError); they take
    what the API takes and refuse the rest in one line."""
    with pytest.raises(SceneError) as e:
        call(krsview.bench)
    assert said in one_line(e)


def test_the_benchmarks_are_named_in_krsview_bench():
    """The control: a preset's name runs, and ``dir`` lists the benchmarks."""
    assert "bench_levels" in dir(krsview.bench)
    m = krsview.bench.bench_levels("sierpinski", (16, 9), step=8, rounds=1)
    assert m.rows and m.scene.name == "sierpinski"


def test_a_scenes_statistics_read_as_check_prints_them():
    """``str(krsview.check(...))`` was the dataclass's repr, empty fields and all; it is the
    text `krsview check` prints (the CLI's own call), and the Scene class says what it is."""
    info = krsview.check("grove")
    text = str(info)
    assert text.startswith("grove\n") and "geometry        compound of 8" in text
    assert info.text("grove.toml").startswith("grove.toml: ok — grove\n")
    assert "SceneInfo(" not in text and "parts=" not in text
    assert "scene file holds" in krsview.Scene.__doc__


def test_a_render_knob_checks_only_the_rules_that_read_render(monkeypatch):
    """A [render] knob's edit meets the rules that read [render] (the tracer's; the keys of
    tracks on render values), not every track's keys against the MöKRS's view again, and a
    scene so configured, or given the fast settings, is not validated whole again where the
    API takes it: on animated palm-curl each was 0.7–1.1 s, and `krsview render palm-curl
    --exact` took 40 s. Controls: a camera edit checks the view, a scene changed outside the
    schema is validated whole, and the tracer's rule still refuses."""
    import krsview.scene.edits as edits
    import krsview.scene.scene as scene_module
    from krsview import api

    palm = krsview.load("palm-curl")
    views, wholes = [], []
    view, whole = scene_module.check_view, edits.validated
    monkeypatch.setattr(scene_module, "check_view", lambda *a: views.append(1) or view(*a))
    monkeypatch.setattr(edits, "validated", lambda s: wholes.append(1) or whole(s))
    fast = krsview.configure(api.fast_settings(palm), prepass=0, max_iterations=300)
    exact = krsview.configure(api.exact_settings(palm), epsilon_scale=0.5)
    krsview.configure(fast, time=1.0)
    assert (fast.render.prepass, fast.render.max_iterations) == (0, 300)
    assert exact.render.lod == 0.0 and exact.render.epsilon_scale == 0.5
    assert views == [] and wholes == []
    with pytest.raises(SceneError) as e:
        krsview.configure(palm, tracer="sphere")
    assert "render.tracer = 'sphere'" in one_line(e) and "binary" in one_line(e)

    moved = palm.edit("camera.position", [p + 0.01 for p in palm.camera.position])
    assert len(views) > 0 and wholes == []  # a camera edit checks the MöKRS's view
    outside = dataclasses.replace(palm, render=dataclasses.replace(palm.render, prepass=2))
    krsview.configure(api.fast_settings(outside), prepass=1)
    krsview.configure(moved, prepass=1)
    assert len(wholes) == 1  # the scene changed outside the schema, once; the edit's not
