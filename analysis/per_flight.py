"""What each run did on each labelled flight: which faults it finds, misses or pre-empts,
and by how much.

The tables count outcomes; this lists them, so that a miss can be traced to its flight:
per (method, flight) the outcome under the deadline, the first alarm relative to the
onset, and the channel that raised it (the earliest of the record's
``pair_first_alarm_s``). ``verdict`` says it in words: ``detected in 0.48 s (side)``,
``alarm 10.4 s before onset (thrust)``, ``first alarm 12.6 s after onset, past the
deadline (pitch)``, ``no alarm``, ``false alarm at 72.0 s (thrust)``.

A detection in time is flagged when its first channel cannot see the fault's class:
``detected_class`` is the class acting on the axis its first alarm isolates
(:func:`~.isolation.named_class`; an aileron flight alarmed first by ``thrust`` names
``engine``; empty where no class is named), and ``other_class`` is true where it is
another than the flight's class, so the
verdict adds ``first on the engine axis, not aileron``. Nothing is removed.

Margins, from the stored traces, in units of the threshold (a channel alarms above 1):
``margin_in_time`` is the largest score/threshold of any channel from the onset to the
deadline, with its ``margin_channel``: how near the fault came to being detected in
time. ``margin_before`` is the largest before the onset (over the whole flight when
fault-free): how near the flight came to a false alarm. A fault whose in-time margin is
below the margins fault-free flying reaches has no signature this method can use at
any threshold.

``survival`` is the share of resampled calibration pools under which the outcome stays
the one reported (:func:`~.stability.survival`; NaN for a run without pools): a
detection near its threshold is luck until it survives the pools.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from alfa_bench.data import subset_flights
from alfa_bench.methods import Trace
from alfa_bench.render import fmt, markdown

from .blocks import BLOCK_MARKS, BLOCKS, block
from .isolation import named_class, names_class
from .scoring import flight_outcome
from .stability import survival

__all__ = ["margins", "per_flight_frame", "per_flight_markdown", "per_flight_rows",
           "per_flight_table", "subset_counts", "verdict"]


def verdict(onset_s: float | None, first_alarm_s: float | None, channel: str | None,
            deadline_s: float, other_axis: tuple[str, str] | None = None) -> str:
    """The outcome of one flight in words (module docstring); ``other_axis`` is
    ``(named class, true class)`` for a detection first on another class's axis."""
    by = f" ({channel})" if channel else ""
    if first_alarm_s is None:
        return "no alarm"
    if onset_s is None:
        return f"false alarm at {first_alarm_s:.1f} s{by}"
    delay = first_alarm_s - onset_s
    if delay < 0:
        return f"alarm {-delay:.1f} s before onset{by}"
    if delay > deadline_s:
        return f"first alarm {delay:.1f} s after onset, past the deadline{by}"
    flag = f", first on the {other_axis[0]} axis, not {other_axis[1]}" if other_axis else ""
    return f"detected in {delay:.2f} s{by}{flag}"


def _first_channel(record: dict) -> str | None:
    alarms = {c: t for c, t in (record.get("pair_first_alarm_s") or {}).items() if t is not None}
    return min(alarms, key=alarms.get) if alarms else None


def margins(trace: Trace, onset_s: float | None,
            deadline_s: float) -> tuple[float, str | None, float]:
    """``(margin_in_time, margin_channel, margin_before)`` of one flight (module
    docstring); NaN and None where there is no such span or no finite score."""
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = trace.score / trace.threshold
    before = trace.t < (math.inf if onset_s is None else onset_s)

    def peak(rows):
        r = ratio[rows]
        if not np.isfinite(r).any():
            return math.nan, None
        k, c = np.unravel_index(np.nanargmax(r), r.shape)
        return float(r[k, c]), trace.channels[c]

    in_time = (math.nan, None) if onset_s is None else peak(
        (trace.t >= onset_s) & (trace.t <= onset_s + deadline_s))
    return in_time[0], in_time[1], peak(before)[0]


def per_flight_rows(records: list[dict], traces: Mapping[tuple[str, str], Trace],
                    manifest: pd.DataFrame, deadline_s: float,
                    subset: str = "all") -> list[dict]:
    """The rows of :func:`per_flight_table`, in the order of ``records``: a run's
    alone are its part of the table (:func:`per_flight_frame` merges the parts)."""
    flights = set(subset_flights(manifest, subset))
    emr = manifest.set_index("flight")["emergency_trajectory"]
    rows = []
    for r in records:
        if r["flight"] not in flights:
            continue
        onset, first = r["onset_s"], r["first_alarm_s"]
        channel = _first_channel(r)
        outcome = flight_outcome(onset, first, deadline_s)
        detected = named_class(r) if outcome == "TP" else None
        other = detected is not None and not names_class(r)
        in_time, margin_channel, before = margins(traces[r["method"], r["flight"]], onset,
                                                  deadline_s)
        rows.append({
            "method": r["method"], "block": block(r), "flight": r["flight"],
            "fault_class": r["fault_class"], "emergency_trajectory": bool(emr[r["flight"]]),
            "onset_s": onset, "first_alarm_s": first,
            "delay_s": first - onset if onset is not None and first is not None else math.nan,
            "first_channel": channel, "outcome": outcome,
            "detected_class": detected or "", "other_class": other,
            "verdict": verdict(onset, first, channel, deadline_s,
                               (detected, r["fault_class"]) if other else None),
            "margin_in_time": in_time, "margin_channel": margin_channel,
            "margin_before": before, "survival": survival(r, deadline_s)})
    return rows


def per_flight_frame(rows: list[dict]) -> pd.DataFrame:
    """The table of :func:`per_flight_rows` (every run's, in run order), ordered by
    block, method and flight."""
    table = pd.DataFrame(rows)
    if table.empty:
        return table
    order = {b: i for i, b in enumerate(BLOCKS)}
    return table.sort_values(["block", "method", "flight"],
                             key=lambda c: c.map(order) if c.name == "block" else c,
                             kind="stable").reset_index(drop=True)


def per_flight_table(records: list[dict], traces: Mapping[tuple[str, str], Trace],
                     manifest: pd.DataFrame, deadline_s: float,
                     subset: str = "all") -> pd.DataFrame:
    """One row per record of a flight of ``subset``: method, block, flight, fault class,
    emergency trajectory, onset, first alarm, delay, the first channel, the outcome
    under ``deadline_s``, the verdict and the :func:`margins` from ``traces`` (by
    method and flight)."""
    return per_flight_frame(per_flight_rows(records, traces, manifest, deadline_s, subset))


def per_flight_markdown(table: pd.DataFrame, deadline_s: float) -> str:
    """One Markdown table per method: flight, fault, outcome, verdict and margins."""
    if table.empty:
        return "No labelled flight was scored.\n"
    sections = []
    for method, rows in table.groupby("method", sort=False):
        mark = BLOCK_MARKS[rows["block"].iloc[0]]
        sections.append((f"`{method}`{mark}, deadline {deadline_s:g} s",
                         ["flight", "fault", "emr", "outcome", "what happened",
                          f"largest score/threshold, onset to +{deadline_s:g} s",
                          "largest before onset", "survival, calibration flights resampled"],
                         [[f"`{r['flight']}`", r["fault_class"],
                           "yes" if r["emergency_trajectory"] else "",
                           fmt(r["outcome"]), r["verdict"],
                           (f"{fmt(r['margin_in_time'])} ({r['margin_channel']})"
                            if isinstance(r["margin_channel"], str) else "-"),
                           fmt(r["margin_before"]), fmt(r["survival"])]
                          for r in rows.to_dict(orient="records")]))
    return markdown(sections)


def subset_counts(runs: pd.DataFrame, members: set[str], stable: float) -> dict:
    """One run's rows of the per-flight table on the flights ``members``: its faulty
    flights and the faults detected in time, the faulty flights alarmed before onset,
    the fault-free flights and those alarmed, and the detections stable under resampled
    calibration pools (survival >= ``stable``; None where the run has no pools)."""
    sub = runs[runs["flight"].isin(members)]
    faulty = sub["fault_class"] != "none"
    early = sub["first_alarm_s"] < sub["onset_s"]
    in_time = faulty & (sub["outcome"] == "TP")
    return {"faulty_flights": int(faulty.sum()), "detected": int(in_time.sum()),
            "early_alarms": int((faulty & early).sum()),
            "fault_free_flights": int((~faulty).sum()),
            "fault_free_alarmed": int((~faulty & sub["first_alarm_s"].notna()).sum()),
            "stable_detections": (int((in_time & (sub["survival"] >= stable)).sum())
                                  if sub["survival"].notna().any() else None)}
