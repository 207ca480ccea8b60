"""The per-flight figures: one small panel per method of its score-to-threshold ratio
around the onset, each method's drawn by its detect job and stacked per flight.

A figure is, in pixels at :data:`~.figures.DPI`, a header holding the title, then one
strip per method holding its panel, then a footer holding the time axis. Every panel
sits alike in its strip, whatever the other methods, so a method's strips are drawn
apart (:class:`FlightPanel`) and a flight's figure is their stack
(:class:`FlightFrame`), which copies the strips' compressed rows (:mod:`.png`).
:func:`flight_figure` draws the same figure whole, as one matplotlib figure: the stack
must equal it pixel for pixel (tested).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import FixedLocator, NullLocator

from alfa_bench.analysis.sweep import ratio
from alfa_bench.methods import Trace

from .figures import DPI
from .png import stack, write_png

__all__ = ["FLIGHT_WINDOW_S", "FlightFrame", "FlightPanel", "flight_figure", "flight_span"]

#: the figure's width, and the heights of its header, of a method's strip and of its
#: footer, px
_WIDTH_PX, _HEADER_PX, _STRIP_PX, _FOOTER_PX = 880, 48, 136, 48
#: a panel's axes: its left and right edges (fractions of the width), and the strip's
#: rows above and below it
_AXES_X = (0.2, 0.98)
_GAP_PX = 8
#: the time a flight's figure shows either side of the onset, s
FLIGHT_WINDOW_S = 30.0
_TITLE = "{flight}\nscore / threshold (dashed: alarm level; grey: fault; red line: first alarm)"


def flight_span(onset_s: float | None, flight_s: float,
                window_s: float = FLIGHT_WINDOW_S) -> tuple[float, float]:
    """The time a flight's figure shows: ``window_s`` either side of the onset (up to
    the flight's end, ``flight_s``), or the whole of a fault-free flight."""
    if onset_s is None:
        return 0.0, flight_s
    return onset_s - window_s, min(onset_s + window_s, flight_s)


def _figure(height_px: int) -> Figure:
    fig = Figure(figsize=(_WIDTH_PX / DPI, height_px / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _band(fig, top_px: float, height_px: float) -> list[float]:
    """The rect (figure fractions) of the axes ``height_px`` tall whose top is ``top_px``
    below the figure's top, between the panels' left and right edges."""
    total = fig.get_figheight() * DPI
    return [_AXES_X[0], (total - top_px - height_px) / total, _AXES_X[1] - _AXES_X[0],
            height_px / total]


def _panel(fig, top_px: int, method: str) -> dict:
    """The artists of ``method``'s panel, in the strip ``top_px`` below the top of
    ``fig``: a log axis of score / threshold, the alarm level, and what each flight
    moves (the fault's span, the score, the first alarm, a note)."""
    ax = fig.add_axes(_band(fig, top_px + _GAP_PX, _STRIP_PX - 2 * _GAP_PX))
    ax.set_yscale("log")
    ax.set_ylim(1e-2, 1e4)
    # fixed decades, no minor ticks: the log locators took much of the drawing
    ax.yaxis.set_major_locator(FixedLocator([1e-2, 1e0, 1e2, 1e4]))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.set_ylabel(method, fontsize=7, rotation=0, ha="right", va="center")
    ax.tick_params(labelsize=7, labelbottom=False)
    return {"ax": ax,
            "fault": ax.axvspan(0.0, 1.0, color="0.85"),
            "alarm_level": ax.axhline(1.0, color="tab:red", lw=0.9, ls="--"),
            "score": ax.plot([], [], lw=0.9, color="tab:blue")[0],
            "first": ax.axvline(0.0, color="tab:red", lw=1.2),
            "note": ax.text(0.005, 0.95, "", transform=ax.transAxes, fontsize=7, va="top")}


def _show(panel: dict, trace: Trace, onset_s: float | None, end_s: float | None,
          span: tuple[float, float]) -> list:
    """Put ``trace`` (:math:`\\max_c s_c/\\gamma_c`, clipped to the axis) into the
    ``panel`` over ``span``; the artists that changed, in drawing order."""
    lo, hi = span
    r = ratio(trace)
    sel = (trace.t >= lo) & (trace.t <= hi) & np.isfinite(r)
    panel["score"].set_data(trace.t[sel], np.clip(r[sel], 1e-2, 1e4))
    fault = panel["fault"]
    fault.set_visible(onset_s is not None)
    if onset_s is not None:
        fault.set_x(onset_s)
        fault.set_width(min(hi, end_s if end_s is not None else hi) - onset_s)
    first = trace.first_alarm_s()
    panel["first"].set_visible(first is not None and lo <= first <= hi)
    panel["first"].set_xdata([first, first])
    panel["note"].set_text("no alarm" if first is None else f"first alarm {first:.1f} s")
    ax = panel["ax"]
    ax.set_xlim(lo, hi)
    return [panel["fault"], panel["alarm_level"], panel["score"], panel["first"],
            *ax.spines.values(), ax.xaxis, panel["note"]]


def _time_axis(fig, top_px: int):
    """The footer's time axis, ``top_px`` below the top of ``fig``: an invisible axes
    over the last panel's, whose tick labels and label show below it."""
    ax = fig.add_axes(_band(fig, top_px - _STRIP_PX + _GAP_PX, _STRIP_PX - 2 * _GAP_PX))
    ax.patch.set_visible(False)
    ax.yaxis.set_visible(False)
    for spine in ax.spines.values():
        spine.set_visible(False)
    # the ticks are the last panel's: these only place the labels under them
    ax.tick_params(axis="x", labelsize=7, color=(0.0, 0.0, 0.0, 0.0))
    ax.set_xlabel("flight time (s)")
    return ax


def _title(fig, top_px: int):
    """The title's text, its top 6 px under the header's top, ``top_px`` below the top
    of ``fig``."""
    total = fig.get_figheight() * DPI
    return fig.text(0.5, (total - top_px - 6) / total, "", ha="center", va="top", fontsize=9)


def _rgba(fig) -> np.ndarray:
    """What ``fig``'s canvas holds, as an (h, w, 4) image."""
    return np.asarray(fig.canvas.buffer_rgba())


#: a trace to lay a panel out with
_EMPTY = Trace(t=np.zeros(1), score=np.full((1, 1), np.nan), alarm=np.zeros((1, 1), bool),
               channels=("c",), threshold=np.ones(1))


class FlightPanel:
    """``method``'s panel of every flight figure, on a strip of its own: its score /
    threshold, :math:`\\max_c s_c/\\gamma_c` against the threshold 1, over the
    flight's :func:`flight_span`. The method's detect job draws it for each flight it
    scores; :class:`FlightFrame` stacks the strips.

    The strip is laid out and its fixed parts rendered once; per flight only what
    changes is drawn over them (matplotlib's blitting), pixel for pixel what a full
    drawing gives.
    """

    def __init__(self, method: str):
        self.fig = _figure(_STRIP_PX)
        self.panel = _panel(self.fig, 0, method)
        self._layers = _show(self.panel, _EMPTY, None, None, (0.0, 1.0))
        for artist in self._layers:
            artist.set_animated(True)
        self.fig.canvas.draw()
        self._background = self.fig.canvas.copy_from_bbox(self.fig.bbox)

    def draw(self, trace: Trace, onset_s: float | None, end_s: float | None,
             span: tuple[float, float], path: str | Path) -> None:
        """Draw ``trace`` of a flight (its fault from ``onset_s`` to ``end_s``) over
        ``span`` and write the strip to ``path``."""
        _show(self.panel, trace, onset_s, end_s, span)
        self.fig.canvas.restore_region(self._background)
        for artist in self._layers:
            self.fig.draw_artist(artist)
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_png(_rgba(self.fig), path, DPI)


class FlightFrame:
    """The flight figures: a title, the methods' strips (:class:`FlightPanel`) in
    order, and the time axis, stacked."""

    def __init__(self):
        self.header, self.footer = _figure(_HEADER_PX), _figure(_FOOTER_PX)
        self.title = _title(self.header, 0)
        self.axis = _time_axis(self.footer, 0)

    def draw(self, flight: str, span: tuple[float, float], strips: list[str | Path],
             path: str | Path) -> None:
        """Write the figure of ``flight`` over ``span`` with the strips at the paths
        ``strips``, top to bottom, to ``path``."""
        self.title.set_text(_TITLE.format(flight=flight))
        self.axis.set_xlim(*span)
        for fig in (self.header, self.footer):
            fig.canvas.draw()
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        # the strips' rows are copied as they are compressed (.png): no decoding
        stack([_rgba(self.header), *strips, _rgba(self.footer)], path, DPI)


def flight_figure(flight: str, onset_s: float | None, end_s: float | None,
                  span: tuple[float, float], traces: dict[str, Trace]):
    """The figure :class:`FlightFrame` stacks for ``flight``, drawn whole, as one
    matplotlib figure: what the stack must equal, pixel for pixel."""
    fig = _figure(_HEADER_PX + _STRIP_PX * len(traces) + _FOOTER_PX)
    _title(fig, 0).set_text(_TITLE.format(flight=flight))
    for k, (method, trace) in enumerate(traces.items()):
        _show(_panel(fig, _HEADER_PX + k * _STRIP_PX, method), trace, onset_s, end_s, span)
    _time_axis(fig, _HEADER_PX + _STRIP_PX * len(traces)).set_xlim(*span)
    return fig
