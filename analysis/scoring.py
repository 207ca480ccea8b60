"""Per-flight scoring: Keipour et al.'s rule (ICRA 2019, Sec. V-C), with a deadline.

- fault flight, first alarm at or after onset and at most ``deadline_s`` after it:
  true positive, detection time = first alarm - onset;
- fault flight, first alarm later than onset + ``deadline_s``: a false negative (a
  miss); without a deadline (the paper's rule) a true positive, however late;
- fault flight, first alarm before onset: a false positive *and* a false negative;
- fault flight, no alarm: false negative;
- fault-free flight: any alarm is a false positive, none a true negative.

Precision = TP / (TP + FP), recall = TP / (TP + FN), accuracy = correct flights /
flights, a flight being correct when it is TP or TN.

The paper's rule rewards lateness: one alarm at the last sample of every flight
scores ~0.77 accuracy on its 22 flights. The deadline is therefore the primary
score, the paper's rule beside it. With a few dozen flights one flight moves a rate
by several points, so every rate comes with a Wilson 95 % interval
(:func:`wilson_interval`), and two methods scored on the same flights are compared
by the exact McNemar test on the flights where one is correct and the other not
(:func:`mcnemar_exact`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction

__all__ = ["OUTCOMES", "flight_outcome", "mcnemar_exact", "rates", "score_records",
           "summarize", "wilson_interval"]

OUTCOMES = ("TP", "FP", "FN", "TN", "FP+FN")


def flight_outcome(onset_s: float | None, first_alarm_s: float | None,
                   deadline_s: float = math.inf) -> str:
    """Outcome of one flight; ``onset_s`` is None for a fault-free flight. A first
    alarm after ``onset_s + deadline_s`` is a miss (the default: no deadline)."""
    if onset_s is None:
        return "TN" if first_alarm_s is None else "FP"
    if first_alarm_s is None or first_alarm_s - onset_s > deadline_s:
        return "FN"
    return "TP" if first_alarm_s >= onset_s else "FP+FN"


def wilson_interval(successes: int, trials: int, level: float = 0.95) -> tuple[float, float]:
    r"""Wilson score interval of a proportion (NaN, NaN without trials).

    With :math:`p = k/n` and :math:`z = \Phi^{-1}(\tfrac12 + \tfrac12\,\mathrm{level})`
    (Newcombe 1998, in the form and order of ``scipy.stats.binomtest``'s ``"wilson"``,
    which computes a p-value besides and took most of the sweep's time):

    .. math:: \frac{2np + z^2}{2(n + z^2)} \pm \frac{z}{2(n + z^2)}\sqrt{4npq + z^2},

    with the lower end 0 at :math:`k = 0` and the upper end 1 at :math:`k = n`."""
    if trials == 0:
        return math.nan, math.nan
    from scipy.special import ndtri  # here: the detect jobs score outcomes, not intervals

    k, n = successes, trials
    p = k / n
    z = float(ndtri(0.5 + 0.5 * level))
    denom = 2 * (n + z**2)
    center = (2 * n * p + z**2) / denom
    delta = z / denom * math.sqrt(4 * n * p * (1 - p) + z**2)
    return (0.0 if k == 0 else float(center - delta)), (1.0 if k == n else float(center + delta))


def mcnemar_exact(correct_a: Sequence[bool], correct_b: Sequence[bool]) -> dict:
    r"""Exact McNemar test of two methods on the same flights.

    Only discordant flights carry information: ``b`` where only A is correct, ``c``
    where only B is. Under equal accuracy each discordant flight goes either way with
    probability 1/2, so the two-sided p-value is that of ``b`` in
    :math:`\mathrm{Bin}(n, 1/2)`, :math:`n = b + c`. The law is symmetric, so the
    outcomes as unlikely as ``b`` are the two tails beyond :math:`m = \min(b, c)`:

    .. math:: p = \min\Bigl(1,\; 2^{1-n} \sum_{j=0}^{m} \binom{n}{j}\Bigr),

    summed in integers and rounded once (1 without discordant flights). It is
    ``scipy.stats.binomtest(b, n).pvalue`` without its float tails, or its import."""
    if len(correct_a) != len(correct_b):
        raise ValueError("McNemar needs the same flights for both methods")
    b = sum(1 for x, y in zip(correct_a, correct_b, strict=True) if x and not y)
    c = sum(1 for x, y in zip(correct_a, correct_b, strict=True) if y and not x)
    n = b + c
    tails = 2 * sum(math.comb(n, j) for j in range(min(b, c) + 1))
    return {"only_a": b, "only_b": c, "p_value": min(1.0, float(Fraction(tails, 2**n)))}


def _ratio(a: int, b: int) -> float:
    return a / b if b else math.nan


def rates(outcomes: Sequence[str], detection_s: Sequence[float | None] = ()) -> dict:
    """:func:`summarize` without the intervals: the counts, precision, recall, accuracy
    and the detection times (cheap enough to score the calibration pools with)."""
    bad = set(outcomes) - set(OUTCOMES)
    if bad:
        raise ValueError(f"unknown outcomes {sorted(bad)}")
    n = {o: sum(1 for x in outcomes if x == o) for o in OUTCOMES}
    tp, tn = n["TP"], n["TN"]
    fp, fn = n["FP"] + n["FP+FN"], n["FN"] + n["FP+FN"]
    times = [d for d in detection_s if d is not None]
    return {"flights": len(outcomes), "tp": tp, "fp": fp, "fn": fn, "tn": tn,
            "precision": _ratio(tp, tp + fp), "recall": _ratio(tp, tp + fn),
            "accuracy": _ratio(tp + tn, len(outcomes)),
            "mean_detection_s": sum(times) / len(times) if times else math.nan,
            "max_detection_s": max(times) if times else math.nan}


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
        flights, tp, fp, fn, tn, precision, recall, accuracy (fractions), each rate
        with its Wilson 95 % interval (``<rate>_low``, ``<rate>_high``),
        mean_detection_s, max_detection_s (NaN without true positives).
    """
    r = rates(outcomes, detection_s)
    tp, fp, fn, tn = r["tp"], r["fp"], r["fn"], r["tn"]
    out = {k: r[k] for k in ("flights", "tp", "fp", "fn", "tn")}
    for name, (k, n) in {"precision": (tp, tp + fp), "recall": (tp, tp + fn),
                         "accuracy": (tp + tn, r["flights"])}.items():
        out[name] = r[name]
        out[f"{name}_low"], out[f"{name}_high"] = wilson_interval(k, n)
    return {**out, "mean_detection_s": r["mean_detection_s"],
            "max_detection_s": r["max_detection_s"]}


def score_records(records: Sequence[dict], deadline_s: float = math.inf) -> tuple[list[str], dict]:
    """Per-flight outcomes of detection ``records`` (``onset_s``, ``first_alarm_s``)
    under ``deadline_s``, and their :func:`summarize`."""
    outcomes = [flight_outcome(r["onset_s"], r["first_alarm_s"], deadline_s) for r in records]
    times = [r["first_alarm_s"] - r["onset_s"] if o == "TP" else None
             for r, o in zip(records, outcomes, strict=True)]
    return outcomes, summarize(outcomes, times)
