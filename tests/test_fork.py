"""Forked runs (methods/base.py): a run continued from a snapshot equals the run from
t = 0, a flight that does not share the fork's steps runs from t = 0, a detector
that cannot continue is never forked, and a state taken under another fit or other
hyper-parameters is refused, never restored. (Every registered run is checked by the
contract's check_forked_run_equals_run.)"""

import dataclasses

import numpy as np
import pytest

from alfa_bench.data import sample
from alfa_bench.data.inject import inject_flight
from alfa_bench.methods import (
    Detector,
    StaleStateError,
    fault_free_segments,
    forks,
    make_detector,
    run_detector,
)


class RunningMean(Detector):
    """The running mean of one signal: a detector that steps update() only, so the
    base class's snapshot (a copy of its attributes) forks it."""

    rate_hz = 25.0

    def __init__(self, signal="roll"):
        self.signal = signal

    def signals(self):
        return (self.signal,)

    def channels(self):
        return ("mean",)

    def channel_outputs(self):
        return (self.signal,)

    def thresholds(self):
        return np.array([5.0])

    def reset(self):
        self.total_, self.steps_ = 0.0, 0
        return self

    def update(self, x, fresh):
        self.total_ += float(x[0])
        self.steps_ += 1
        return np.array([self.total_ / self.steps_])


class BatchOnly(RunningMean):
    """A plugin with its own batch run() that says nothing of continuing."""

    def run(self, s, probes=False, start=0, state=None):
        self.reset()
        return np.cumsum(s.x[:, :1], axis=0) / np.arange(1, s.t.size + 1)[:, None], {}


def _engine(corpus_flights):
    return corpus_flights["carbonZ_2018-07-18-15-53-31_1_engine_failure"]


def test_the_update_loop_forks_through_the_base_snapshot(corpus_flights, tmp_path):
    flight = next(f for n, f in corpus_flights.items() if "no_failure" in n)
    det = RunningMean()
    onset = 0.5 * flight.duration_s
    fork = forks(det, flight, [0.25 * flight.duration_s, onset])[onset]
    injected = inject_flight(flight, tmp_path, "roll", "drift", 0.5, onset)
    forked = run_detector(det, injected, fork=fork)
    whole = run_detector(det, injected)
    np.testing.assert_array_equal(forked.score, whole.score)
    # the fork ran the steps before the onset: its state is there, not at t = 0
    assert fork.state.attributes["steps_"] == fork.sampled.t.size > 0


def test_a_flight_that_does_not_share_the_steps_runs_from_the_start(corpus_flights):
    flight = _engine(corpus_flights)
    det = make_detector("rls_arx_zscore")
    fork = forks(det, flight, [0.5 * flight.duration_s])[0.5 * flight.duration_s]
    s = sample(flight, det.signals(), det.rate_hz)
    assert fork.shared_by(s, probes=False)
    assert not fork.shared_by(s, probes=True)          # the fork kept no probes
    x = s.x.copy()
    x[3, 0] += 1.0
    assert not fork.shared_by(dataclasses.replace(s, x=x), probes=False)
    # a fork from another flight's start is not shared, so the run starts afresh
    other = next(f for n, f in corpus_flights.items() if "no_failure" in n)
    np.testing.assert_array_equal(run_detector(det, other, fork=fork).score,
                                  run_detector(det, other).score)


def test_a_detector_that_cannot_continue_is_not_forked(corpus_flights):
    flight = _engine(corpus_flights)
    det = BatchOnly()
    assert det.snapshot() is None
    assert forks(det, flight, [0.5 * flight.duration_s]) == {}


def test_a_state_taken_under_other_parameters_is_refused(corpus_flights):
    flight = _engine(corpus_flights)
    det = RunningMean()
    s = sample(flight, det.signals(), det.rate_hz)
    det.run(s.before(0.5 * flight.duration_s))
    state, k = det.snapshot(), s.before(0.5 * flight.duration_s).t.size
    det.run(s, start=k, state=state)                 # the same detector continues
    det.signal = "pitch"
    with pytest.raises(StaleStateError, match="another fit or other parameters"):
        det.run(s, start=k, state=state)


def test_a_fork_taken_before_a_rethreshold_is_refused(corpus_flights):
    flight = _engine(corpus_flights)
    det = make_detector("residual_bank")
    det.fit(fault_free_segments(det, [f for n, f in corpus_flights.items() if n != flight.id],
                                margin_s=1.0))
    fork = forks(det, flight, [0.5 * flight.duration_s])[0.5 * flight.duration_s]
    run_detector(det, flight, fork=fork)
    det.false_alarm = 0.05
    det.rethreshold()
    with pytest.raises(StaleStateError, match="fork again"):
        run_detector(det, flight, fork=fork)
