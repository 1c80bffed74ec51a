"""Progress bars (krsview/progress.py, drawn by tqdm): a bar redrawn in place on a terminal,
silent when stderr is a file or a pipe (no carriage returns in logs), and silent for work
quicker than its delay."""

from __future__ import annotations

import fcntl
import os
import pty
import struct
import subprocess
import sys
import termios

STEPS = "from krsview.progress import Progress; p = Progress(3, 'work', {delay}); " + (
    "[p.step(f'item {{k}}') for k in range(3)]"
)


def run_steps(delay: float, terminal: bool) -> bytes:
    """stderr of three steps of a bar, written to a terminal (a pty) or to a pipe."""
    code = STEPS.format(delay=delay)
    if not terminal:
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=60)
        return r.stderr
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    subprocess.run([sys.executable, "-c", code], stderr=follower, timeout=60, check=True)
    os.close(follower)
    out = b""
    try:
        while chunk := os.read(leader, 4096):
            out += chunk
    except OSError:  # the terminal closed: everything is read
        pass
    os.close(leader)
    return out


def test_a_bar_draws_on_a_terminal_and_nothing_in_a_pipe():
    shown = run_steps(0.0, terminal=True)
    assert b"\r" in shown and b"work" in shown and b"3/3" in shown and b"item 2" in shown
    assert run_steps(0.0, terminal=False) == b""


def test_quick_work_shows_no_bar_even_on_a_terminal():
    assert b"work" not in run_steps(5.0, terminal=True)


def test_render_into_a_pipe_logs_no_carriage_returns(tmp_path):
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "krsview",
            "render",
            "sierpinski",
            "--size",
            "48x27",
            "--repeats",
            "3",
            "-o",
            str(tmp_path / "s.png"),
        ],
        capture_output=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    assert b"\r" not in r.stdout + r.stderr
    assert b"frame time" in r.stdout  # the log has the report itself
