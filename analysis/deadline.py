"""Detection rate against the detection deadline, beside the false alarms.

For a deadline :math:`D`, a fault flight counts as detected when its first alarm comes
at or after onset and at most :math:`D` after it. The false alarms do not depend on
:math:`D`: fault flights alarmed before onset, fault-free flights alarmed at all, and
alarm events (rising edges) per hour of fault-free flight (whole fault-free flights and
fault flights before onset). A method high on the curve only at long deadlines owes
its score to the paper's rule, not to detection.

Computed from the detection records alone (first alarm, alarm intervals, grid span),
so no detector is re-run.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from alfa_bench.data import subset_flights
from alfa_bench.render import fmt, markdown

from .blocks import BLOCKS, block
from .scoring import wilson_interval

__all__ = ["deadline_markdown", "deadline_table", "false_alarm_time"]


def false_alarm_time(record: dict) -> tuple[int, float]:
    """Alarm events and seconds of fault-free flight of one record: all of a
    fault-free flight, a fault flight up to its onset."""
    start, stop = record["grid"]["start_s"], record["grid"]["stop_s"]
    onset = record["onset_s"]
    end = stop if onset is None else min(max(onset, start), stop)
    # before onset, or anywhere in a fault-free flight (its last sample included)
    events = sum(1 for a, _ in record["alarm_intervals"] if a < end or onset is None)
    return events, end - start


def deadline_table(records: list[dict], manifest: pd.DataFrame, subsets,
                   deadlines) -> pd.DataFrame:
    """Per method, subset and deadline: fault flights, detected, detection rate with
    its Wilson 95 % interval, and the false alarms (the same at every deadline)."""
    by_method: dict[str, dict[str, dict]] = {}
    for r in records:
        by_method.setdefault(r["method"], {})[r["flight"]] = r
    rows = []
    for subset in subsets:
        flights = subset_flights(manifest, subset)
        for method, recs in by_method.items():
            scored = [recs[f] for f in flights if f in recs]
            if not scored:
                continue
            faults = [r for r in scored if r["onset_s"] is not None]
            free = [r for r in scored if r["onset_s"] is None]
            delay = np.array([np.inf if r["first_alarm_s"] is None
                              else r["first_alarm_s"] - r["onset_s"] for r in faults])
            events, seconds = np.sum([false_alarm_time(r) for r in scored], axis=0)
            early = int(np.sum(delay < 0))
            for d in deadlines:
                detected = int(np.sum((delay >= 0) & (delay <= d)))
                low, high = wilson_interval(detected, len(faults))
                rows.append({
                    "method": method, "subset": subset, "block": block(scored[0]),
                    "deadline_s": float(d), "fault_flights": len(faults),
                    "detected": detected,
                    "detection_rate": detected / len(faults) if faults else np.nan,
                    "detection_rate_low": low, "detection_rate_high": high,
                    "alarmed_before_onset": early, "fault_free_flights": len(free),
                    "fault_free_alarmed": sum(r["first_alarm_s"] is not None for r in free),
                    "false_alarms_per_hour": events / (seconds / 3600) if seconds else np.nan,
                })
    return pd.DataFrame(rows)


def deadline_markdown(table: pd.DataFrame, shown=(1.0, 2.0, 5.0, 10.0, 30.0)) -> str:
    """Per subset: the detection rate at a few deadlines, and the false alarms."""
    sections = []
    for subset, g in table.groupby("subset", sort=False):
        ds = [d for d in shown if d in set(g["deadline_s"])]
        header = ["method", "block", *[f"detected ≤{d:g} s" for d in ds],
                  "alarmed before onset", "fault-free flights alarmed", "false alarms / h"]
        rows = []
        for b in BLOCKS:
            for method, m in g[g["block"] == b].groupby("method", sort=False):
                at = m.set_index("deadline_s")
                first = m.iloc[0]
                rows.append([f"`{method}`", b,
                             *[f"{int(at.loc[d, 'detected'])} of {int(first['fault_flights'])}"
                               for d in ds],
                             str(first["alarmed_before_onset"]),
                             f"{first['fault_free_alarmed']} of {first['fault_free_flights']}",
                             fmt(first["false_alarms_per_hour"], digits=1)])
        sections.append((f"Subset `{subset}`: detection rate against the deadline", header,
                         rows))
    return markdown(sections)
