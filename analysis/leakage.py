r"""Leakage audit: which signals carry the fault's label, measured from the flights.

ALFA emulates a failure by overriding the failed actuator's output, and on the
``with_emr_traj`` flights its injector also switches the autopilot to an emergency
trajectory at onset. Either way some recorded signals change at onset because of
the injection, not of the aircraft. For every catalogue signal
(:data:`~alfa_bench.data.SIGNALS`), fault class and emergency trajectory (with or
without) this counts two events at onset, each against its chance rate:

*Goes flat.* A spell of unchanged value lasting at least ``flat_s`` begins within
``[onset - before_s, onset + after_s]`` (the ground truth's onset is good to a few
tenths of a second). Its chance rate is the share of windows of the same width,
placed every ``step_s`` before onset on the same flights, and over the fault-free
flights, in which such a spell begins.

*Steps.* On a causal hold of the signal at ``rate_hz``, the step at :math:`\tau`
is how far it moves over the :math:`w` = ``step_window_s`` after :math:`\tau` from its
mean over the :math:`w` before,

.. math:: d(\tau) = \max_{\tau \le s < \tau + w} \bigl|\,x(s) - \bar x_{[\tau - w,
   \tau)}\,\bigr|,

and a flight steps at onset when :math:`d(\text{onset})` exceeds the share
``step_quantile`` of the steps of its reference, the ``reference_s`` before (windows
that end by then; at least ``min_reference_s`` of them, else the flight is not
tested). Its chance rate is the share of instants, every ``step_s`` s before
``onset - margin_s`` and over the fault-free flights, whose step exceeds the same
share of their own reference.

A count is improbable by chance when, with :math:`n` flights, :math:`k` of them
showing the event at onset and :math:`p_0` the larger chance rate,

.. math:: P(X \ge k), \quad X \sim \mathrm{Bin}(n, p_0), \qquad < \alpha.

A signal *goes flat* on a group when that holds and :math:`k \ge n/2`, and *steps* on
it when that holds. What that means depends on the signal's kind:

- a signal that goes flat carries the emulation, whatever its kind (a sensor that
  did would contradict its kind);
- a ``setpoint`` that steps carries the label: a real fault reaches the outer loop's
  commands only through the aircraft, over seconds. The step of a setpoint is taken
  on its command: for an error against a command (``roll_error``, measured minus
  commanded) the command it subtracts, since its measured part is a sensor's;
- a ``sensor`` that steps measures the aircraft's response: the signature a detector
  is there to find, or on an emergency-trajectory flight the manoeuvre the new
  commands cause. An ``actuator`` that steps may be the inner loop answering the
  aircraft within the window as well as the emulation; the flat test is its evidence.
  Both are shown, not counted as leaks.

So ``leaks`` = goes flat, or steps and is a setpoint. A group of flights on which a
sensor or setpoint leaks is one on which an honest method can read the label; the
primary subset must hold none (:func:`leaking_flights`).

A signal constant over a whole flight is not measured on it (:func:`~alfa_bench.data.
not_measured`): that flight is counted apart and left out of the signal's rates.
Nothing here is hard-coded per signal; the kinds declared in the catalogue are set
beside what the data shows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.lib.stride_tricks import sliding_window_view

from alfa_bench.data import (
    SIGNALS,
    AlfaDataError,
    Flight,
    in_subset,
    not_measured,
    series,
    subset_flights,
)
from alfa_bench.render import fmt, markdown

from .blocks import FAULT_ORDER

__all__ = ["StepTest", "audit_note", "flat_spell_starts", "leaking_flights", "leakage_markdown",
           "leakage_table", "step_ranks", "step_sizes"]


#: fault classes in the tables' order, for sorting the audit's groups
_ORDER = {c: i for i, c in enumerate(FAULT_ORDER)}


@dataclass(frozen=True)
class StepTest:
    """The step test's settings (module docstring)."""

    rate_hz: float = 10.0
    step_window_s: float = 1.5
    reference_s: float = 60.0
    min_reference_s: float = 20.0
    step_quantile: float = 0.95
    step_s: float = 1.0


def flat_spell_starts(t: np.ndarray, value: np.ndarray, flat_s: float) -> np.ndarray:
    """Record times at which a spell of unchanged ``value`` lasting at least ``flat_s``
    begins (a spell runs until the next change, or the last row)."""
    start = np.flatnonzero(np.r_[True, value[1:] != value[:-1]])
    end = np.r_[t[start[1:]], t[-1]]
    return t[start][end - t[start] >= flat_s]


def step_sizes(t: np.ndarray, value: np.ndarray, rate_hz: float,
               window_s: float) -> tuple[np.ndarray, np.ndarray]:
    """``(tau, d)``: the step :math:`d(\\tau)` of the module docstring at every grid time
    :math:`\\tau = k / f_s` with a full window either side, ``value`` held causally
    from its record times ``t``."""
    grid = np.arange(np.ceil(t[0] * rate_hz), np.floor(t[-1] * rate_hz) + 1) / rate_hz
    x = value[np.searchsorted(t, grid, side="right") - 1]
    w = max(int(round(window_s * rate_hz)), 1)
    if grid.size < 2 * w:
        return grid[:0], x[:0]
    c = np.r_[0.0, np.cumsum(x)]
    i = np.arange(w, grid.size - w + 1)
    before = (c[i] - c[i - w]) / w
    return grid[i], np.abs(sliding_window_view(x, w)[i] - before[:, None]).max(axis=1)


def step_ranks(d: np.ndarray, at: np.ndarray, reference: int, gap: int,
               least: int | None = None) -> np.ndarray:
    """Per index ``i`` of ``at``: the share of the reference steps, the ``reference``
    ending ``gap`` indices before ``i`` (fewer where the signal starts later, down to
    ``least``; NaN with fewer still), that are below ``d[i]``."""
    least = reference if least is None else least
    out = np.full(at.size, np.nan)
    for j, i in enumerate(at):
        ref = d[max(i - gap - reference + 1, 0):i - gap + 1]
        if ref.size >= least:
            out[j] = np.mean(ref < d[i])
    return out


def _step_events(tau: np.ndarray, d: np.ndarray, onset: float | None, margin_s: float,
                 test: StepTest) -> tuple[bool | None, int, int]:
    """``(steps at onset, chance hits, chance instants)`` of one flight: None at onset
    for a fault-free flight or one with too little reference before its onset."""
    gap = int(round(test.step_window_s * test.rate_hz))
    ref = int(round(test.reference_s * test.rate_hz))
    least = int(round(test.min_reference_s * test.rate_hz))
    at = None
    end = d.size if onset is None else int(np.searchsorted(tau, onset - margin_s))
    if onset is not None:
        k = int(np.searchsorted(tau, onset - 0.5 / test.rate_hz))
        rank = step_ranks(d, np.array([k]), ref, gap, least) if k < d.size else [np.nan]
        at = None if np.isnan(rank[0]) else bool(rank[0] > test.step_quantile)
    every = max(int(round(test.step_s * test.rate_hz)), 1)
    ranks = step_ranks(d, np.arange(gap + least - 1, end, every), ref, gap, least)
    return at, int(np.sum(ranks > test.step_quantile)), int(ranks.size)


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


def _command_part(flight: Flight, name: str) -> tuple[np.ndarray, np.ndarray]:
    """What the step test reads of signal ``name``: a setpoint's command (module
    docstring), any other signal itself."""
    sig = SIGNALS[name]
    if sig.kind == "setpoint" and sig.minus:
        tp = flight.topic(sig.topic)
        return tp.t, tp.values(sig.minus)
    return series(flight, name)


def _verdict_p(k: int, n: int, p0: float) -> float:
    # here: the tables, index page and paper read the audit's note, not its test, and
    # scipy.stats would cost each of them a second to import
    from scipy.stats import binom

    return float(binom.sf(k - 1, n, p0)) if n else math.nan


#: the columns of :func:`leakage_table`, which it has when no flight has a fault too
LEAKAGE_COLUMNS = ["signal", "kind", "fault_class", "emergency_trajectory", "flights",
                   "not_measured", "flat_at_onset", "flat_share", "flat_chance_before",
                   "flat_chance_fault_free", "flat_p", "goes_flat", "step_flights",
                   "step_at_onset", "step_share", "step_chance_before",
                   "step_chance_fault_free", "step_p", "steps", "leaks"]


def leakage_table(flights: dict[str, Flight], flat_s: float = 1.0, before_s: float = 0.5,
                  after_s: float = 1.0, margin_s: float = 1.0, step_s: float = 0.1,
                  alpha: float = 0.01, step: StepTest = StepTest()) -> pd.DataFrame:
    """One row per catalogue signal, fault class and emergency trajectory of
    ``flights`` (with ground truth).

    Columns: ``signal``, ``kind``, ``fault_class``, ``emergency_trajectory``,
    ``flights`` (measured), ``not_measured`` (flights of the group on which the signal
    is constant); for the flat test ``flat_at_onset``, ``flat_share``,
    ``flat_chance_before``, ``flat_chance_fault_free``, ``flat_p`` and ``goes_flat``;
    for the step test ``step_flights`` (tested: enough reference before onset),
    ``step_at_onset``, ``step_share``, ``step_chance_before``,
    ``step_chance_fault_free``, ``step_p`` and ``steps``; and ``leaks`` (module
    docstring).
    """
    width = before_s + after_s
    labelled = {n: f for n, f in flights.items() if f.fault is not None}
    rows = []
    for name, sig in SIGNALS.items():
        groups: dict[tuple[str, bool], list] = {}
        free = np.zeros(4, dtype=int)        # flat hits, windows; step hits, instants
        for flight in labelled.values():
            if sig.topic not in flight.topics:
                continue
            try:
                dead = bool(not_measured(flight, [name]))
                t, value = series(flight, name)
                tau, d = step_sizes(*_command_part(flight, name), step.rate_hz,
                                    step.step_window_s)
            except AlfaDataError:
                continue
            onset = flight.fault.onset_s
            if onset is None:
                if not dead:
                    starts = flat_spell_starts(t, value, flat_s)
                    free += [*_window_share(starts, float(t[0]), float(t[-1]), width, step_s),
                             *_step_events(tau, d, None, margin_s, step)[1:]]
                continue
            entry = groups.setdefault((flight.fault.fault_class, flight.emergency_trajectory),
                                      [])
            if dead:
                entry.append(None)
                continue
            starts = flat_spell_starts(t, value, flat_s)
            flat_at = bool(np.any((starts >= onset - before_s) & (starts <= onset + after_s)))
            entry.append((flat_at, *_window_share(starts, float(t[0]), onset - margin_s,
                                                  width, step_s),
                          *_step_events(tau, d, onset, margin_s, step)))
        flat_free = free[0] / free[1] if free[1] else math.nan
        step_free = free[2] / free[3] if free[3] else math.nan
        for (fault_class, emr) in sorted(groups, key=lambda g: (_ORDER.get(g[0], 99), g[1])):
            entries = groups[(fault_class, emr)]
            live = [e for e in entries if e is not None]
            n, k = len(live), sum(e[0] for e in live)
            windows = sum(e[2] for e in live)
            flat_before = sum(e[1] for e in live) / windows if windows else math.nan
            flat_p = _verdict_p(k, n, np.nanmax([flat_before, flat_free, 0.0]))
            tested = [e for e in live if e[3] is not None]
            m, j = len(tested), sum(e[3] for e in tested)
            instants = sum(e[5] for e in live)
            step_before = sum(e[4] for e in live) / instants if instants else math.nan
            step_p = _verdict_p(j, m, np.nanmax([step_before, step_free,
                                                 1 - step.step_quantile]))
            goes_flat = bool(n and k / n >= 0.5 and flat_p < alpha)
            steps = bool(m and step_p < alpha)
            rows.append({
                "signal": name, "kind": sig.kind, "fault_class": fault_class,
                "emergency_trajectory": emr, "flights": n, "not_measured": len(entries) - n,
                "flat_at_onset": k, "flat_share": k / n if n else math.nan,
                "flat_chance_before": flat_before, "flat_chance_fault_free": flat_free,
                "flat_p": flat_p, "goes_flat": goes_flat,
                "step_flights": m, "step_at_onset": j, "step_share": j / m if m else math.nan,
                "step_chance_before": step_before, "step_chance_fault_free": step_free,
                "step_p": step_p, "steps": steps,
                "leaks": goes_flat or (steps and sig.kind == "setpoint"),
            })
    return pd.DataFrame(rows, columns=LEAKAGE_COLUMNS)


def leaking_flights(table: pd.DataFrame, manifest: pd.DataFrame, flights: list[str]
                    ) -> dict[str, list[str]]:
    """The flights of ``flights`` whose group (fault class, emergency trajectory) has a
    sensor or setpoint leaking in ``table``, each with those signals: what an honest
    method could read the label from. Empty for a subset fit to rank on."""
    honest = table[table["leaks"] & (table["kind"] != "actuator")]
    bad = honest.groupby(["fault_class", "emergency_trajectory"])["signal"].apply(list)
    info = manifest.set_index("flight")
    out = {}
    for f in flights:
        key = (info.at[f, "fault_class"], bool(info.at[f, "emergency_trajectory"]))
        if key in bad.index:
            out[f] = bad[key]
    return out


def audit_note(table: pd.DataFrame, manifest: pd.DataFrame, subset: str,
               refused: pd.DataFrame | None = None) -> str:
    """One paragraph: whether the audit finds a sensor or setpoint carrying the label on
    a flight of ``subset`` (:func:`leaking_flights`), the headline's condition.
    ``refused``: the flights refused at load (``failures.csv`` rows, with ``subsets``),
    counted in the subset's size but not audited."""
    flights = subset_flights(manifest, subset)
    bad = leaking_flights(table, manifest, flights)
    gone = 0 if refused is None else len(in_subset(refused, subset))
    size = (f"{len(flights)} flights" if not gone else
            f"{len(flights) + gone} flights, {gone} refused at load and not audited")
    if not bad:
        return (f"The headline subset `{subset}` ({size}): the leakage audit "
                "(`results/tables/leakage.md`) finds no sensor or setpoint carrying the label "
                "on any of its flights.\n\n")
    signals = sorted({s for names in bad.values() for s in names})
    return (f"**WARNING: the headline subset `{subset}` is not clean.** On {len(bad)} of its "
            f"{len(flights)} audited flights ({size}; e.g. `{next(iter(bad))}`) the leakage "
            "audit finds "
            f"{', '.join(f'`{s}`' for s in signals)} carrying the label: set "
            "`primary_subset` to a subset without them.\n\n")


def _group(r) -> str:
    return f"{r['fault_class']}{' (emr)' if r['emergency_trajectory'] else ''}"


def _p(v) -> str:
    return "-" if math.isnan(v) else f"{v:.1e}"


def leakage_markdown(table: pd.DataFrame, flat_s: float = 1.0,
                     step: StepTest = StepTest()) -> str:
    """The verdict per signal (its kind, the groups it goes flat, steps and leaks on,
    the flights on which it is not measured), then the evidence per signal and group
    for each test. A group is a fault class, marked ``(emr)`` for the flights with an
    emergency trajectory. Without a flight with a fault (a corpus of fault-free logs)
    there is no onset to audit, and it says so."""
    if table.empty:
        return ("## Which signals carry the label\n\nNo flight has a fault: there is no "
                "onset at which a signal could carry the label, so nothing is audited.\n")
    verdict = []
    for signal, g in table.groupby("signal", sort=False):
        kind = g["kind"].iloc[0]
        on = {c: ", ".join(_group(r) for r in g[g[c]].to_dict(orient="records")) or "none"
              for c in ("goes_flat", "steps", "leaks")}
        flat = g["goes_flat"].any()
        agrees = ("NO: it goes flat, so it must not be read as a sensor or setpoint"
                  if flat and kind != "actuator" else
                  "yes" if flat or (kind == "actuator" and g["leaks"].any()) else
                  "not shown: no leak on these flights" if kind == "actuator" else
                  "yes; its flights leave the primary subset" if g["leaks"].any() else "yes")
        verdict.append([f"`{signal}`", kind, on["goes_flat"], on["steps"], on["leaks"], agrees,
                        f"{int(g['not_measured'].sum())} of "
                        f"{int(g['not_measured'].sum() + g['flights'].sum())}"])
    flat_rows, step_rows = [], []
    for r in table.to_dict(orient="records"):
        flat_rows.append([f"`{r['signal']}`", _group(r), f"{r['flat_at_onset']} of {r['flights']}",
                          fmt(r["flat_share"], True, 0), fmt(r["flat_chance_before"], True, 1),
                          fmt(r["flat_chance_fault_free"], True, 1), _p(r["flat_p"]),
                          "**goes flat**" if r["goes_flat"] else ""])
        mark = ("**leaks**" if r["steps"] and r["kind"] == "setpoint" else
                "steps (the aircraft's response)" if r["steps"] and r["kind"] == "sensor" else
                "steps (the inner loop's response, or the emulation)" if r["steps"] else "")
        step_rows.append([f"`{r['signal']}`", _group(r),
                          f"{r['step_at_onset']} of {r['step_flights']}",
                          fmt(r["step_share"], True, 0), fmt(r["step_chance_before"], True, 1),
                          fmt(r["step_chance_fault_free"], True, 1), _p(r["step_p"]), mark])
    w, q = f"{step.step_window_s:g}", f"{100 * step.step_quantile:g}"
    return markdown([
        ("Which signals carry the label", ["signal", "kind (declared)", "goes flat on",
                                           "steps on", "leaks on", "data agrees with kind",
                                           "fault flights not measured (constant)"], verdict),
        (f"Goes flat (unchanged ≥ {flat_s:g} s) at onset, against chance",
         ["signal", "fault", "flat at onset", "share %", "chance before onset %",
          "chance fault-free %", "p (binomial)", ""], flat_rows),
        (f"Steps at onset (moves over {w} s after from the mean of {w} s before, above "
         f"{q} % of the {step.reference_s:g} s before; a setpoint's command), against chance",
         ["signal", "fault", "steps at onset", "share %", "chance before onset %",
          "chance fault-free %", "p (binomial)", ""], step_rows),
    ])
