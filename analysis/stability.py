r"""How much each outcome owes to the flights that calibrated it: resampled pools.

About an hour of fault-free flight calibrates every threshold, and a threshold set
from it moves when flights are added. For each fold :math:`k`, :math:`B` pools are
drawn (:func:`pool_draws`): the fold's calibration flights drawn with replacement, as
many as there are (a bootstrap), seeded by the fold's name, so that every run sees the
same pools and the scored date is never among them. A run whose thresholds come from
the pool alone (:meth:`~alfa_bench.methods.Detector.pool_thresholds`: per-flight
maxima, :class:`~alfa_bench.methods.MaximaThresholds`) gets each pool's thresholds,
and each flight its first alarm under them, from its stored scores
(:func:`pool_first_alarms`): the model the pool would also have moved is kept, so the
spread is that of the thresholds alone. A run whose thresholds come with a fitted
model gets none (``stability`` is None in its records).

A flight's *survival* is the share of pools under which its outcome, under the
deadline, is the one reported (:func:`survival`); a detection with survival of at
least ``stable`` (0.9) is *stable*. :func:`stability_table` gives per run and subset
the reported in-time detections and fault-free alarms beside their mean and interval
over the pools; :func:`calibration_table` what each fold was calibrated on: its
flights, their hours of fault-free flight, and the smallest per-flight false-alarm
level that many flights can check (one in as many as there are).

Whether the thresholds alone are the spread: :func:`refit_first_alarms` fits the model
again on the first pools too, and :func:`refit_table` puts both side by side
(``snakemake stability_refit``, not part of ``all``: a fit per pool and fold).
"""

from __future__ import annotations

import hashlib
import logging
import math

import numpy as np
import pandas as pd

from alfa_bench.data import subset_flights
from alfa_bench.methods import Trace

from .scoring import flight_outcome, rates

__all__ = ["calibration_table", "pool_counts", "pool_draws", "pool_first_alarms",
           "pool_outcomes", "pool_summaries", "refit_first_alarms", "refit_table",
           "stability_table", "survival"]

log = logging.getLogger(__name__)


def pool_draws(flights: list[str], pools: int, seed: int, fold: str) -> list[dict[str, int]]:
    """``pools`` bootstrap draws of ``flights`` (each: flight -> times drawn, as many
    draws as flights), the same for a fold whatever the run."""
    key = int.from_bytes(hashlib.blake2b(fold.encode(), digest_size=8).digest(), "big")
    rng = np.random.default_rng([seed, key])
    counts = rng.multinomial(len(flights), np.full(len(flights), 1 / len(flights)),
                             size=pools)
    return [{f: int(n) for f, n in zip(flights, row, strict=True) if n} for row in counts]


def pool_first_alarms(trace: Trace, thresholds: np.ndarray) -> list[float | None]:
    """Per pool, the first alarm of ``trace``'s scores under that pool's ``thresholds``
    (pools, channels); a channel whose pool threshold is NaN (too few maxima) never
    alarms."""
    score = np.where(np.isfinite(trace.score), trace.score, -np.inf)
    running = np.maximum.accumulate(score, axis=0)              # nondecreasing per channel
    n = trace.t.size
    first = np.full(thresholds.shape[0], n)
    for c in range(score.shape[1]):
        limit = np.where(np.isfinite(thresholds[:, c]), thresholds[:, c], np.inf)
        first = np.minimum(first, np.searchsorted(running[:, c], limit, side="right"))
    return [float(trace.t[k]) if k < n else None for k in first]


def pool_outcomes(record: dict, deadline_s: float) -> list[str] | None:
    """The record's outcome under each pool (None where it has no pools)."""
    pools = record.get("stability")
    if not pools:
        return None
    return [flight_outcome(record["onset_s"], first, deadline_s)
            for first in pools["first_alarm_s"]]


def survival(record: dict, deadline_s: float) -> float:
    """The share of pools under which the record's outcome under ``deadline_s`` is the
    one reported; NaN where it has no pools."""
    outcomes = pool_outcomes(record, deadline_s)
    if outcomes is None:
        return math.nan
    reported = flight_outcome(record["onset_s"], record["first_alarm_s"], deadline_s)
    return sum(o == reported for o in outcomes) / len(outcomes)


def pool_counts(recs: list[dict], deadline_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Per pool, the in-time detections and the fault-free flights alarmed among
    ``recs`` (each with pools)."""
    table = [pool_outcomes(r, deadline_s) for r in recs]
    pools = len(table[0])
    tp = np.array([sum(o[b] == "TP" for o in table) for b in range(pools)])
    fa = np.array([sum(o[b] == "FP" for r, o in zip(recs, table, strict=True)
                       if r["onset_s"] is None) for b in range(pools)])
    return tp, fa


def pool_summaries(recs: list[dict], deadline_s: float, pools: int) -> list[dict]:
    """Per pool, the :func:`~.scoring.rates` of ``recs`` under that pool's first alarms
    (the reported ones for every pool where the run has no pools): what the comparison
    ranks a run by, pool by pool."""
    out = []
    for b in range(pools):
        firsts = [r["stability"]["first_alarm_s"][b] if r.get("stability")
                  else r["first_alarm_s"] for r in recs]
        outcomes = [flight_outcome(r["onset_s"], f, deadline_s)
                    for r, f in zip(recs, firsts, strict=True)]
        out.append(rates(outcomes, [f - r["onset_s"] if o == "TP" else None
                                    for r, f, o in zip(recs, firsts, outcomes, strict=True)]))
    return out


def stability_table(records: list[dict], manifest: pd.DataFrame, subsets, deadline_s: float,
                    stable: float = 0.9, level: float = 0.9) -> pd.DataFrame:
    """Per run and subset: the reported in-time detections and fault-free alarms, their
    mean and central ``level`` interval over the pools, the stable detections (survival
    at least ``stable``), and the pools drawn (0 where its thresholds need a refit, or
    it is not calibrated)."""
    rows = []
    lo, hi = (1 - level) / 2, (1 + level) / 2
    for subset in subsets:
        member = set(subset_flights(manifest, subset))
        by_method: dict[str, list[dict]] = {}
        for r in records:
            if r["flight"] in member:
                by_method.setdefault(r["method"], []).append(r)
        for method, recs in by_method.items():
            outcomes = [flight_outcome(r["onset_s"], r["first_alarm_s"], deadline_s)
                        for r in recs]
            row = {"method": method, "subset": subset, "deadline_s": deadline_s,
                   "detections": outcomes.count("TP"),
                   "fault_free_alarms": sum(o == "FP" for r, o in zip(recs, outcomes,
                                                                      strict=True)
                                            if r["onset_s"] is None),
                   "fault_free_flights": sum(r["onset_s"] is None for r in recs)}
            if all(r.get("stability") for r in recs):
                tp, fa = pool_counts(recs, deadline_s)
                row |= {"detections_mean": float(tp.mean()),
                        "detections_low": float(np.quantile(tp, lo)),
                        "detections_high": float(np.quantile(tp, hi)),
                        "stable_detections": sum(
                            o == "TP" and survival(r, deadline_s) >= stable
                            for r, o in zip(recs, outcomes, strict=True)),
                        "fault_free_alarms_mean": float(fa.mean()),
                        "fault_free_alarms_low": float(np.quantile(fa, lo)),
                        "fault_free_alarms_high": float(np.quantile(fa, hi)),
                        "pools": len(tp)}
            else:
                row |= {k: math.nan for k in (
                    "detections_mean", "detections_low", "detections_high",
                    "stable_detections", "fault_free_alarms_mean", "fault_free_alarms_low",
                    "fault_free_alarms_high")} | {"pools": 0}
            rows.append(row)
    return pd.DataFrame(rows, columns=_STABILITY_COLUMNS)


_STABILITY_COLUMNS = ["method", "subset", "deadline_s", "detections", "fault_free_alarms",
                      "fault_free_flights", "detections_mean", "detections_low",
                      "detections_high", "stable_detections", "fault_free_alarms_mean",
                      "fault_free_alarms_low", "fault_free_alarms_high", "pools"]


def calibration_table(records: list[dict]) -> pd.DataFrame:
    """Per fold, from the records of the calibrated runs: its calibration flights (the
    most any run used), their hours of fault-free flight, and the smallest per-flight
    false-alarm level that many flights can check."""
    folds: dict[str, dict] = {}
    for r in records:
        cal = r.get("calibration")
        if not cal or "fault_free_hours" not in cal:
            continue
        best = folds.get(cal["fold"])
        if best is None or len(cal["flights"]) > best["flights"]:
            folds[cal["fold"]] = {"fold": cal["fold"], "flights": len(cal["flights"]),
                                  "fault_free_hours": cal["fault_free_hours"],
                                  "smallest_level": 1 / len(cal["flights"])}
    return pd.DataFrame(sorted(folds.values(), key=lambda f: f["fold"]),
                        columns=["fold", "flights", "fault_free_hours", "smallest_level"])


def refit_first_alarms(spec: dict, flights, manifest: pd.DataFrame, calibration: dict,
                       settings: dict, refits: int) -> dict[str, list[float | None]]:
    """Per labelled flight of ``manifest``, its first alarm under each of the first
    ``refits`` pools of its fold (:func:`pool_draws`, as the detect job draws them),
    the detector of ``spec`` fitted again on each pool (a flight drawn twice calibrates
    twice): what the pool moves, the model included. None where the pool cannot
    calibrate it (logged), or it alarms nowhere."""
    from alfa_bench.methods import (
        CalibrationError,
        make_detector,
        run_detector,
        training_segments,
    )

    from .held_out import check_held_out, folds, group_labels, own_calibration

    calibration = own_calibration(calibration, spec)
    group = dict(zip(manifest["flight"], group_labels(manifest, calibration["group_by"]),
                     strict=True))
    out: dict[str, list[float | None]] = {}
    segments: dict[str, list] = {}
    for fold, (scored, training) in folds(manifest, calibration["group_by"]).items():
        draws = pool_draws(training, settings["pools"], settings["seed"], fold)[:refits]
        out |= {f: [] for f in scored}
        for draw in draws:
            detector = make_detector(spec["detector"], spec.get("params"))
            for f in draw:
                if f not in segments:
                    segments[f] = training_segments(detector, [flights[f]],
                                                    calibration["margin_s"])
            data = [s for f, n in draw.items() for _ in range(n) for s in segments[f]]
            check_held_out(data, fold, scored, group)
            try:
                # a pool of a few flights drawn many times can have no spread to fit
                with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                    detector.fit(data)
            except CalibrationError as e:
                log.warning("fold %s: a pool cannot calibrate %s: %s", fold,
                            spec["detector"], e)
                detector = None
            for f in scored:
                out[f].append(None if detector is None else
                              run_detector(detector, flights[f]).first_alarm_s())
    return out


def refit_table(records: list[dict], refitted: dict[str, dict[str, list]],
                manifest: pd.DataFrame, subsets, deadline_s: float) -> pd.DataFrame:
    """Per run of ``refitted`` (run -> :func:`refit_first_alarms`) and subset: over the
    same pools, the in-time detections when only the thresholds move (the records'
    ``stability``) and when the model is fitted again, their spread, and the share of
    (flight, pool) outcomes the two agree on."""
    rows = []
    for method, firsts in refitted.items():
        recs = {r["flight"]: r for r in records if r["method"] == method}
        refits = len(next(iter(firsts.values())))
        for subset in subsets:
            member = [f for f in subset_flights(manifest, subset) if f in recs]
            cheap = np.zeros(refits)
            full = np.zeros(refits)
            agree = 0
            for f in member:
                r = recs[f]
                for b in range(refits):
                    a = flight_outcome(r["onset_s"], r["stability"]["first_alarm_s"][b],
                                       deadline_s)
                    c = flight_outcome(r["onset_s"], firsts[f][b], deadline_s)
                    cheap[b] += a == "TP"
                    full[b] += c == "TP"
                    agree += a == c
            rows.append({"method": method, "subset": subset, "deadline_s": deadline_s,
                         "pools": refits, "thresholds_mean": cheap.mean(),
                         "thresholds_min": cheap.min(), "thresholds_max": cheap.max(),
                         "thresholds_sd": cheap.std(), "refit_mean": full.mean(),
                         "refit_min": full.min(), "refit_max": full.max(),
                         "refit_sd": full.std(),
                         "outcomes_agree": agree / (len(member) * refits)})
    return pd.DataFrame(rows)
