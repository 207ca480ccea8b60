"""Per-flight scoring as Keipour et al. count it (ICRA 2019, Sec. V-C).

- fault flight, first alarm at or after onset: true positive, detection time =
  first alarm - onset;
- fault flight, first alarm before onset: a false positive *and* a false negative;
- fault flight, no alarm: false negative;
- fault-free flight: any alarm is a false positive, none a true negative.

Precision = TP / (TP + FP), recall = TP / (TP + FN), accuracy = correct flights /
flights, a flight being correct when it is TP or TN.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["OUTCOMES", "flight_outcome", "summarize"]

OUTCOMES = ("TP", "FP", "FN", "TN", "FP+FN")


def flight_outcome(onset_s: float | None, first_alarm_s: float | None) -> str:
    """Outcome of one flight; ``onset_s`` is None for a fault-free flight."""
    if onset_s is None:
        return "TN" if first_alarm_s is None else "FP"
    if first_alarm_s is None:
        return "FN"
    return "TP" if first_alarm_s >= onset_s else "FP+FN"


def _ratio(a: int, b: int) -> float:
    return a / b if b else math.nan


def summarize(outcomes: Sequence[str], detection_s: Sequence[float | None] = ()) -> dict:
    """Counts and rates over flights.

    Parameters
    ----------
    outcomes : sequence of str
        One of :data:`OUTCOMES` per flight.
    detection_s : sequence of float or None
        Detection times of the true positives (others are ignored if None).

    Returns
    -------
    dict
        flights, tp, fp, fn, tn, precision, recall, accuracy (fractions),
        mean_detection_s, max_detection_s (NaN without true positives).
    """
    bad = set(outcomes) - set(OUTCOMES)
    if bad:
        raise ValueError(f"unknown outcomes {sorted(bad)}")
    n = {o: sum(1 for x in outcomes if x == o) for o in OUTCOMES}
    tp, tn = n["TP"], n["TN"]
    fp, fn = n["FP"] + n["FP+FN"], n["FN"] + n["FP+FN"]
    times = [d for d in detection_s if d is not None]
    return {
        "flights": len(outcomes),
        "tp": tp, "fp": fp, "fn": fn, "tn": tn,
        "precision": _ratio(tp, tp + fp),
        "recall": _ratio(tp, tp + fn),
        "accuracy": _ratio(tp + tn, len(outcomes)),
        "mean_detection_s": sum(times) / len(times) if times else math.nan,
        "max_detection_s": max(times) if times else math.nan,
    }
