"""A traced frame: the per-pixel outputs of the GPU renderer and of the NumPy reference alike
(rows top → bottom), as NumPy arrays, with ways to save and show them."""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .files import write_atomic
from .messages import SceneError, name_too_long, under_a_file


@dataclass(eq=False)  # arrays: == would be ambiguous; compare the arrays themselves
class Frame:
    """``color`` (H, W, 3) display colour in [0, 1] (gamma-encoded); ``depth`` (H, W) ray
    distance t to the hit, 0 where missed; ``normal`` (H, W, 3) unit world normal, 0 where
    missed; ``iterations`` (H, W) distance evaluations spent by the tracer; ``hit`` (H, W)
    bool."""

    color: np.ndarray
    depth: np.ndarray
    normal: np.ndarray
    iterations: np.ndarray
    hit: np.ndarray

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return self.hit.shape[1], self.hit.shape[0]

    def rgb8(self) -> np.ndarray:
        """The colour as (H, W, 3) uint8."""
        return np.round(np.clip(self.color, 0.0, 1.0) * 255.0).astype(np.uint8)

    def image(self):
        """The colour as a PIL image."""
        from PIL import Image

        return Image.fromarray(self.rgb8(), "RGB")

    def save(self, path: str | Path) -> Path:
        """Write the colour (``.png``, or any format Pillow writes by the suffix) or every
        array (``.npz``), whole or not at all (the file's bytes are made in memory first, then
        written to a temporary file beside it and renamed; a link stays a link, and the file
        it points to is written); returns the path. A suffix neither writes (Pillow reads
        some formats it cannot write, or not in colour), a folder, a name the system refuses,
        or a place under a file is refused in one line (SceneError, a ValueError) before
        anything is written; a write that fails (a disk full) is an OSError naming ``path``,
        and leaves nothing behind."""
        if not isinstance(path, (str, Path)) or str(path) == "":
            raise SceneError("path", path, "expected a file's path")
        if "\0" in str(path):
            raise SceneError("path", repr(str(path)), "a file name cannot hold a NUL character")
        path = Path(path)
        if why := name_too_long(path):
            raise SceneError("path", str(path), why)
        if path.is_dir():  # first: a folder has no suffix to ask about
            raise SceneError("path", str(path), "is a folder; give a file name")
        data = self._encoded(path)
        if why := under_a_file(path.parent):
            raise SceneError("path", str(path), why)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)  # as krsview.save and export do
            write_atomic(path, data)
        except OSError as e:  # a disk full, a place not writable: said of the file asked for
            raise OSError(e.errno, e.strerror, str(path)) from None
        return path

    def _encoded(self, path: Path) -> bytes:
        """The bytes :meth:`save` writes for ``path``'s suffix, or a SceneError."""
        from PIL import Image

        suffix = path.suffix.lower()
        out = io.BytesIO()
        if suffix == ".npz":
            np.savez_compressed(out, **{n: getattr(self, n) for n in self.__dataclass_fields__})
            return out.getvalue()
        kind = Image.registered_extensions().get(suffix)
        allowed = "allowed: .png, .npz or another format Pillow writes in colour (.jpg, .tif, …)"
        if kind not in Image.SAVE:
            raise SceneError(
                "path",
                str(path),
                f"Pillow writes no {suffix or 'file without a suffix'}; {allowed}",
            )
        try:
            self.image().save(out, format=kind)
        except (OSError, ValueError, KeyError) as e:  # e.g. a format of one bit per pixel
            said = str(e).strip() or type(e).__name__
            raise SceneError(
                "path",
                str(path),
                f"Pillow cannot write a colour image as {suffix} ({said}); {allowed}",
            ) from None
        return out.getvalue()

    @classmethod
    def load(cls, path: str | Path) -> Frame:
        """A frame written by :meth:`save` as ``.npz`` (SceneError for any other file)."""
        names = list(cls.__dataclass_fields__)
        try:
            with np.load(path, allow_pickle=False) as data:
                return cls(**{name: data[name] for name in names})
        except OSError as e:
            raise SceneError("path", str(path), f"cannot read: {e.strerror}") from None
        except (ValueError, KeyError, AttributeError, TypeError):
            raise SceneError(
                "path",
                str(path),
                f"not a frame written by Frame.save as .npz (arrays {', '.join(names)})",
            ) from None

    def _repr_png_(self) -> bytes:
        """Jupyter shows a frame as its image."""
        out = io.BytesIO()
        self.image().save(out, format="PNG")
        return out.getvalue()

    def __repr__(self) -> str:
        w, h = self.size
        return (
            f"Frame({w}×{h}, {self.hit.mean():.0%} hit, "
            f"{self.iterations.mean():.1f} iterations/pixel)"
        )
