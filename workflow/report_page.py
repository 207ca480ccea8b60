"""The Snakemake report and the results page in a real browser: load, screenshot, check.

``snakemake --report results/report.html`` writes one self-contained page whose
script draws everything: :func:`open_report` loads it in headless Chromium (driven by
Playwright), reads the overview it opens on, then opens one result of one category,
as a reader clicks it, and reports the width of every image that loaded there. A page
whose script failed shows neither.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from .viewer import CHROMIUM_ARGS, chromium

__all__ = ["IndexView", "ReportView", "open_index", "open_report"]


@dataclass(frozen=True)
class ReportView:
    """``overview``: the text of the page it opens on; once the item is open,
    ``images``: the natural width of each raster image loaded (0 for one that failed),
    and ``frames``: the text of each embedded page (an HTML item); ``errors``: the
    page's script errors."""

    overview: str
    images: list[int]
    frames: list[str]
    errors: list[str]


@contextmanager
def _opened(html: str | Path, size: tuple[int, int]):
    """``html`` loaded in headless Chromium in a ``size`` window: yields the page and
    the list its script errors go to; the browser is closed after."""
    from playwright.sync_api import sync_playwright

    exe = chromium()
    if exe is None:
        raise RuntimeError("no Chromium: install Debian's chromium, or set CHROMIUM")
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, headless=True, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": size[0], "height": size[1]})
            errors: list[str] = []
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(Path(html).resolve().as_uri())
            yield page, errors
        finally:
            browser.close()


def open_report(html: str | Path, out: str | Path, category: str, item: str, *,
                size: tuple[int, int] = (1400, 900), wait_ms: int = 1500) -> ReportView:
    """Open the report ``html``, then ``item`` (its path, as the report lists it) of
    ``category``; save a screenshot of the item shown to ``out`` and return what the
    page showed."""
    with _opened(html, size) as (page, errors):
        page.wait_for_timeout(wait_ms)
        overview = page.inner_text("body")
        page.get_by_role("link", name=category).click()
        page.wait_for_timeout(wait_ms // 3)
        page.locator(f'tr:has(td:text-is("{item}")) a[iconname=eye]').click()
        page.wait_for_timeout(wait_ms)
        page.screenshot(path=str(out))
        images = page.evaluate("Array.from(document.images).filter(i => "
                               "!i.src.startsWith('data:image/svg')).map(i => "
                               "i.naturalWidth)")
        frames = [f.inner_text("body") for f in page.frames[1:]]
    return ReportView(overview, images, frames, errors)


@dataclass(frozen=True)
class IndexView:
    """What ``results/index.html`` shows on arrival: ``first_rows``, the text of each
    table's first data row whose box lies wholly inside the window (none that does
    not), ``images``, the natural width of each image (0 for one that failed),
    ``images_in_view``, how many lie wholly inside the window,
    ``page_width``, the page's scroll width, and ``errors``, its script errors."""

    first_rows: list[str]
    images: list[int]
    images_in_view: int
    page_width: int
    errors: list[str]


def open_index(html: str | Path, out: str | Path, *, size: tuple[int, int] = (1400, 900)
               ) -> IndexView:
    """Open the results page ``html`` in a ``size`` window, without a click or a
    scroll, save a screenshot of the window to ``out`` and return what it shows."""
    inside = (f"getBoundingClientRect().bottom <= {size[1]} && "
              f"{{}}.getBoundingClientRect().right <= {size[0]}")
    with _opened(html, size) as (page, errors):
        page.wait_for_load_state("load")
        page.screenshot(path=str(out))
        rows = page.evaluate("Array.from(document.querySelectorAll('table')).map(t => "
                             "t.rows[1]).filter(r => r && r." + inside.format("r")
                             + ").map(r => r.innerText)")
        images = page.evaluate("Array.from(document.images).map(i => i.naturalWidth)")
        in_view = page.evaluate("Array.from(document.images).filter(i => i."
                                + inside.format("i") + ").length")
        width = page.evaluate("document.documentElement.scrollWidth")
    return IndexView(rows, images, in_view, width, errors)
