"""Camera-path frames and video [issue 18 §3]: each frame is the headless render of its
camera (computed here from the pose by the fly camera's formula, not by the code under test),
chunks and resumed runs give the same files, and the video holds the frames."""

from __future__ import annotations

import json
import math
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from krsview.scene import Camera, SceneError, load_scene
from krsview.scene.camera_path import CameraPath, Pose, load_camera_path
from krsview.scene.presets import resolve
from krsview.share.frames import FrameJob, frame_file, parse_frames, render_frames

from .conftest import headless_render, krsview_cli

SIZE = (64, 36)
FPS = 4.0
# tree's camera looks along +z with y up; three poses 0.5 s apart, turning and climbing
POSES = [
    dict(t=10.0, position=[0.0, 2.0, -9.0], yaw=0.0, pitch=0.0),
    dict(t=10.5, position=[0.5, 2.5, -8.0], yaw=0.3, pitch=0.1),
    dict(t=11.0, position=[1.0, 2.5, -7.0], yaw=-0.2, pitch=0.1),
]


@pytest.fixture
def path_file(tmp_path):
    f = tmp_path / "tree.path.json"
    f.write_text(json.dumps({"poses": POSES}))
    return f


def render_path(path_file: Path, out: Path, *options: str) -> subprocess.CompletedProcess:
    """`krsview render tree` of the frames along ``path_file`` at SIZE and FPS into ``out``."""
    size = f"{SIZE[0]}x{SIZE[1]}"
    args = ("--camera-path", str(path_file), "--size", size, "--fps", str(FPS), "-o", str(out))
    return krsview_cli("render", "tree", *args, *options)


def read(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB")).astype(int)


def expected_camera(position, yaw: float, pitch: float, base: Camera) -> Camera:
    """y up: yaw 0 looks along +z, yaw > 0 turns towards +x, pitch > 0 looks up."""
    d = (math.cos(pitch) * math.sin(yaw), math.sin(pitch), math.cos(pitch) * math.cos(yaw))
    target = tuple(p + c for p, c in zip(position, d))
    return Camera(tuple(position), target, base.up, base.fov_y)


def test_poses_interpolate_linearly_and_clamp(path_file):
    path = load_camera_path(path_file)
    assert path.duration == 1.0 and path.frame_count(FPS) == 5
    mid = path.pose_at(0.25)
    assert np.allclose(mid.position, [0.25, 2.25, -8.5]) and math.isclose(mid.yaw, 0.15)
    assert path.pose_at(-1).position == (0.0, 2.0, -9.0)
    assert path.pose_at(5).yaw == -0.2
    # yaw turns the short way round across ±π
    wrap = CameraPath((Pose(0, (0, 0, 0), 3.0, 0), Pose(1, (0, 0, 0), -3.0, 0)))
    assert math.isclose(wrap.pose_at(0.5).yaw, math.pi, rel_tol=1e-12)


def test_scene_time_advances_with_the_frames_from_the_scenes_own(path_file, tmp_path):
    path = load_camera_path(path_file)
    scene = load_scene(resolve("tree"))
    times = [FrameJob(scene, path, FPS, SIZE, tmp_path).frame_scene(k).time for k in range(5)]
    assert times == [k / FPS for k in range(5)]
    later = FrameJob(scene.at(2.0), path, FPS, SIZE, tmp_path)  # krsview render --time 2
    assert [later.frame_scene(k).time for k in range(3)] == [2.0 + k / FPS for k in range(3)]
    assert (
        later.frame_scene(2).camera
        == FrameJob(scene, path, FPS, SIZE, tmp_path).frame_scene(2).camera
    ), "the start time moved the camera"


def test_each_frame_is_the_headless_render_of_its_camera(path_file, tmp_path):
    r = render_path(path_file, tmp_path / "frames")
    assert r.returncode == 0, r.stderr
    assert "frames 0-4 of 5" in r.stdout and "0 already there, 5 to render" in r.stdout
    scene = load_scene(resolve("tree"))
    for k, pose in ((0, POSES[0]), (2, POSES[1]), (4, POSES[2])):
        cam = expected_camera(pose["position"], pose["yaw"], pose["pitch"], scene.camera)
        ref = headless_render(replace(scene, camera=cam), tmp_path / f"ref{k}", SIZE)
        frame = read(frame_file(tmp_path / "frames", k))
        assert (np.abs(frame - ref).max(-1) <= 2).mean() >= 0.999, k
    # negative control: a frame is not its neighbour
    assert (np.abs(read(frame_file(tmp_path / "frames", 1)) - ref).max(-1) > 2).mean() > 0.05


def test_chunks_and_an_interrupted_run_give_the_same_files(path_file, tmp_path, renderer):
    scene = load_scene(resolve("tree"))
    path = load_camera_path(path_file)
    whole, chunks = tmp_path / "whole", tmp_path / "chunks"
    whole.mkdir(), chunks.mkdir()
    render_frames(FrameJob(scene, path, FPS, SIZE, whole), list(range(5)), renderer)

    class Interrupted(Exception):
        pass

    def stop_after_two(k):
        if k == 1:
            raise Interrupted

    job = FrameJob(scene, path, FPS, SIZE, chunks)
    with pytest.raises(Interrupted):
        render_frames(job, [3, 4, 0, 1, 2], renderer, stop_after_two)  # a chunk, then a crash
    assert sorted(p.name for p in chunks.iterdir()) == [
        frame_file(chunks, k).name for k in (0, 1, 3, 4)
    ]  # whole files
    assert job.missing(range(5)) == [2]
    # a frame cut short or overwritten since (by a full disk, by hand) is not "already
    # there": it was counted so, and the video step then refused a frame of 0×0 [review]
    f3 = frame_file(chunks, 3)
    f3.write_bytes(f3.read_bytes()[:-20])
    frame_file(chunks, 4).write_bytes(b"not a png")
    assert job.missing(range(5)) == [2, 3, 4]  # control above: the whole ones stay
    render_frames(job, job.missing(range(5)), renderer)
    for k in range(5):
        assert np.array_equal(read(frame_file(whole, k)), read(frame_file(chunks, k))), k
    junk = tmp_path / "junk"  # a folder of an older run (no frames.json) holding no PNG
    junk.mkdir()
    frame_file(junk, 0).write_bytes(b"not a png")
    with pytest.raises(SceneError, match="holds frame_00000.png, not a PNG image of 64×36"):
        FrameJob(scene, path, FPS, SIZE, junk).claim()


def test_a_resumed_run_skips_the_frames_already_written(path_file, tmp_path):
    out = tmp_path / "frames"
    assert render_path(path_file, out, "--frames", "1-3").returncode == 0
    assert sorted(p.name for p in out.glob("*.png")) == [f"frame_0000{k}.png" for k in (1, 2, 3)]
    stamps = {k: frame_file(out, k).stat().st_mtime_ns for k in (1, 2, 3)}
    r = render_path(path_file, out)
    assert "3 already there, 2 to render" in r.stdout
    assert {k: frame_file(out, k).stat().st_mtime_ns for k in (1, 2, 3)} == stamps
    assert len(list(out.glob("*.png"))) == 5


def test_a_folder_of_another_runs_frames_is_refused(path_file, tmp_path):
    """A resumed run kept any frame there: another size broke the video (ffmpeg wrote it
    anyway, exit 0), another scene showed in it. The folder's frames.json says what made
    its frames; a folder without it is judged by its frames' size."""
    import krsview.export

    out = tmp_path / "frames"
    assert render_path(path_file, out, "--frames", "0-1").returncode == 0
    base = ("--camera-path", str(path_file), "--fps", str(FPS), "-o", str(out))
    other = ("render", "tree", *base, "--size", "48x28")
    r = krsview_cli(*other)
    assert r.returncode == 2 and "holds frames of another run (its size differs)" in r.stderr
    r = krsview_cli("render", "rock", *base, "--size", f"{SIZE[0]}x{SIZE[1]}")
    assert r.returncode == 2 and "(its scene and render differ)" in r.stderr
    # this run, resumed with --exact: said as such, naming the settings apart ("its scene
    # differs" read as if the folder held another scene)
    r = krsview_cli(*other[:-1], f"{SIZE[0]}x{SIZE[1]}", "--exact")
    assert r.returncode == 2 and "this run's frames drawn with other render settings" in r.stderr
    assert "lod: 0.5 there, 0.0 here;" in r.stderr and "--exact or not" in r.stderr
    (out / "frames.json").unlink()  # frames an older krsview wrote
    r = krsview_cli(*other)
    assert r.returncode == 2 and "holds frame_00000.png of 64×36, not 48×28" in r.stderr
    assert render_path(path_file, out).returncode == 0, "control: the same run resumes"
    Image.new("RGB", (10, 10)).save(frame_file(out, 4))
    with pytest.raises(SceneError, match="frame_00004.png is 10×10, frame 0 of the video 64×36"):
        krsview.export.video(out, tmp_path / "v.mp4")
    assert not list(tmp_path.glob("*.mp4")) and not list(tmp_path.glob(".*.tmp*"))


def test_the_video_holds_the_frames(path_file, tmp_path):
    import imageio_ffmpeg

    out, video = tmp_path / "frames", tmp_path / "fly.mp4"
    r = render_path(path_file, out, "--video", str(video))
    assert r.returncode == 0, r.stderr
    reader = imageio_ffmpeg.read_frames(str(video))
    meta = next(reader)
    assert tuple(meta["size"]) == SIZE and meta["fps"] == 4.0
    decoded = [np.frombuffer(f, np.uint8).reshape(SIZE[1], SIZE[0], 3).astype(int) for f in reader]
    assert len(decoded) == 5
    for k in range(5):
        assert np.abs(decoded[k] - read(frame_file(out, k))).mean() < 4, k  # lossy, close
    assert np.abs(decoded[0] - read(frame_file(out, 4))).mean() > 8  # and in order


@pytest.mark.parametrize(
    "args, message",
    [
        (["--frames", "3-9"], "--frames = '3-9': the path has frames 0-4 at this frame rate"),
        (["--frames", "x"], "--frames = 'x': expected FIRST-LAST or one frame number"),
        (["--video", "v.avi"], "--video = 'v.avi': the file must end in .mp4"),
        (["--size", "63x36", "--video", "v.mp4"], "--video needs an even width and height"),
        (["-o", "f.png"], "-o = 'f.png': with --camera-path, give a folder for the frames"),
        (["--buffers", "b.npz"], "--buffers = 'b.npz': cannot be combined with --camera-path"),
        (["--view", "iterations"], "--view = 'iterations': cannot be combined with"),
        (["--repeats", "50"], "--repeats = 50: cannot be combined with --camera-path"),
        (["--legend-max", "9"], "--legend-max = 9: cannot be combined with --camera-path"),
        (["--frames", "3-"], "--frames = '3-': expected FIRST-LAST"),  # it drew frame 3 alone
    ],
)
def test_bad_camera_path_options_are_one_line_errors(path_file, tmp_path, args, message):
    r = krsview_cli(
        "render",
        "tree",
        "--camera-path",
        str(path_file),
        "--fps",
        "4",
        *(["-o", str(tmp_path / "f")] if "-o" not in args else []),
        *args,
    )
    assert r.returncode == 2 and message in r.stderr and len(r.stderr.splitlines()) == 1, r.stderr
    assert not (tmp_path / "f").exists(), "a refused run makes no folder"


@pytest.mark.parametrize(
    "text, message",
    [
        ("{", "not JSON"),
        ('{"poses": []}', "poses = []: a non-empty list"),
        ('{"poses": [{"t": 0, "position": [1, "x", 0], "yaw": 0, "pitch": 0}]}', "poses[0]"),
        ('{"poses": [{"t": 0, "position": [1, 2], "yaw": 0, "pitch": 0}]}', "3-vector"),
        (
            '{"poses": [{"t": 1, "position": [0, 0, 0], "yaw": 0, "pitch": 0},'
            ' {"t": 0, "position": [0, 0, 0], "yaw": 0, "pitch": 0}]}',
            "poses[1].t = 0.0: times must",
        ),
        ('{"poses": [{"t": 0, "position": [0, 0, 0], "yaw": 0, "pitch": 2}]}', "−π/2 < pitch"),
        ('{"poses": [{"t": 0, "position": [0, 0, NaN], "yaw": 0, "pitch": 0}]}', "finite"),
        # a pose's time far out: the run checked every frame of the path and hung [review]
        (
            '{"poses": [{"t": 0, "position": [0, 0, 0], "yaw": 0, "pitch": 0},'
            ' {"t": 1e9, "position": [0, 0, 0], "yaw": 0, "pitch": 0}]}',
            "poses[1].t = 1000000000.0: a path lasts at most 1e+06 s",
        ),
        (
            '{"poses": [{"t": 0, "position": [0, 0, 0], "yaw": 0, "pitch": 0, "roll": 1}]}',
            "poses[0].roll = 1: unknown key; a pose has t, position, yaw, pitch",
        ),
        ('{"poses": [{"t": 0, "position": [0, 2e9, 0], "yaw": 0, "pitch": 0}]}', "±1e+09"),
        # JSON keeps the last of a key given twice; which one the author meant is a guess
        (
            '{"poses": [{"t": 0, "position": [0, 0, 0], "yaw": 0, "yaw": 1, "pitch": 0}]}',
            "key 'yaw' given twice in one object",
        ),
        ('[{"t": 0, "position": [0, 0, 0], "yaw": 0, "pitch": 0}]', "a JSON array: an object"),
        ('{"poses": [1]}', "poses[0] = 1: an object with t, position, yaw, pitch"),
        # float() alone took true as 1 and "1.5" as 1.5
        ('{"poses": [{"t": true, "position": [0, 0, 0], "yaw": 0, "pitch": 0}]}', "True is not"),
        ('{"poses": [{"t": 0, "position": [0, 0, "1.5"], "yaw": 0, "pitch": 0}]}', "'1.5' is not"),
    ],
)
def test_a_damaged_path_file_names_the_file_and_the_pose(tmp_path, text, message):
    f = tmp_path / "bad.path.json"
    f.write_text(text)
    with pytest.raises(SceneError) as e:
        load_camera_path(f)
    assert message in str(e.value) and str(f) in str(e.value)
    r = krsview_cli("render", "tree", "--camera-path", str(f), "-o", str(tmp_path / "out"))
    assert r.returncode == 2 and message in r.stderr and len(r.stderr.splitlines()) == 1


def test_frames_outside_the_path_are_refused():
    assert parse_frames(None, 5) == range(5) and parse_frames("2", 5) == range(2, 3)
    with pytest.raises(SceneError, match="allowed 0 ≤ FIRST ≤ LAST ≤ 4"):
        parse_frames("4-2", 5)


def test_frames_are_named_alike_for_frames_and_video():
    """``which`` took a string in export.frames and a range in export.video, and neither
    checked it (an int or a range crashed deep inside): both take every form now, and
    anything else is refused in one line."""
    for which, wanted in (("1-3", range(1, 4)), ("2", range(2, 3)), (2, range(2, 3))):
        assert parse_frames(which, 5, "which") == wanted
    assert parse_frames(range(1, 4), 5, "which") == range(1, 4)
    for bad in (2.5, range(0, 4, 2), True, [1, 2]):
        with pytest.raises(SceneError, match="which = .*: expected 'FIRST-LAST'"):
            parse_frames(bad, 5, "which")
    with pytest.raises(SceneError, match="the folder has frames 0-1; allowed"):
        parse_frames(range(0, 7), 2, "which", "the folder has frames {}")


def test_a_video_of_odd_sized_frames_is_refused_before_ffmpeg(path_file, tmp_path):
    """ffmpeg refuses odd sides (H.264 4:2:0) and wrote an empty .mp4 that the call
    returned as done. Control: even frames make a video."""
    import krsview.export

    scene = load_scene(resolve("rock"))
    odd = krsview.export.frames(scene, path_file, tmp_path / "odd", (33, 19), FPS, "0-1")
    with pytest.raises(SceneError, match="its frames are 33×19: a video needs an even width"):
        krsview.export.video(odd[0].parent, tmp_path / "odd.mp4")
    assert not list(tmp_path.glob("*.mp4")) and not list(tmp_path.glob(".*.tmp*"))
    even = krsview.export.frames(scene, path_file, tmp_path / "even", (32, 18), FPS, 1)
    video = krsview.export.video(even[0].parent, tmp_path / "even.mp4", which="1")
    assert video.stat().st_size > 0


TURNING_UP = """name = "turning"
[tree]
levels = 6
up = [1.0, 0.0, 0.0]
[[animation.tracks]]
path = "tree.up"
interpolation = "linear"
keys = [[0.0, [1.0, 0.0, 0.0]], [KEY, [-1.0, 0.0, 0.0]]]
"""


def test_a_track_that_breaks_its_rule_between_keys_is_refused_before_any_frame(tmp_path):
    """tree.up through the zero vector half way (t = 0.5 s, frame 2 at 4 fps): the run used to
    draw the frames before it and stop there, leaving frames and no video [review]."""
    f = tmp_path / "turning.toml"
    f.write_text(TURNING_UP.replace("KEY", "1.0"))
    path = tmp_path / "p.path.json"
    path.write_text(json.dumps({"poses": POSES}))
    out = tmp_path / "frames"
    r = krsview_cli(
        "render", str(f), "--camera-path", str(path), "--fps", str(FPS), "--size", "32x18",
        "-o", str(out), "--video", str(tmp_path / "v" / "v.mp4"),
    )  # fmt: skip
    assert r.returncode == 2 and len(r.stderr.splitlines()) == 1, r.stderr
    assert f"{f}: animation.tracks[0] at t = 0.5 s" in r.stderr and "zero vector" in r.stderr
    assert not out.exists() and not (tmp_path / "v").exists(), "a refused run made folders"
    # control: keys 1.1 s apart put the zero between frames (0.55 s): every frame draws
    f.write_text(TURNING_UP.replace("KEY", "1.1"))
    r = krsview_cli(
        "render", str(f), "--camera-path", str(path), "--fps", str(FPS), "--size", "32x18",
        "-o", str(out), "--frames", "1-2",
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in out.glob("*.png")) == ["frame_00001.png", "frame_00002.png"]


@pytest.mark.parametrize("exact", [False, True])
def test_the_apis_frames_are_the_command_lines(path_file, tmp_path, exact):
    """export.frames drew the scene as given (no pre-pass), `render --camera-path` with the
    fast settings: two sets of frames under one name [review]. Both settle alike now, so the
    API resumes the command line's folder (a folder of other frames is refused)."""
    import krsview

    out = tmp_path / "f"
    r = render_path(path_file, out, "--frames", "0-1", *(["--exact"] if exact else []))
    assert r.returncode == 0, r.stderr
    cli = [read(frame_file(out, k)) for k in (0, 1)]
    files = krsview.export.frames("tree", path_file, out, SIZE, FPS, exact=exact)
    assert len(files) == 5 and all(f.exists() for f in files)  # resumed: 2 there, 3 drawn
    api = tmp_path / "api"
    krsview.export.frames("tree", path_file, api, SIZE, FPS, "0-1", exact=exact)
    for k in (0, 1):
        assert np.array_equal(read(frame_file(api, k)), cli[k]), k
    with pytest.raises(SceneError, match="frames drawn with other render settings"):  # control
        krsview.export.frames("tree", path_file, out, SIZE, FPS, exact=not exact)
