"""The interactive page in a real browser: Debian's headless chromium, driven over the DevTools
protocol on a pipe (``--remote-debugging-pipe``: no port, no network, no extra package).

The page must load with no console errors (uncaught exceptions, ``console.error``, or errors
that the browser itself logs for the page, such as a failed resource), plotly must have drawn
the 3D scene, and a screenshot must not be blank. A page with a deliberate error must fail the
same check. ``tests/setup_browser.sh`` installs chromium; without it these tests are skipped.
"""

from __future__ import annotations

import base64
import contextlib
import fcntl
import io
import json
import os
import queue
import shutil
import subprocess
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from collisionlab.demos import load_demo
from collisionlab.plotting import save_html
from collisionlab.world import World

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
if CHROMIUM is None and os.environ.get("CI"):
    # In CI the browser test must run, not skip: the test setup (python3 tasks.py test) installs chromium.
    raise RuntimeError("CI: chromium is missing; tests/setup_browser.sh should have installed it")
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="Debian's chromium is not installed: run tests/setup_browser.sh (tasks.py test does)"
)

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-extensions",
    "--disable-dev-shm-usage",
    # WebGL (plotly's 3D scenes) in software, as no GPU is used:
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--window-size=1200,800",
    "--remote-debugging-pipe",
]


@dataclass
class PageResult:
    errors: list[str] = field(default_factory=list)
    screenshot: bytes = b""
    rendered: Any = None


class Browser:
    """A headless chromium spoken to over fds 3 (commands in) and 4 (answers out)."""

    def __init__(self, profile: Path) -> None:
        assert CHROMIUM is not None
        cmd_read, self._cmd_write = os.pipe()
        self._out_read, out_write = os.pipe()
        # Move the child's ends above fd 9, so putting them on 3 and 4 cannot clobber either.
        for low in (cmd_read, out_write):
            high = fcntl.fcntl(low, fcntl.F_DUPFD, 10)
            os.close(low)
            if low == cmd_read:
                cmd_read = high
            else:
                out_write = high

        def wire() -> None:  # in the child, before exec: the pipes become fds 3 and 4
            os.dup2(cmd_read, 3)
            os.dup2(out_write, 4)

        self.process = subprocess.Popen(
            [CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "about:blank"],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            pass_fds=(3, 4),
            preexec_fn=wire,
        )
        os.close(cmd_read)
        os.close(out_write)
        self._next_id = 0
        self._messages: queue.Queue[dict[str, Any] | None] = queue.Queue()
        self._events: list[dict[str, Any]] = []
        threading.Thread(target=self._reader, daemon=True).start()

    def _reader(self) -> None:
        buffer = b""
        with os.fdopen(self._out_read, "rb", buffering=0) as stream:
            while chunk := stream.read(1 << 16):
                buffer += chunk
                while b"\0" in buffer:
                    message, buffer = buffer.split(b"\0", 1)
                    self._messages.put(json.loads(message))
        self._messages.put(None)

    def send(self, method: str, params: dict[str, Any] | None = None, session: str | None = None,
             timeout: float = 30.0) -> dict[str, Any]:  # fmt: skip
        """Send one command and wait for its answer; events that arrive meanwhile are kept."""
        self._next_id += 1
        message: dict[str, Any] = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self._cmd_write, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            answer = self._messages.get(timeout=max(deadline - time.monotonic(), 0.01))
            if answer is None:
                raise RuntimeError("chromium closed the pipe")
            if answer.get("id") == self._next_id:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error']}")
                result: dict[str, Any] = answer.get("result", {})
                return result
            self._events.append(answer)

    def wait_for(self, method: str, timeout: float = 30.0) -> None:
        """Wait for an event (it may have come already)."""
        if any(e.get("method") == method for e in self._events):
            return
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                message = self._messages.get(timeout=0.1)
            except queue.Empty:
                continue
            if message is None:
                raise RuntimeError("chromium closed the pipe")
            self._events.append(message)
            if message.get("method") == method:
                return
        raise TimeoutError(method)

    def drain(self, seconds: float) -> None:
        """Collect events for a while (errors thrown after the load event count too)."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            try:
                message = self._messages.get(timeout=0.05)
            except queue.Empty:
                continue
            if message is None:
                return
            self._events.append(message)

    def errors(self) -> list[str]:
        """Every error the page produced: uncaught exceptions, console.error/assert, and the
        browser's own error log entries (failed loads, security errors...)."""
        found = []
        for event in self._events:
            method, params = event.get("method"), event.get("params", {})
            if method == "Runtime.exceptionThrown":
                details = params["exceptionDetails"]
                text = details.get("exception", {}).get("description") or details.get("text", "")
                found.append(f"uncaught: {text}")
            elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
                args = " ".join(str(a.get("value", a.get("description", ""))) for a in params.get("args", []))
                found.append(f"console.{params['type']}: {args}")
            elif method == "Log.entryAdded" and params["entry"].get("level") == "error":
                found.append(f"log: {params['entry'].get('text')} {params['entry'].get('url', '')}")
        return found

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.send("Browser.close", timeout=5)
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        os.close(self._cmd_write)


@pytest.fixture(scope="module")
def browser(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Browser]:
    b = Browser(tmp_path_factory.mktemp("chromium-profile"))
    yield b
    b.close()


def open_page(browser: Browser, path: Path, ready: str = "true", settle: float = 1.0) -> PageResult:
    """Open ``path`` in a fresh tab; wait for the load event and for ``ready`` (a JS expression)
    to be true; collect errors for ``settle`` more seconds; take a screenshot."""
    browser._events.clear()
    target = browser.send("Target.createTarget", {"url": "about:blank"})["targetId"]
    session = browser.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
    try:
        for domain in ("Runtime", "Log", "Page"):
            browser.send(f"{domain}.enable", session=session)
        metrics = {"width": 1200, "height": 800, "deviceScaleFactor": 1, "mobile": False}
        browser.send("Emulation.setDeviceMetricsOverride", metrics, session=session)
        browser.send("Page.navigate", {"url": path.resolve().as_uri()}, session=session)
        browser.wait_for("Page.loadEventFired")
        rendered: Any = None
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:
            answer = browser.send("Runtime.evaluate", {"expression": ready, "returnByValue": True}, session=session)
            rendered = answer.get("result", {}).get("value")
            if rendered:
                break
            browser.drain(0.2)
        browser.drain(settle)
        shot = browser.send("Page.captureScreenshot", {"format": "png"}, session=session)
        return PageResult(browser.errors(), base64.b64decode(shot["data"]), rendered)
    finally:
        browser.send("Target.closeTarget", {"targetId": target})


def not_blank(png: bytes) -> tuple[float, int]:
    pixels = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.float64)
    return float(pixels.std()), len(np.unique(pixels.reshape(-1, 3), axis=0))


# plotly has drawn its 3D scene: the WebGL canvas exists and the slider and buttons are there.
PLOTLY_READY = (
    "(() => { const d = document.getElementById('collisionlab-plot');"
    " return !!(d && d._fullLayout && d.querySelector('.gl-container canvas')"
    " && d.querySelector('.slider-container') && d.querySelector('.updatemenu-container')"
    " && document.getElementById('collisionlab-run')); })()"
)


@pytest.mark.parametrize("name", ["spheres", "circle-line"])
def test_page_loads_without_errors_and_draws(browser: Browser, tmp_path: Path, name: str) -> None:
    scenario = load_demo(name)
    record = World(scenario).run()
    page = tmp_path / f"{name}.html"
    save_html(record, scenario, str(page))
    result = open_page(browser, page, PLOTLY_READY)
    assert result.errors == []
    assert result.rendered is True, "plotly did not draw the scene, the slider and the buttons"
    (tmp_path / f"{name}.png").write_bytes(result.screenshot)
    std, colours = not_blank(result.screenshot)
    assert std > 10 and colours > 50, f"screenshot looks blank (std {std:.1f}, {colours} colours)"


def test_page_data_is_readable_in_the_browser(browser: Browser, tmp_path: Path) -> None:
    scenario = load_demo("sphere-plane")
    record = World(scenario).run()
    page = tmp_path / "page.html"
    save_html(record, scenario, str(page))
    expression = "JSON.parse(document.getElementById('collisionlab-run').textContent).events[0].step"
    result = open_page(browser, page, expression, settle=0.2)
    assert result.errors == []
    assert result.rendered == record.events[0].step


def test_the_check_catches_a_broken_page(browser: Browser, tmp_path: Path) -> None:
    page = tmp_path / "broken.html"
    page.write_text(
        "<!doctype html><html><body><h1>broken on purpose</h1>"
        "<script>console.error('deliberate console error');</script>"
        "<script>notAFunction();</script>"
        "<script>setTimeout(() => { throw new Error('late failure'); }, 100);</script>"
        "</body></html>",
        encoding="utf-8",
    )
    result = open_page(browser, page, settle=0.6)
    text = "\n".join(result.errors)
    assert "deliberate console error" in text
    assert "notAFunction" in text
    assert "late failure" in text


def test_a_blank_page_is_seen_as_blank(browser: Browser, tmp_path: Path) -> None:
    page = tmp_path / "blank.html"
    page.write_text("<!doctype html><html><body></body></html>", encoding="utf-8")
    result = open_page(browser, page, settle=0.1)
    assert result.errors == []
    std, colours = not_blank(result.screenshot)
    assert std < 1 and colours <= 2


# Jump to the last frame as the slider or Play would, then read the slider's readout and where
# the ball's mesh is.
ANIMATE_TO_END = """(() => {
  const d = document.getElementById('collisionlab-plot');
  if (!d || !d._fullLayout || !d._transitionData) return null;
  if (!window.__anim) {
    window.__anim = 'started';
    const last = String(d._transitionData._frames.length - 1);
    Plotly.animate(d, [last], {frame: {duration: 0, redraw: true}, transition: {duration: 0}, mode: 'immediate'})
      .then(() => { window.__anim = 'done'; });
    return null;
  }
  if (window.__anim !== 'done') return null;
  const ball = d._fullData.find(t => t.type === 'mesh3d' && t.name === 'ball');
  const xs = Array.from(ball.x);
  const readout = Array.from(d.querySelectorAll('.slider-container text')).map(t => t.textContent);
  return {slider: readout.find(t => t.startsWith('t = ')) || readout.join('|'),
          x: (Math.min(...xs) + Math.max(...xs)) / 2};
})()"""


def test_the_animation_runs_in_the_browser(browser: Browser, tmp_path: Path) -> None:
    scenario = load_demo("sphere-plane")
    record = World(scenario).run()
    page = tmp_path / "page.html"
    save_html(record, scenario, str(page))
    result = open_page(browser, page, ANIMATE_TO_END, settle=0.3)
    assert result.errors == []
    assert result.rendered is not None, "the animation did not reach its last frame"
    end = record.frames[-1]
    assert result.rendered["slider"] == f"t = {end.time:.3f} s"
    assert abs(result.rendered["x"] - end.bodies[0].position.x) < 0.01  # the mesh is a polygon about it
