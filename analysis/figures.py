"""Comparison figures, drawn from detection records, stored traces and sweeps.

- :func:`sweep_figure`: detection rate against false alarms (per flight and per hour
  of fault-free flight) and mean detection time against false alarms per hour, every
  method on one set of axes, the configured operating point marked.
- :func:`detection_time_figure`: per method, detection times by fault class.
- :class:`FlightPanel` and :class:`FlightFrame`: per flight, one small panel per
  method of its score-to-threshold ratio around the onset; each method's detect job
  draws its panels, and the flight figures stack them.

PNG output is deterministic for a given matplotlib version (no dates are written).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.ticker import FixedLocator, NullLocator  # noqa: E402

from alfa_bench.methods import Trace  # noqa: E402

from .png import stack, write_png  # noqa: E402
from .sweep import ratio  # noqa: E402
from .tables import FAULT_ORDER  # noqa: E402

__all__ = ["BLOCK_STYLES", "FLIGHT_WINDOW_S", "FlightFrame", "FlightPanel", "colors",
           "detection_time_figure", "flight_figure", "flight_span", "save", "sweep_figure"]

_DPI = 110
_METADATA = {"Software": None}


#: line styles of the blocks of runs (:func:`~.tables.block`): honest methods solid,
#: those reading the emulation dashed, reference rows dotted
BLOCK_STYLES = {"honest": {"ls": "-", "lw": 1.4}, "reads actuators": {"ls": "--", "lw": 1.1},
                "reference": {"ls": ":", "lw": 1.1}}


def colors(methods) -> dict[str, tuple]:
    """A colour per method, in order (tab10, then every fourth of tab20b beyond ten)."""
    cmap, more = plt.get_cmap("tab10"), plt.get_cmap("tab20b")
    return {m: cmap(i) if i < 10 else more(4 * (i - 10) % 20) for i, m in enumerate(methods)}


def save(fig, path: str | Path) -> None:
    """Write ``fig`` as a deterministic PNG and close it."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=_DPI, metadata=_METADATA)
    plt.close(fig)


def sweep_figure(sweep: pd.DataFrame, subset: str, path: str | Path) -> None:
    """Three panels over the threshold scale, for ``subset`` of ``sweep``
    (:func:`~.sweep.sweep_table`). Each curve is traced in the order of the scale; it
    need not be monotone, since a lower threshold can turn a detection into an alarm
    before onset."""
    data = sweep[sweep["subset"] == subset]
    methods = list(dict.fromkeys(data["method"]))
    palette = colors(methods)
    deadline = float(data["deadline_s"].iloc[0]) if len(data) else float("nan")
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.0), layout="constrained")
    panels = [
        ("false_alarm_flights", "recall", "flights with a false alarm (share)",
         f"detected within {deadline:g} s (recall)", "linear"),
        ("false_alarms_per_hour", "recall", "false alarms per hour of fault-free flight",
         f"detected within {deadline:g} s (recall)", "symlog"),
        ("false_alarms_per_hour", "mean_detection_s",
         "false alarms per hour of fault-free flight", "mean detection time (s)", "symlog"),
    ]
    for ax, (x, y, xlabel, ylabel, xscale) in zip(axes, panels, strict=True):
        for m in methods:
            d = data[data["method"] == m].sort_values("scale")
            ax.plot(d[x], d[y], color=palette[m], label=f"{m} ({d['block'].iloc[0]})",
                    alpha=0.9, **BLOCK_STYLES[d["block"].iloc[0]])
            at = d[d["scale"] == 1.0]
            ax.plot(at[x], at[y], "o", color=palette[m], ms=6, mec="black", mew=0.6)
        ax.set_xscale(xscale, **({"linthresh": 1.0} if xscale == "symlog" else {}))
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
    axes[0].set_xlim(-0.02, 1.02)
    axes[0].set_ylim(-0.02, 1.02)
    axes[1].set_ylim(-0.02, 1.02)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(4, len(methods)),
               fontsize=8)
    n = int(data["flights"].iloc[0]) if len(data) else 0
    fig.suptitle(f"Threshold sweep, subset '{subset}' ({n} flights): every channel "
                 "threshold scaled by one factor; dots = configured thresholds")
    save(fig, path)


def detection_time_figure(records: list[dict], flights: list[str], deadline_s: float,
                          path: str | Path) -> None:
    """Per method, the detection time of each fault detected within ``deadline_s``, by
    fault class, over ``flights``, on an axis from 0 to the deadline; the first alarms
    after it, detections by the paper's rule only, are drawn apart above it. Each class
    is labelled with detected in time / flights, and + the late ones."""
    methods = list(dict.fromkeys(r["method"] for r in records))
    keep = set(flights)
    classes = [c for c in FAULT_ORDER if c != "none" and any(
        r["fault_class"] == c and r["flight"] in keep for r in records)]
    cols = min(4, len(methods))
    rows = -(-len(methods) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.0 * rows), squeeze=False,
                             sharey=True, layout="constrained")
    late_at = 1.12 * deadline_s
    for ax, m in zip(axes.flat, methods, strict=False):
        recs = [r for r in records if r["method"] == m and r["flight"] in keep]
        labels = []
        for i, c in enumerate(classes):
            rc = [r for r in recs if r["fault_class"] == c]
            delays = np.array([r["detection_s"] for r in rc if r["outcome"] == "TP"])
            times, late = delays[delays <= deadline_s], delays[delays > deadline_s]
            jitter = (np.arange(times.size) % 5 - 2) * 0.06
            ax.plot(i + jitter, times, "o", ms=4, alpha=0.8)
            ax.plot(i + (np.arange(late.size) % 5 - 2) * 0.06, np.full(late.size, late_at),
                    "x", ms=4, color="0.5")
            if times.size:
                ax.hlines(np.median(times), i - 0.3, i + 0.3, color="black", lw=1.2)
            extra = f" +{late.size}" if late.size else ""
            name = c.replace("+", "+\n")      # rudder+aileron on two lines, apart
            labels.append(f"{name}\n{times.size}/{len(rc)}{extra}")
        ax.axhline(deadline_s, color="0.3", lw=0.8, ls="--")
        ax.set_xticks(range(len(classes)), labels, fontsize=7)
        ax.set_title(m, fontsize=9)
        ax.grid(alpha=0.3, axis="y")
    for ax in axes.flat[len(methods):]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylim(0, 1.2 * deadline_s)
        ticks = list(np.arange(0, deadline_s + 1e-9, 1.0))
        ax.set_yticks([*ticks, late_at], [f"{t:g}" for t in ticks] + ["late"])
        ax.set_ylabel("detection time (s)")
    fig.suptitle(f"Detection time by fault class, scored with the {deadline_s:g} s deadline "
                 "(bar = median; label = detected in time / flights, + late: x, detected "
                 "by the paper's rule only)", fontsize=9)
    save(fig, path)


#: The flight figures, in pixels at :data:`_DPI`: a header holding the title, then one
#: strip per method holding its panel, then a footer holding the time axis. Every panel
#: sits alike in its strip, so a method's strips are drawn apart (:class:`FlightPanel`,
#: by its detect job) and a flight's figure is their stack (:class:`FlightFrame`).
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


def _figure(height_px: int):
    from matplotlib.figure import Figure

    return Figure(figsize=(_WIDTH_PX / _DPI, height_px / _DPI), dpi=_DPI)


def _band(fig, top_px: float, height_px: float) -> list[float]:
    """The rect (figure fractions) of the axes ``height_px`` tall whose top is ``top_px``
    below the figure's top, between the panels' left and right edges."""
    total = fig.get_figheight() * _DPI
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
    total = fig.get_figheight() * _DPI
    return fig.text(0.5, (total - top_px - 6) / total, "", ha="center", va="top", fontsize=9)


def _rgba(fig) -> np.ndarray:
    """What ``fig``'s canvas holds, as an (h, w, 4) image."""
    return np.asarray(fig.canvas.buffer_rgba())


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
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        self.method = method
        self.fig = _figure(_STRIP_PX)
        FigureCanvasAgg(self.fig)
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
        write_png(_rgba(self.fig), path, _DPI)


_EMPTY = Trace(t=np.zeros(1), score=np.full((1, 1), np.nan), alarm=np.zeros((1, 1), bool),
               channels=("c",), threshold=np.ones(1))


class FlightFrame:
    """The flight figures: a title, the methods' strips (:class:`FlightPanel`) in
    order, and the time axis, stacked."""

    def __init__(self):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        self.header, self.footer = _figure(_HEADER_PX), _figure(_FOOTER_PX)
        for fig in (self.header, self.footer):
            FigureCanvasAgg(fig)
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
        stack([_rgba(self.header), *strips, _rgba(self.footer)], path, _DPI)


def flight_figure(flight: str, onset_s: float | None, end_s: float | None,
                  span: tuple[float, float], traces: dict[str, Trace]):
    """The figure :class:`FlightFrame` stacks for ``flight``, drawn whole, as one
    matplotlib figure: what the stack must equal, pixel for pixel."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = _figure(_HEADER_PX + _STRIP_PX * len(traces) + _FOOTER_PX)
    FigureCanvasAgg(fig)
    _title(fig, 0).set_text(_TITLE.format(flight=flight))
    for k, (method, trace) in enumerate(traces.items()):
        _show(_panel(fig, _HEADER_PX + k * _STRIP_PX, method), trace, onset_s, end_s, span)
    _time_axis(fig, _HEADER_PX + _STRIP_PX * len(traces)).set_xlim(*span)
    return fig
