"""Run a configured method over flights and describe each result as a record.

The record is what ``results/detections/{method}/{flight}.json`` holds. A calibrated
method is fitted once per fold of :func:`~.held_out.folds`, on the fault-free data
of the other folds' flights only, and each record names those flights.

A flight the method cannot read (a topic it needs is missing, a gap in its rows)
is either the end of the run (strict) or a failure row: the flight then gives
neither a record nor calibration data, and the failure is logged. So is a fold the
method cannot calibrate (too little fault-free data for its threshold, a single date
to leave out): each flight of the fold gets a failure row at stage ``calibration``
saying why and what to change, and the other folds, and every other method, are
still scored.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from alfa_bench.data import (
    SIGNALS,
    AlfaDataError,
    Flight,
    failure_row,
    not_measured,
    reads_actuators,
)
from alfa_bench.methods import (
    CalibrationError,
    Detector,
    Fork,
    Trace,
    clone,
    continue_forks,
    fault_free_segments,
    fork_for,
    forks,
    labelled_segments,
    make_detector,
    run_detector,
)

from .held_out import (
    TooFewGroupsError,
    check_held_out,
    folds,
    group_labels,
    groups_of,
    own_calibration,
)
from .isolation import isolate
from .provenance import provenance
from .scoring import flight_outcome
from .stability import pool_draws, pool_first_alarms

__all__ = ["calibration_failure", "detect_all", "detection_record"]

log = logging.getLogger(__name__)



def detect_all(method: str, spec: dict, flights: Mapping[str, Flight], manifest: pd.DataFrame,
               calibration: dict, failures: list[dict] | None = None,
               calibrate_on: pd.DataFrame | None = None, detector: Detector | None = None,
               stability: dict | None = None, fitted: dict | None = None
               ) -> Iterator[tuple[dict, Trace]]:
    """Records and traces (with probes) of ``spec`` (``{"detector": name, "params":
    {...}}``) on every flight of ``manifest`` with ground truth; ``calibration`` is
    ``{"group_by", "margin_s"}``. The detector run is a clone of ``detector`` if given
    (unfitted; ``spec`` then names it in the records; it is left as it was), else the
    registry's ``spec``. Each fold fits a clone of its own; with ``fitted`` (a dict),
    each fold's fitted detector is put there by fold name (``""`` for an uncalibrated
    detector's one run).

    With ``stability`` (``{"pools", "seed"}``), each fold also draws that many pools of
    its calibration flights (:func:`~.stability.pool_draws`), and each real flight's
    record holds its first alarm under each pool's thresholds, where the detector can
    set them without fitting again (``stability``; :mod:`.stability`).

    A calibrated method is fitted per fold on the other groups' flights of
    ``calibrate_on`` (default ``manifest``): injected flights are scored by the
    model of their source's group, fitted on real flights only. A supervised one gets
    those flights whole, with their labels. Before each fit, no segment may come from
    the group scored (:func:`~.held_out.check_held_out`, which stops the run).

    With ``failures`` None, a flight that cannot be read raises its
    :class:`~alfa_bench.data.AlfaDataError`; with a list, the flight is skipped and a
    :func:`~alfa_bench.data.failure_row` appended, once per flight.
    """
    if detector is None:
        detector = make_detector(spec["detector"], spec.get("params"))
    calibration = own_calibration(calibration, spec)
    train = manifest if calibrate_on is None else calibrate_on
    sha = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
    sha |= dict(zip(train["flight"], train["sha256"], strict=True))
    runner = _FoldRunner(method, spec, clone(detector), flights, sha, calibration, failures,
                         _sources(manifest), stability, _fault_free_s(train, calibration))
    if fitted is not None:
        runner.fitted = fitted
    if not detector.calibrated:
        runner.fitted[""] = runner.detector
        runner.scored = manifest.loc[manifest["ground_truth"], "flight"].tolist()
        for name in runner.scored:
            if (out := runner.record(name)) is not None:
                yield out
        return
    scored = manifest.loc[manifest["ground_truth"]]
    groups = scored.groupby(groups_of(scored, train, calibration["group_by"]))["flight"]
    scored_by_fold = {g: list(f) for g, f in groups}
    try:
        by_fold = folds(train, calibration["group_by"])
    except TooFewGroupsError as e:
        runner.uncalibrated([f for names in scored_by_fold.values() for f in names], e)
        return
    group = dict(zip(train["flight"], group_labels(train, calibration["group_by"]),
                     strict=True))
    for fold, (_, training) in by_fold.items():
        scored = scored_by_fold.pop(fold, [])
        if not scored:
            continue
        info = runner.fit(fold, training, scored, group)
        if info is None:
            continue
        for name in scored:
            if (out := runner.record(name, info)) is not None:
                yield out
    if scored_by_fold:
        runner.uncalibrated([f for names in scored_by_fold.values() for f in names],
                            CalibrationError(f"no calibration flights outside group(s) "
                                             f"{sorted(scored_by_fold)}"))


def _fault_free_s(manifest: pd.DataFrame, calibration: dict) -> dict[str, float]:
    """Per flight, its seconds of fault-free flight as calibration takes them: all of a
    fault-free flight, a faulty one's up to ``margin_s`` before onset."""
    pre = manifest["pre_fault_s"].fillna(manifest["flight_s"]) - calibration["margin_s"]
    free = manifest["fault_class"] == "none"
    seconds = manifest["flight_s"].where(free, pre.clip(lower=0.0))
    return dict(zip(manifest["flight"], seconds.astype(float), strict=True))


def _sources(manifest: pd.DataFrame) -> dict[str, tuple[str, list[float]]]:
    """Per injected flight of ``manifest`` (``fault_source`` set), its source flight
    and the onsets of every flight injected into that source: where runs fork."""
    if "fault_source" not in manifest:
        return {}
    injected = manifest[manifest["fault_source"].fillna("").astype(str) != ""]
    onsets = injected.groupby("fault_source")["onset_s"].agg(lambda v: sorted(set(v)))
    return {f: (s, onsets[s]) for f, s in zip(injected["flight"], injected["fault_source"],
                                               strict=True)}


class _FoldRunner:
    """One method's run over flights, fold by fold: it fits the detector per fold,
    forks it and runs it; each flight's record is made once; a flight's bad
    data turned into a failure row (or raised, with ``failures`` None), after which the
    flight is neither scored nor calibrates; and a fold it cannot calibrate turned into
    failure rows for the flights that fold scores.

    An injected flight is its source up to its onset, so the fitted detector is run
    over each source once per fold, up to every onset injected into it
    (:func:`~alfa_bench.methods.forks`), and each injected flight continues from the
    fork at its onset: the fold's flights injected into one source all in one call
    (:func:`~alfa_bench.methods.continue_forks`)."""

    def __init__(self, method: str, spec: dict, detector: Detector,
                 flights: Mapping[str, Flight], sha: dict, calibration: dict,
                 failures: list[dict] | None, sources: dict[str, tuple[str, list[float]]],
                 stability: dict | None = None, fault_free_s: dict[str, float] | None = None):
        self.method, self.spec, self.detector = method, spec, detector
        self.flights, self.sha, self.calibration = flights, sha, calibration
        self.failures, self.sources = failures, sources
        self.stability, self.fault_free_s = stability, fault_free_s or {}
        self.failed: set[str] = set()
        # each fold's fitted clone of ``detector``, by fold
        self.fitted: dict[str, Detector] = {}
        self.forks: dict[str, dict[float, Fork]] = {}
        # the flights the current fold scores, and the scores continued from a source's
        # forks for those injected into it (continue_forks) and those flights, built
        # once for both (an injected flight is built when looked up), until recorded
        self.scored: list[str] = []
        self.continued: dict = {}
        self.built: dict[str, Flight] = {}
        # the fold's pool thresholds (pools, channels), or None
        self.pools: np.ndarray | None = None

    def guarded(self, stage: str, name: str, fn):
        """``fn()``, or None once flight ``name`` has bad data (at ``stage``)."""
        if name in self.failed:
            return None
        try:
            return fn()
        except AlfaDataError as e:
            if self.failures is None:
                raise
            self.failed.add(name)
            self.failures.append(failure_row(e, stage, self.method))
            log.error("%s: flight %s excluded at %s: %s", self.method, name, stage, e)
            return None

    def record(self, name: str, info: dict | None = None) -> tuple[dict, Trace] | None:
        if name not in self.sources:
            return self.guarded("detect", name, lambda: detection_record(
                self.method, self.spec, self.detector, self.flights[name], self.sha, info,
                pools=self.pools))
        source, onsets = self.sources[name]
        if source not in self.forks:
            self.forks[source] = self.guarded("detect", source, lambda: forks(
                self.detector, self.flights[source], onsets)) or {}
            # the fold's flights injected into this source, scored in one call
            injected = [n for n in self.scored if self.sources.get(n, ("",))[0] == source]
            self.built = {n: f for n in injected
                          if (f := self.guarded("detect", n, lambda n=n: self.flights[n]))
                          is not None}
            self.continued = continue_forks(self.detector, list(self.built.values()),
                                            self.forks[source])
        built = self.built.pop(name, None)
        return self.guarded("detect", name, lambda: detection_record(
            self.method, self.spec, self.detector,
            self.flights[name] if built is None else built, self.sha, info,
            forked=self.forks[source], continued=self.continued.pop(name, None)))

    def uncalibrated(self, names: list[str], error: CalibrationError) -> None:
        if self.failures is None:
            raise error
        # not added to ``failed``: the flights are still fault-free data for other folds
        self.failures.extend(calibration_failure(name, self.method, error, self.calibration)
                             for name in names)
        log.error("%s: %d flight(s) excluded, not calibrated: %s", self.method, len(names),
                  error)

    def fit(self, fold: str, training: list[str], scored: list[str],
            group: dict[str, str]) -> dict | None:
        """Fit a clone of the detector on the readable, measured ``training`` flights of
        ``fold``; the calibration block of its records, or None if it could not be
        fitted."""
        detector = self.detector = clone(self.detector)
        margin_s = self.calibration["margin_s"]
        segments = {f: self.guarded("calibration", f, lambda f=f: (
            labelled_segments(detector, [self.flights[f]]) if detector.supervised else
            fault_free_segments(detector, [self.flights[f]], margin_s)))
            for f in training}
        readable = [f for f in training if segments[f] is not None]
        dead = {f: list(d) for f in readable
                if (d := not_measured(self.flights[f], detector.signals()))}
        used = [f for f in readable if f not in dead]
        data = [s for f in used for s in segments[f]]
        check_held_out(data, fold, scored, group)
        self.forks = {}                # run by the previous fold's fit
        self.scored, self.continued, self.built = scored, {}, {}
        self.pools = None
        try:
            detector.fit(data)
            _check_thresholds(detector)
        except CalibrationError as e:
            self.uncalibrated(scored, CalibrationError(
                f"fold {fold} ({len(used)} calibration flights): {e}"))
            return None
        log.info("%s: fold %s fitted on %d flights", self.method, fold, len(used))
        self.fitted[fold] = detector
        if self.stability:
            self.pools = self._pool_thresholds(fold, training, used, scored, group)
        return {**self.calibration, "fold": fold, "flights": used, "not_measured": dead,
                "fault_free_hours": sum(self.fault_free_s[f] for f in used) / 3600.0,
                "supervised": detector.supervised,
                # what reached fit, flight by flight: the spans of its segments, s
                "segments": {f: [[float(x.t[0]), float(x.t[-1])] for x in segments[f]]
                             for f in used},
                "fitted": detector.fitted()}

    def _pool_thresholds(self, fold: str, training: list[str], used: list[str],
                         scored: list[str], group: dict[str, str]) -> np.ndarray | None:
        """The fitted detector's thresholds under each pool of the fold's calibration
        flights (:func:`~.stability.pool_draws`), those it used counted; None where
        it cannot set them without a refit."""
        draws = pool_draws(training, self.stability["pools"], self.stability["seed"], fold)
        check_held_out([_Drawn(f) for d in draws for f in d], fold, scored, group)
        kept = set(used)
        return self.detector.pool_thresholds(
            [{f: n for f, n in d.items() if f in kept} for d in draws])


def _check_thresholds(detector: Detector) -> None:
    """A fitted detector's thresholds are finite and positive, or it is not calibrated."""
    gamma = np.asarray(detector.thresholds(), dtype=float)
    if not np.all(np.isfinite(gamma) & (gamma > 0)):
        bad = {c: float(g) for c, g in zip(detector.channels(), gamma, strict=True)
               if not (np.isfinite(g) and g > 0)}
        raise CalibrationError(f"{type(detector).__name__} fitted thresholds that are not "
                               f"finite and positive: {bad}")


@dataclass(frozen=True)
class _Drawn:
    """A flight drawn into a pool, as :func:`~.held_out.check_held_out` reads it."""

    flight: str


def calibration_failure(flight: str, method: str, error: CalibrationError,
                        calibration: dict) -> dict:
    """A failures-table row for ``flight``, which ``method`` could not be calibrated to
    score: why, and what to change."""
    advice = ("add fault-free flights (or flights with more time before onset) from other "
              "groups")
    if calibration["group_by"] != "flight":
        advice += (", or set calibration.group_by: flight on the run, with role: "
                   "reference, to leave out one flight, not one day (flights of the scored "
                   "date then train it, so it is not ranked)")
    return {"flight": flight, "stage": "calibration", "method": method, "file": "",
            "column": "", "line": "", "error": f"{error}; to calibrate, {advice}"}


def detection_record(method: str, spec: dict, detector: Detector, flight: Flight,
                     sha256: dict[str, str], calibration: dict | None = None,
                     forked: dict[float, Fork] | None = None,
                     continued: tuple | None = None,
                     pools: np.ndarray | None = None) -> tuple[dict, Trace]:
    """Run ``detector`` (fitted if calibrated) on ``flight``: its record and trace.
    ``sha256`` maps flights to their checksums; the record's provenance gives those of
    ``flight`` and of the flights that calibrated the detector.

    With ``forked`` (an injected flight: :func:`~alfa_bench.methods.forks` of its
    source, by time), the run continues from the latest fork at or before the onset,
    and keeps no probes (an injected flight has no trace written); with ``continued``
    (:func:`~alfa_bench.methods.continue_forks` of the flight), its scores are those.

    With ``pools`` (thresholds per calibration pool and channel), the record's
    ``stability`` holds the first alarm under each (:func:`~.stability.
    pool_first_alarms`); None without."""
    if flight.fault is None:
        raise ValueError(f"flight {flight.id} has no ground truth and cannot be scored")
    onset = flight.fault.onset_s
    if forked is None:
        trace = run_detector(detector, flight, probes=True)
    else:
        trace = run_detector(detector, flight, fork=fork_for(forked, onset),
                             continued=continued)
    first = trace.first_alarm_s()
    outputs = dict(zip(trace.channels, detector.channel_outputs(), strict=True))
    outcome = flight_outcome(onset, first)
    return {
        "flight": flight.id,
        "method": method,
        "detector": spec["detector"],
        # a detector of a script or notebook: which code scored (methods.source_digest)
        **({"detector_source": spec["source"]} if "source" in spec else {}),
        "role": spec.get("role", "method"),
        # what the detector declares: one that is not causal is a reference row (blocks)
        "causal": bool(detector.causal),
        "family": detector.family,
        # whether it reads what the fault emulation writes: from its signals, never set
        "reads_actuators": reads_actuators(detector.signals()),
        "signal_kinds": {n: SIGNALS[n].kind for n in detector.signals()},
        "parameters": detector.get_params(),
        "fault_class": flight.fault.fault_class,
        "fault_sensor": flight.fault.sensor,
        "onset_s": onset,
        "fault_end_s": flight.fault.end_s,
        "first_alarm_s": first,
        # by the paper's rule (no deadline); the tables score deadlines from first_alarm_s
        "detection_s": first - onset if outcome == "TP" else None,
        "outcome": outcome,
        "alarm_intervals": trace.alarm_intervals(),
        "pair_first_alarm_s": {ch: trace.first_alarm_s(i)
                               for i, ch in enumerate(trace.channels)},
        "pair_armed_s": {ch: trace.armed_s(i) for i, ch in enumerate(trace.channels)},
        "skipped_channels": trace.skipped,
        "channel_outputs": outputs,
        # the sensor the first alarm from the onset points at (isolation.py), or "missed"
        "isolated_sensor": None if onset is None else isolate(trace, onset, outputs),
        "grid": {"rate_hz": detector.rate_hz, "samples": int(trace.t.size),
                 "start_s": float(trace.t[0]), "stop_s": float(trace.t[-1])},
        "repairs": list(flight.repairs),
        "calibration": calibration,
        "stability": None if pools is None else {
            "pools": int(pools.shape[0]), "first_alarm_s": pool_first_alarms(trace, pools)},
        "provenance": provenance(spec, {
            "flight_sha256": sha256[flight.id],
            "calibration_sha256": ({f: sha256[f] for f in calibration["flights"]}
                                   if calibration else {})}),
    }, trace
