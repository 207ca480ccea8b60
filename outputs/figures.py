"""Comparison figures, drawn from detection records, stored traces and sweeps.

- :func:`sweep_figure`: detection rate against false alarms (per flight and per hour
  of fault-free flight) and mean detection time against false alarms per hour, every
  method on one set of axes, the configured operating point marked.
- :func:`detection_time_figure`: per method, detection times by fault class.
- :func:`deadline_figure`: detection rate against the detection deadline
  (:mod:`alfa_bench.analysis.deadline`).
- :func:`detectability_figure`: detection rate of the injected sensor faults against
  their size (:mod:`alfa_bench.analysis.detectability`).
- the per-flight figures, one small panel per method of its score-to-threshold ratio
  around the onset, are in :mod:`.flight_figures`.

PNG output is deterministic for a given matplotlib version (no dates are written).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from alfa_bench.analysis.blocks import FAULT_ORDER  # noqa: E402
from alfa_bench.analysis.detectability import EMPTY, by_fault, fault_name  # noqa: E402
from alfa_bench.render import fmt  # noqa: E402

__all__ = ["BLOCK_STYLES", "DPI", "SWEEP_LEGEND", "SWEEP_SIZE", "colors", "deadline_figure",
           "detectability_figure", "detection_time_figure", "save", "sweep_figure",
           "sweep_legend"]

#: the resolution of every figure, dots per inch
DPI = 110
_METADATA = {"Software": None}


#: line styles of the blocks of runs (:func:`~.tables.block`): honest methods solid,
#: those reading the emulation dashed, reference rows dotted
BLOCK_STYLES = {"honest": {"ls": "-", "lw": 1.4}, "reads actuators": {"ls": "--", "lw": 1.1},
                "reference": {"ls": ":", "lw": 1.1}}


def colors(methods) -> dict[str, tuple]:
    """A colour per method, in order (tab10, then every fourth of tab20b beyond ten)."""
    cmap, more = plt.get_cmap("tab10"), plt.get_cmap("tab20b")
    return {m: cmap(i) if i < 10 else more(4 * (i - 10) % 20) for i, m in enumerate(methods)}


def _grid_in_inches(fig, rows: int, cols: int, *, left: float, right: float, top: float,
                    bottom: float, between_rows: float, between_cols: float) -> None:
    """Place a grid of axes with its margins and gaps in inches: what a constrained
    layout would find, without its solver, whose cost grows with the axes (about 4 s
    for one panel per run)."""
    width, height = fig.get_size_inches()
    axes_h = (height - top - bottom - between_rows * (rows - 1)) / rows
    axes_w = (width - left - right - between_cols * (cols - 1)) / cols
    fig.subplots_adjust(left=left / width, right=1 - right / width, top=1 - top / height,
                        bottom=bottom / height, hspace=between_rows / axes_h,
                        wspace=between_cols / axes_w)


def save(fig, path: str | Path) -> None:
    """Write ``fig`` as a deterministic PNG and close it."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI, metadata=_METADATA)
    plt.close(fig)


def sweep_figure(sweep: pd.DataFrame, subset: str, path: str | Path) -> None:
    """Three panels over the threshold scale, for ``subset`` of ``sweep``
    (:func:`~.sweep.sweep_table`), two by two with the legend in the fourth cell: drawn
    at the size the results page shows it, so that its text reads there unscaled. Each
    curve is traced in the order of the scale; it need not be monotone, since a lower
    threshold can turn a detection into an alarm before onset."""
    data = sweep[sweep["subset"] == subset]
    methods = list(dict.fromkeys(data["method"]))
    shown = sweep_legend(data)
    palette = colors(shown)
    deadline = float(data["deadline_s"].iloc[0]) if len(data) else float("nan")
    with plt.rc_context({"font.size": 8, "axes.labelsize": 8, "xtick.labelsize": 7,
                         "ytick.labelsize": 7}):
        fig, grid = plt.subplots(2, 2, figsize=SWEEP_SIZE, layout="constrained")
    axes, key = [grid[0, 0], grid[0, 1], grid[1, 0]], grid[1, 1]
    panels = [
        ("false_alarm_flights", "recall", "fault-free flights alarmed (share)",
         f"detected ≤{deadline:g} s (recall)", "linear"),
        ("false_alarms_per_hour", "recall", "false alarms per hour, fault-free",
         f"detected ≤{deadline:g} s (recall)", "symlog"),
        ("false_alarms_per_hour", "mean_detection_s",
         "false alarms per hour, fault-free", "mean detection time (s)", "symlog"),
    ]
    for ax, (x, y, xlabel, ylabel, xscale) in zip(axes, panels, strict=True):
        # the runs outside the legend first, grey, under the best few
        others = [m for m in methods if m not in shown]
        for m in others + shown:
            d = data[data["method"] == m].sort_values("scale")
            named = m in shown
            color = palette[m] if named else "0.75"
            label = f"{m} ({d['block'].iloc[0]})" if named else None
            ax.plot(d[x], d[y], color=color, label=label, alpha=0.9 if named else 0.6,
                    **({**BLOCK_STYLES[d["block"].iloc[0]], "lw": 0.8} if not named
                       else BLOCK_STYLES[d["block"].iloc[0]]))
            at = d[d["scale"] == 1.0]
            ax.plot(at[x], at[y], "o", color=color, ms=5 if named else 3,
                    mec="black" if named else "0.6", mew=0.6)
        ax.set_xscale(xscale, **({"linthresh": 1.0} if xscale == "symlog" else {}))
        ax.set_xlabel(xlabel, fontsize=8)
        ax.set_ylabel(ylabel, fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    axes[0].set_xlim(-0.02, 1.02)
    axes[0].set_ylim(-0.02, 1.02)
    axes[1].set_ylim(-0.02, 1.02)
    if len(methods) > len(shown):
        axes[0].plot([], [], color="0.75", lw=0.8,
                     label=f"{len(methods) - len(shown)} other runs (grey)")
    handles, labels = axes[0].get_legend_handles_labels()
    key.axis("off")
    n = int(data["flights"].iloc[0]) if len(data) else 0
    key.legend(handles, labels, loc="center", fontsize=7, frameon=False,
               title=f"subset '{subset}', {n} flights;\nevery channel threshold scaled\n"
                     "by one factor; dots: as configured", title_fontsize=7)
    save(fig, path)


#: the sweep figure's size in inches: at :data:`DPI`, the width of the results page's
#: figure column (outputs/index_page.py), so the page shows it unscaled
SWEEP_SIZE = (5.6, 3.9)


#: the runs the sweep's legend names: the best honest ones at the configured thresholds
SWEEP_LEGEND = 6


def sweep_legend(data: pd.DataFrame) -> list[str]:
    """The :data:`SWEEP_LEGEND` honest runs of a subset's sweep with the most faults
    detected in time at the configured thresholds (fewer fault-free flights alarmed
    first among equals), best first: the curves drawn in colour."""
    at = data[(data["scale"] == 1.0) & (data["block"] == "honest")]
    best = at.sort_values(["recall", "false_alarm_flights"], ascending=[False, True],
                          kind="stable")
    return list(dict.fromkeys(best["method"]))[:SWEEP_LEGEND]


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
    # one y-axis set on each panel alike, not shared: a shared axis propagates each
    # change to every other panel, which costs seconds over one panel per run
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.0 * rows), squeeze=False)
    _grid_in_inches(fig, rows, cols, left=0.65, right=0.4, top=0.55, bottom=0.75,
                    between_rows=1.05, between_cols=0.35)
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
    ticks = list(np.arange(0, deadline_s + 1e-9, 1.0))
    for i, ax in enumerate(axes.flat[:len(methods)]):
        ax.set_ylim(0, 1.2 * deadline_s)
        ax.set_yticks([*ticks, late_at], [f"{t:g}" for t in ticks] + ["late"])
        ax.tick_params(labelleft=i % cols == 0)
    for ax in axes[:, 0]:
        ax.set_ylabel("detection time (s)")
    fig.suptitle(f"Detection time by fault class, scored with the {deadline_s:g} s deadline "
                 "(bar = median; label = detected in time / flights, + late: x, detected "
                 "by the paper's rule only)", fontsize=9, y=1 - 0.12 / fig.get_figheight(),
                 va="top")
    save(fig, path)


def deadline_figure(table: pd.DataFrame, subset: str, path: str | Path) -> None:
    """Detection rate against the deadline, one curve per run (honest solid, marked
    dashed, reference dotted); the legend gives the false alarms per hour."""
    data = table[table["subset"] == subset]
    methods = list(dict.fromkeys(data["method"]))
    palette = colors(methods)
    # the legend below the axes, two runs a line: inside them, one line a run hid the
    # curves once the field outgrew a dozen runs
    fig, ax = plt.subplots(figsize=(8.5, 4.5 + 0.15 * -(-len(methods) // 2)),
                           layout="constrained")
    for m in methods:
        d = data[data["method"] == m].sort_values("deadline_s")
        style = BLOCK_STYLES[d["block"].iloc[0]]
        fa = d["false_alarms_per_hour"].iloc[0]
        ax.plot(d["deadline_s"], d["detection_rate"], color=palette[m], marker=".", **style,
                label=f"{m} ({d['block'].iloc[0]}; {fmt(fa, digits=1)} false alarms/h)")
    ax.set_xscale("log")
    ax.set_xlabel("detection deadline after onset (s)")
    ax.set_ylabel("faults detected within the deadline (share)")
    ax.set_ylim(-0.02, 1.02)
    ax.grid(alpha=0.3, which="both")
    if methods:
        fig.legend(fontsize=7, loc="outside lower center", ncols=2)
    n = int(data["fault_flights"].iloc[0]) if len(data) else 0
    ax.set_title(f"Detection rate against deadline, subset '{subset}' ({n} fault flights)",
                 fontsize=10)
    save(fig, path)


def detectability_figure(table: pd.DataFrame, path: str | Path) -> None:
    """Detection rate against fault size (drift, scale) per method, and for the
    faults without a size (stuck, zero) and those beyond the paper (noise, ramp)."""
    if table.empty:
        fig = plt.figure(figsize=(13, 1.5))
        fig.text(0.5, 0.5, EMPTY, ha="center", va="center", wrap=True)
        save(fig, path)
        return
    by = by_fault(table)
    methods = list(dict.fromkeys(by["method"]))
    palette = colors(methods)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), layout="constrained")
    for ax, kind, size, label in [
            (axes[0], "drift", lambda m: m, "drift (fraction of the sensor's range)"),
            (axes[1], "scale", lambda m: 1 - m, "lost output, 1 - scale factor")]:
        for method in methods:
            d = by[(by["method"] == method) & (by["kind"] == kind)]
            x = size(d["magnitude"].to_numpy())
            order = np.argsort(x)
            ax.plot(x[order], d["detection_rate"].to_numpy()[order], "o-", label=method,
                    color=palette[method])
            ax.plot(x[order], d["chance_rate"].to_numpy()[order], ":", color=palette[method],
                    lw=1)
        ax.set_xlabel(label)
        ax.set_title(kind)
    other = [f for f in dict.fromkeys(zip(by["kind"], by["magnitude"], strict=True))
             if f[0] not in ("drift", "scale")]
    width = 0.8 / max(len(methods), 1)
    for i, method in enumerate(methods):
        d = by[by["method"] == method].set_index(["kind", "magnitude"])
        axes[2].bar(np.arange(len(other)) + i * width,
                    [d.loc[f, "detection_rate"] for f in other], width, color=palette[method])
    axes[2].set_xticks(np.arange(len(other)) + 0.4 - width / 2,
                       [fault_name(*f) for f in other], fontsize=8)
    axes[2].set_title("other faults")
    for ax in axes:
        ax.set_ylim(-0.03, 1.03)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("detection rate (dotted: chance rate)")
    axes[0].legend(fontsize=7)
    fig.suptitle("Detectability of injected sensor faults (all sensors, onsets, flights)")
    save(fig, path)
