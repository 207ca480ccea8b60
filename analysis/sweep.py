"""Threshold sweeps from stored traces, without re-running any detector.

Every channel threshold of a run is scaled by the same factor :math:`\\kappa`. By the
detector contract (a channel alarms when its score exceeds its threshold), the run
alarms at scale :math:`\\kappa` at step :math:`k` when

.. math:: r(k) = \\max_c s_c(k) / \\gamma_c > \\kappa,

so :math:`\\kappa = 1` is the run as configured, exactly (floating-point division is
monotone and :math:`s > \\gamma \\Leftrightarrow s/\\gamma > 1`). A detector whose
state depends on its own threshold (``ffrls_monitor`` freezes adaptation while its
residual test is up) is swept open-loop: its scores stay those of the configured run.

Per scale, flights are scored as :mod:`.scoring` scores them, with the detection
deadline (and the paper's rule beside it: ``recall_paper``, ``accuracy_paper``), and
false alarms are also counted as events (rising edges of the alarm) per hour of
fault-free flight: whole fault-free flights and faulty flights before onset.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from alfa_bench.data import subset_flights
from alfa_bench.methods import Trace

from .blocks import block
from .scoring import flight_outcome, summarize

__all__ = ["DEFAULT_SCALES", "flight_curves", "merge_sweeps", "ratio", "sweep_table"]

#: :math:`\kappa` from 1/100 to 10^4, 50 per decade; 1 is on it exactly.
DEFAULT_SCALES = 10.0 ** (np.arange(-100, 201) / 50)


def ratio(trace: Trace) -> np.ndarray:
    """:math:`r(k)`, the largest score-to-threshold ratio; -inf where no channel is armed."""
    with np.errstate(invalid="ignore"):
        r = trace.score / trace.threshold
    r = np.where(np.isnan(r), -np.inf, r)
    return r.max(axis=1)


def flight_curves(trace: Trace, onset_s: float | None, scales: np.ndarray) -> dict:
    """For one flight, per scale: the first alarm (NaN if none), the alarm events
    and the seconds of fault-free flight (before ``onset_s``, or all of a fault-free
    flight)."""
    r = ratio(trace)
    running = np.maximum.accumulate(r)
    first = np.searchsorted(running, scales, side="right")  # first k with r(k) > kappa
    first_s = np.where(first < r.size, trace.t[np.minimum(first, r.size - 1)], np.nan)
    n_free = r.size if onset_s is None else int(np.searchsorted(trace.t, onset_s, "left"))
    free = r[:n_free]
    lo, hi = np.r_[-np.inf, free[:-1]], free
    rising = lo < hi                                          # an edge for lo <= kappa < hi
    lo, hi = np.sort(lo[rising]), np.sort(hi[rising])
    events = (np.searchsorted(lo, scales, side="right") - np.searchsorted(hi, scales, "right"))
    dt = float(np.median(np.diff(trace.t))) if trace.t.size > 1 else 0.0
    return {"first_alarm_s": first_s, "events": events, "free_s": n_free * dt}


def sweep_table(records: list[dict], traces: Mapping[tuple[str, str], Trace],
                manifest: pd.DataFrame, subsets, deadline_s: float,
                scales=DEFAULT_SCALES) -> pd.DataFrame:
    """Per method, subset and scale: the scoring of :func:`~.scoring.summarize` under
    ``deadline_s``, the paper's recall and accuracy (no deadline), plus
    ``false_alarm_flights`` (share of flights alarmed in fault-free flight) and
    ``false_alarms_per_hour``. ``traces`` maps (method, flight) to its trace."""
    scales = np.asarray(scales, dtype=float)
    curves = {(r["method"], r["flight"]): (r, flight_curves(traces[r["method"], r["flight"]],
                                                            r["onset_s"], scales))
              for r in records}
    methods = list(dict.fromkeys(r["method"] for r in records))
    blocks = {r["method"]: block(r) for r in records}
    rows = []
    for subset in subsets:
        flights = subset_flights(manifest, subset)
        for method in methods:
            # an excluded flight has no curve (the tables count it)
            cs = [curves[method, f] for f in flights if (method, f) in curves]
            hours = sum(c["free_s"] for _, c in cs) / 3600.0
            events = np.sum([c["events"] for _, c in cs], axis=0)
            firsts = np.array([c["first_alarm_s"] for _, c in cs]).reshape(len(cs), scales.size)
            for i, kappa in enumerate(scales):
                # the first alarms change at few of the scales: score only where they do
                if i == 0 or not np.array_equal(firsts[:, i], firsts[:, i - 1],
                                                equal_nan=True):
                    s, p = _score([rec for rec, _ in cs], firsts[:, i], deadline_s)
                rows.append({
                    "method": method, "subset": subset, "block": blocks[method],
                    "deadline_s": deadline_s, "scale": float(kappa), **s,
                    "recall_paper": p["recall"], "accuracy_paper": p["accuracy"],
                    "false_alarm_flights": (s["fp"] / s["flights"]) if s["flights"] else np.nan,
                    "false_alarms_per_hour": events[i] / hours if hours else np.nan,
                    "fault_free_hours": hours,
                })
    return pd.DataFrame(rows)


def merge_sweeps(parts: pd.DataFrame, subsets) -> pd.DataFrame:
    """The :func:`sweep_table` of every run from each run's own (``parts``: stacked in
    run order), in its order: subset by subset, the runs in order within each."""
    if parts.empty:
        return parts
    order = {s: i for i, s in enumerate(subsets)}
    return parts.sort_values("subset", key=lambda c: c.map(order),
                             kind="stable").reset_index(drop=True)


def _score(records: list[dict], firsts: np.ndarray, deadline_s: float) -> tuple[dict, dict]:
    """:func:`summarize` of the flights with first alarms ``firsts`` (NaN: none), with
    the deadline and by the paper's rule."""
    outcomes, times, paper = [], [], []
    for rec, first in zip(records, firsts, strict=True):
        first = None if np.isnan(first) else float(first)
        outcome = flight_outcome(rec["onset_s"], first, deadline_s)
        outcomes.append(outcome)
        times.append(first - rec["onset_s"] if outcome == "TP" else None)
        paper.append(flight_outcome(rec["onset_s"], first))
    return summarize(outcomes, times), summarize(paper)
