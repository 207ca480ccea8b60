"""Comparison figures, drawn from detection records, stored traces and sweeps.

- :func:`sweep_figure`: detection rate against false alarms (per flight and per hour
  of fault-free flight) and mean detection time against false alarms per hour, every
  method on one set of axes, the configured operating point marked.
- :func:`detection_time_figure`: per method, detection times by fault class.
- :class:`FlightFigure`: per flight, one small panel per method of its score-to-
  threshold ratio around the onset.

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
from PIL import Image  # noqa: E402
from PIL.PngImagePlugin import PngInfo  # noqa: E402

from alfa_bench.methods import Trace  # noqa: E402

from .sweep import ratio  # noqa: E402
from .tables import FAULT_ORDER  # noqa: E402

__all__ = ["BLOCK_STYLES", "FlightFigure", "colors", "detection_time_figure", "save",
           "sweep_figure"]

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


class FlightFigure:
    """Per flight, one panel per method of ``methods``: :math:`\\max_c s_c/\\gamma_c`
    against the threshold 1, within ``window_s`` of the onset (the whole flight if
    fault-free).

    The figure is laid out and its fixed parts rendered once; per flight only what
    changes is drawn over them (matplotlib's blitting), pixel for pixel what a full
    drawing gives. Call :meth:`close` when done.
    """

    def __init__(self, methods: list[str], window_s: float = 30.0):
        self.methods = list(methods)
        self.window_s = window_s
        height = 1.25 * len(self.methods) + 0.8
        self.fig, axes = plt.subplots(len(self.methods), 1, figsize=(8, height), sharex=True,
                                      squeeze=False, dpi=_DPI)
        # fixed margins (in inches): a constrained layout of this many axes took most
        # of the drawing time
        self.fig.subplots_adjust(left=0.2, right=0.98, bottom=0.45 / height,
                                 top=1 - 0.75 / height, hspace=0.12)
        self.panels = []
        for ax, m in zip(axes[:, 0], self.methods, strict=True):
            ax.set_yscale("log")
            ax.set_ylim(1e-2, 1e4)
            # fixed decades, no minor ticks: the log locators took much of the drawing
            ax.yaxis.set_major_locator(FixedLocator([1e-2, 1e0, 1e2, 1e4]))
            ax.yaxis.set_minor_locator(NullLocator())
            ax.set_ylabel(m, fontsize=7, rotation=0, ha="right", va="center")
            ax.tick_params(labelsize=7)
            self.panels.append({
                "ax": ax,
                "fault": ax.axvspan(0.0, 1.0, color="0.85"),
                "alarm_level": ax.axhline(1.0, color="tab:red", lw=0.9, ls="--"),
                "score": ax.plot([], [], lw=0.9, color="tab:blue")[0],
                "first": ax.axvline(0.0, color="tab:red", lw=1.2),
                "note": ax.text(0.005, 0.95, "", transform=ax.transAxes, fontsize=7,
                                va="top")})
        axes[-1, 0].set_xlabel("flight time (s)")
        self.title = self.fig.suptitle("", fontsize=9)
        # What changes from flight to flight is drawn, in the order a full draw takes,
        # over a background rendered once: the y axes (log ticks, mathtext labels) and
        # the method names were most of each figure's time.
        self._layers = [a for p in self.panels for a in (
            p["fault"], p["alarm_level"], p["score"], p["first"], *p["ax"].spines.values(),
            p["ax"].xaxis, p["note"])] + [self.title]
        for artist in self._layers:
            artist.set_animated(True)
        self.fig.canvas.draw()
        self._background = self.fig.canvas.copy_from_bbox(self.fig.bbox)

    def draw(self, flight: str, onset_s: float | None, end_s: float | None,
             traces: dict[str, Trace], path: str | Path) -> None:
        """Draw ``traces`` (one per method, in order) of ``flight`` and write ``path``."""
        if list(traces) != self.methods:
            raise ValueError(f"{flight}: traces of {list(traces)}, the figure has panels "
                             f"for {self.methods}")
        for panel, tr in zip(self.panels, traces.values(), strict=True):
            r = ratio(tr)
            lo, hi = ((tr.t[0], tr.t[-1]) if onset_s is None
                      else (onset_s - self.window_s, min(onset_s + self.window_s, tr.t[-1])))
            sel = (tr.t >= lo) & (tr.t <= hi) & np.isfinite(r)
            panel["score"].set_data(tr.t[sel], np.clip(r[sel], 1e-2, 1e4))
            fault = panel["fault"]
            fault.set_visible(onset_s is not None)
            if onset_s is not None:
                fault.set_x(onset_s)
                fault.set_width(min(hi, end_s if end_s is not None else hi) - onset_s)
            first = tr.first_alarm_s()
            panel["first"].set_visible(first is not None and lo <= first <= hi)
            panel["first"].set_xdata([first, first])
            panel["note"].set_text("no alarm" if first is None else f"first alarm {first:.1f} s")
        # the panels share x, so the last panel's span holds for all: set once, since
        # each call updates every panel
        self.panels[-1]["ax"].set_xlim(lo, hi)
        self.title.set_text(f"{flight}\nscore / threshold (dashed: alarm level; grey: "
                            "fault; red line: first alarm)")
        canvas = self.fig.canvas
        canvas.restore_region(self._background)
        for artist in self._layers:
            self.fig.draw_artist(artist)
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        # what savefig writes, without drawing the figure again; the fastest deflate:
        # 6 % larger files, a fifth less time a figure
        Image.frombuffer("RGBA", canvas.get_width_height(), canvas.buffer_rgba(), "raw",
                         "RGBA", 0, 1).save(path, format="png", dpi=(_DPI, _DPI),
                                            pnginfo=PngInfo(), compress_level=1)

    def close(self) -> None:
        plt.close(self.fig)
