"""One headless chromium for many screenshots, driven over its DevTools pipe (fds 3 and 4,
NUL-separated JSON): a browser start costs about as much as a page, so tests/test_web.py
starts one per module and opens each page in a fresh tab, its clock on virtual time as
`chromium --screenshot --virtual-time-budget` runs it."""

from __future__ import annotations

import base64
import io
import json
import os
import select
import shutil
import subprocess
from pathlib import Path

import numpy as np
from PIL import Image

BROWSER = [
    "chromium",
    "--headless=new",
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--hide-scrollbars",
]
TIMEOUT_S = 120  # for any one answer of the browser


class Browser:
    """A chromium whose tabs are ``size`` pixels; ``shot`` opens a page and screenshots it."""

    def __init__(self, size: tuple[int, int]):
        assert shutil.which("chromium"), "chromium is missing: `make deps` installs it"
        commands, self._to = os.pipe()
        self._from, answers = os.pipe()

        def on_fds_3_and_4() -> None:  # in the child, before exec: where the pipe mode reads
            a, b = os.dup(commands), os.dup(answers)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(
            [*BROWSER, "--remote-debugging-pipe", f"--window-size={size[0]},{size[1]}"],
            pass_fds=(3, 4),
            preexec_fn=on_fds_3_and_4,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(commands)
        os.close(answers)
        self.size, self._buffer, self._last, self._events = size, b"", 0, []

    def _read(self) -> dict:
        while b"\0" not in self._buffer:
            ready, _, _ = select.select([self._from], [], [], TIMEOUT_S)
            assert ready, f"chromium gave no answer in {TIMEOUT_S} s"
            chunk = os.read(self._from, 1 << 20)
            assert chunk, f"chromium closed its pipe (exit status {self.proc.wait(10)})"
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        """Send one DevTools command and return its result (events met meanwhile are kept)."""
        self._last += 1
        message = {"id": self._last, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self._to, json.dumps(message).encode() + b"\0")
        while (answer := self._read()).get("id") != self._last:
            self._events.append(answer)
        assert "error" not in answer, (method, answer["error"])
        return answer["result"]

    def _wait(self, event: str, session: str) -> None:
        while not any(
            m.get("method") == event and m.get("sessionId") == session for m in self._events
        ):
            self._events.append(self._read())
        self._events = [m for m in self._events if m.get("sessionId") != session]

    def shot(self, page: Path, fragment: str = "bare", budget_ms: int = 8000) -> np.ndarray:
        """The page in a fresh tab (rows top → bottom), taken once the page's clock has run
        ``budget_ms`` of virtual time."""
        tab = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        s = self.call("Target.attachToTarget", {"targetId": tab, "flatten": True})["sessionId"]
        w, h = self.size
        metrics = {"width": w, "height": h, "deviceScaleFactor": 1, "mobile": False}
        self.call("Emulation.setDeviceMetricsOverride", metrics, s)
        self.call("Emulation.setVirtualTimePolicy", {"policy": "pause"}, s)  # until it loads
        self.call("Page.navigate", {"url": f"{page.resolve().as_uri()}#{fragment}"}, s)
        budget = {"policy": "pauseIfNetworkFetchesPending", "budget": budget_ms}
        self.call("Emulation.setVirtualTimePolicy", budget, s)
        self._wait("Emulation.virtualTimeBudgetExpired", s)
        png = self.call("Page.captureScreenshot", {"format": "png"}, s)["data"]
        self.call("Target.closeTarget", {"targetId": tab})
        image = Image.open(io.BytesIO(base64.b64decode(png))).convert("RGB")
        return np.asarray(image).astype(int)

    def close(self) -> None:
        os.close(self._to)  # the pipe's end is the browser's end
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.terminate()
            self.proc.wait(10)
        os.close(self._from)
