r"""Leakage audit: which signals carry the fault emulation, measured from the flights.

ALFA emulates a failure by overriding the failed actuator's output, so some recorded
signals change at onset because of the emulation, not of the aircraft. For every
catalogue signal (:data:`~alfa_bench.data.SIGNALS`) and fault class this asks how
often the signal *goes flat* at onset: a spell of unchanged value lasting at least
``flat_s`` begins within ``[onset - before_s, onset + after_s]`` (the ground truth's
onset is good to a few tenths of a second). The same event is counted elsewhere, as
a chance rate: the share of windows of the same width, placed every ``step_s`` over
the same flights before onset, and over the fault-free flights, in which such a
spell begins.

A signal *leaks* on a class when it goes flat at onset on at least half of the
class's flights and that count is improbable by chance: with :math:`n` flights,
:math:`k` of them flat at onset and :math:`p_0` the larger chance rate,

.. math:: P(X \ge k), \quad X \sim \mathrm{Bin}(n, p_0), \qquad < \alpha.

A signal constant over a whole flight is not measured on it (:func:`~alfa_bench.data.
not_measured`): that flight is counted apart and left out of the signal's rates.
Nothing here is hard-coded per signal; the kinds declared in the catalogue are set
beside what the data shows.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.stats import binom

from alfa_bench.data import SIGNALS, AlfaDataError, Flight, not_measured, series

from .tables import FAULT_ORDER, fmt, markdown

__all__ = ["flat_spell_starts", "leakage_markdown", "leakage_table"]


def flat_spell_starts(t: np.ndarray, value: np.ndarray, flat_s: float) -> np.ndarray:
    """Record times at which a spell of unchanged ``value`` lasting at least ``flat_s``
    begins (a spell runs until the next change, or the last row)."""
    start = np.flatnonzero(np.r_[True, value[1:] != value[:-1]])
    end = np.r_[t[start[1:]], t[-1]]
    return t[start][end - t[start] >= flat_s]


def _window_share(starts: np.ndarray, lo: float, hi: float, width: float,
                  step_s: float) -> tuple[int, int]:
    """Over windows ``[a, a + width]`` with ``a`` every ``step_s`` from ``lo`` to ``hi -
    width``: how many hold a spell start, and how many there are."""
    anchors = np.arange(lo, hi - width, step_s)
    if anchors.size == 0 or starts.size == 0:
        return 0, int(anchors.size)
    first = np.searchsorted(starts, anchors, side="left")
    hit = (first < starts.size) & (starts[np.minimum(first, starts.size - 1)] <= anchors + width)
    return int(hit.sum()), int(anchors.size)


def leakage_table(flights: dict[str, Flight], flat_s: float = 1.0, before_s: float = 0.5,
                  after_s: float = 1.0, margin_s: float = 1.0, step_s: float = 0.1,
                  alpha: float = 0.01) -> pd.DataFrame:
    """One row per catalogue signal and fault class of ``flights`` (with ground truth).

    Columns: ``signal``, ``kind``, ``fault_class``, ``flights`` (measured), ``not_measured``
    (flights of the class on which the signal is constant), ``flat_at_onset``,
    ``share_at_onset``, ``chance_before_onset`` (the same flights up to ``onset -
    margin_s``), ``chance_fault_free``, ``p_value`` and ``leaks``.
    """
    width = before_s + after_s
    labelled = {n: f for n, f in flights.items() if f.fault is not None}
    rows = []
    for name, sig in SIGNALS.items():
        per_class: dict[str, list] = {}
        hits = windows = 0
        for flight in labelled.values():
            if sig.topic not in flight.topics:
                continue
            try:
                dead = bool(not_measured(flight, [name]))
                t, value = series(flight, name)
            except AlfaDataError:
                continue
            entry = per_class.setdefault(flight.fault.fault_class, [])
            if dead:
                entry.append(None)
                continue
            starts = flat_spell_starts(t, value, flat_s)
            onset = flight.fault.onset_s
            if onset is None:
                h, w = _window_share(starts, float(t[0]), float(t[-1]), width, step_s)
                hits, windows = hits + h, windows + w
                continue
            at = bool(np.any((starts >= onset - before_s) & (starts <= onset + after_s)))
            entry.append((at, *_window_share(starts, float(t[0]), onset - margin_s, width,
                                             step_s)))
        chance_free = hits / windows if windows else math.nan
        for fault_class in [c for c in FAULT_ORDER if c in per_class and c != "none"]:
            entries = per_class[fault_class]
            live = [e for e in entries if e is not None]
            n, k = len(live), sum(e[0] for e in live)
            before = sum(e[2] for e in live)
            chance_before = sum(e[1] for e in live) / before if before else math.nan
            p0 = np.nanmax([chance_before, chance_free, 0.0])
            p = float(binom.sf(k - 1, n, p0)) if n else math.nan
            rows.append({
                "signal": name, "kind": sig.kind, "fault_class": fault_class, "flights": n,
                "not_measured": len(entries) - n, "flat_at_onset": k,
                "share_at_onset": k / n if n else math.nan,
                "chance_before_onset": chance_before, "chance_fault_free": chance_free,
                "p_value": p, "leaks": bool(n and k / n >= 0.5 and p < alpha),
            })
    return pd.DataFrame(rows)


def leakage_markdown(table: pd.DataFrame, flat_s: float = 1.0) -> str:
    """The verdict per signal (its kind, the classes it leaks on, the flights on which
    it is not measured), then the evidence per signal and class."""
    verdict = []
    for signal, g in table.groupby("signal", sort=False):
        leaks = ", ".join(g.loc[g["leaks"], "fault_class"]) or "none"
        actuator = g["kind"].iloc[0] == "actuator"
        agrees = ("yes" if g["leaks"].any() == actuator else
                  "not shown: no leak on these flights" if actuator else
                  "NO: it leaks, so it must not be read as a sensor or setpoint")
        verdict.append([f"`{signal}`", g["kind"].iloc[0], leaks, agrees,
                        f"{int(g['not_measured'].sum())} of "
                        f"{int(g['not_measured'].sum() + g['flights'].sum())}"])
    evidence = [[f"`{r['signal']}`", r["fault_class"], f"{r['flat_at_onset']} of {r['flights']}",
                 fmt(r["share_at_onset"], True, 0), fmt(r["chance_before_onset"], True, 1),
                 fmt(r["chance_fault_free"], True, 1),
                 "-" if math.isnan(r["p_value"]) else f"{r['p_value']:.1e}",
                 "**leaks**" if r["leaks"] else ""]
                for r in table.to_dict(orient="records")]
    return markdown([
        ("Which signals carry the fault emulation", ["signal", "kind (declared)",
                                                     "leaks on", "data agrees with kind",
                                                     "fault flights not measured (constant)"],
         verdict),
        (f"Goes flat (unchanged ≥ {flat_s:g} s) at onset, against chance",
         ["signal", "fault", "flat at onset", "share %", "chance before onset %",
          "chance fault-free %", "p (binomial)", ""], evidence),
    ])
