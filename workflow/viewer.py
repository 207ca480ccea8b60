"""A recording in rerun's web viewer, in a real browser: serve, load, screenshot, check.

``serve_recording`` starts ``rerun --serve-web`` on loopback ports for the ``.rrd``
files of one recording (a flight's parts, which the viewer opens as one);
``screenshot`` loads the viewer in headless Chromium (driven by Playwright) and
waits until the page shows the recording rather than rerun's welcome screen.

The check reads pixels, because the viewer draws everything on one WebGL canvas
and its console does not say when a recording has arrived:

- the recording's plots draw coloured lines in the signal and overview rows, where
  the welcome screen is grey text on white;
- the time panel shows the fault's span selected (rerun's selection blue), which
  is where the blueprint opens (:func:`alfa_bench.outputs.rerun_log.blueprint`).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.parse
import urllib.request
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["CHROMIUM_ARGS", "ViewerCheck", "check_screenshot", "chromium", "screenshot",
           "serve_recording"]

#: rerun's fill of a selected time span in the time panel (RGB), seen in 0.41
SELECTION_RGB = (209, 225, 248)
# Chromium in a sandbox without a GPU or a network: software WebGL, and no calls home
CHROMIUM_ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                  "--disable-background-networking", "--disable-component-update",
                  "--disable-sync", "--no-first-run"]


def chromium() -> str | None:
    """The Chromium executable (``CHROMIUM`` or ``chromium`` on the PATH), or None."""
    return os.environ.get("CHROMIUM") or shutil.which("chromium")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def serve_recording(*rrds: str | Path, timeout_s: float = 30.0):
    """Serve the files ``rrds`` to rerun's web viewer on loopback; yield the viewer's
    URL."""
    grpc, web = _free_port(), _free_port()
    rerun = Path(sys.executable).with_name("rerun")
    cmd = [str(rerun), "--serve-web", "--bind", "127.0.0.1", "--port", str(grpc),
           "--web-viewer-port", str(web), *map(str, rrds)]
    env = {**os.environ, "RERUN_ANALYTICS": "0"}
    # a file, not a pipe: a server that logs more than a pipe holds would block on it
    log = tempfile.TemporaryFile()
    # a session of its own: `rerun` is a launcher whose child, the viewer server,
    # outlives it unless the whole group is stopped
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=log,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + timeout_s
        while not _answers(f"http://127.0.0.1:{web}/"):
            if proc.poll() is not None or time.monotonic() > deadline:
                log.seek(0)
                raise RuntimeError(f"rerun --serve-web did not start for {rrds}: "
                                   f"{log.read().decode(errors='replace')}")
            time.sleep(0.2)
        source = urllib.parse.quote(f"rerun+http://127.0.0.1:{grpc}/proxy", safe="")
        yield f"http://127.0.0.1:{web}/?url={source}"
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(timeout=10)
        log.close()


def _answers(url: str) -> bool:
    try:
        urllib.request.urlopen(url, timeout=1).close()
        return True
    except OSError:
        return False


@dataclass(frozen=True)
class ViewerCheck:
    """What a screenshot shows. ``plots``: share of strongly coloured pixels in the
    signal and overview rows; ``selection``: the selected span in the time panel as
    fractions of the screenshot's width, or None."""

    plots: float
    selection: tuple[float, float] | None

    @property
    def shows_recording(self) -> bool:
        # the welcome screen measured 0.3 % coloured pixels, a recording 3 %
        return self.plots > 0.01 and self.selection is not None


def check_screenshot(rgb: np.ndarray) -> ViewerCheck:
    """Read a screenshot (H×W×3 uint8) of the viewer with our blueprint."""
    rgb = rgb.astype(int)
    h, w, _ = rgb.shape
    top = rgb[int(0.05 * h):int(0.5 * h), int(0.15 * w):]   # past the welcome screen's menu
    coloured = (top.max(axis=2) - top.min(axis=2)) > 90
    panel = rgb[int(0.75 * h):]
    hit = (np.abs(panel - np.array(SELECTION_RGB)) <= 8).all(axis=2)
    cols = np.flatnonzero(hit.sum(axis=0) >= 0.2 * panel.shape[0])
    selection = None if cols.size == 0 else (cols[0] / w, (cols[-1] + 1) / w)
    return ViewerCheck(float(coloured.mean()), selection)


def screenshot(url: str, out: str | Path, *, size: tuple[int, int] = (1600, 1000),
               timeout_s: float = 90.0) -> ViewerCheck:
    """Load ``url`` in headless Chromium, wait until it shows the recording (or
    ``timeout_s`` passes), save a PNG to ``out`` and return what it shows."""
    from PIL import Image
    from playwright.sync_api import sync_playwright

    exe = chromium()
    if exe is None:
        raise RuntimeError("no Chromium: install Debian's chromium, or set CHROMIUM")
    out = Path(out)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, headless=True, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": size[0], "height": size[1]})
            page.goto(url)
            deadline = time.monotonic() + timeout_s
            while True:
                page.wait_for_timeout(1000)
                page.screenshot(path=str(out))
                check = check_screenshot(np.asarray(Image.open(out).convert("RGB")))
                if check.shows_recording or time.monotonic() > deadline:
                    break
            # the plots keep filling in for a moment after the first lines appear
            page.wait_for_timeout(3000)
            page.screenshot(path=str(out))
        finally:
            browser.close()
    return check_screenshot(np.asarray(Image.open(out).convert("RGB")))
