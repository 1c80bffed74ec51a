"""Files written whole or not at all: a temporary file beside the target, renamed over it."""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from pathlib import Path


def write_atomic(path: str | os.PathLike, data: str | bytes) -> None:
    """Write a temporary file beside the target, then rename it over the target: text as
    UTF-8, bytes as they are. The file keeps its mode (and owner, where permitted; a new one
    gets what the umask gives, not mkstemp's 600), a link stays a link, and the folder is
    synced so that the rename survives a crash."""
    p = Path(os.path.realpath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=p.parent)
    try:
        _take_mode(fd, p)
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode("utf-8") if isinstance(data, str) else data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, p)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    folder = os.open(p.parent, os.O_RDONLY | os.O_DIRECTORY)
    try:
        os.fsync(folder)
    finally:
        os.close(folder)


def _take_mode(fd: int, target: Path) -> None:
    """Give the temporary file ``fd`` the target's mode and owner (a new file: 666 − umask)."""
    try:
        st = target.stat()
    except FileNotFoundError:
        umask = os.umask(0o022)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)
        return
    os.fchmod(fd, stat.S_IMODE(st.st_mode))
    if (st.st_uid, st.st_gid) != (os.getuid(), os.getgid()):
        # only root may give a file away; the contents are saved all the same
        with contextlib.suppress(PermissionError):
            os.fchown(fd, st.st_uid, st.st_gid)
