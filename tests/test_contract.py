"""The streaming contract, checked for every registered detector and configured run.

A new method is picked up here by its registry line alone. Calibrated detectors are
fitted first, on the fault-free flights of the synthetic corpus.
"""

import copy
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from alfa_bench.data import SIGNALS, load_flight, sample
from alfa_bench.methods import (
    REGISTRY,
    Detector,
    NotFittedError,
    fault_free_segments,
    make_detector,
    run_detector,
)

CONFIG = yaml.safe_load((Path(__file__).parent.parent / "config/config.yaml").read_text())
RUNS = {name: (spec["detector"], spec.get("params", {})) for name, spec in
        CONFIG["methods"].items()}
CASES = {**{f"registry:{n}": (n, {}) for n in REGISTRY}, **{f"config:{n}": r for n, r in
                                                           RUNS.items()}}


@pytest.fixture(params=sorted(CASES))
def unfitted(request):
    name, params = CASES[request.param]
    return make_detector(name, params)


def fit(detector, corpus):
    """``detector`` fitted on the corpus's fault-free data (no-op if uncalibrated)."""
    training = [load_flight(p) for p in sorted(corpus.iterdir())]
    return detector.fit(fault_free_segments(detector, training, margin_s=1.0))


_FITTED = {}


@pytest.fixture
def detector(request, unfitted, corpus):
    """A fitted detector that has never run (fitting is cached across tests)."""
    key = request.node.callspec.params["unfitted"]
    if key not in _FITTED:
        _FITTED[key] = fit(unfitted, corpus)
    return copy.deepcopy(_FITTED[key])


def causal_or_reference(detector) -> bool:
    """True for a causal detector. A non-causal one (it knows the future, like the
    end-of-flight reference) must be a reference row in every configured run."""
    if detector.causal:
        return True
    runs = [n for n, (d, _) in RUNS.items() if REGISTRY[d] is type(detector)]
    assert all(CONFIG["methods"][n].get("role") == "reference" for n in runs), (
        f"non-causal {type(detector).__name__} runs as a method in {runs}")
    return False


def assert_same(a, b, upto=None):
    sl = slice(None) if upto is None else slice(0, upto)
    np.testing.assert_array_equal(a.t[sl], b.t[sl])
    np.testing.assert_array_equal(a.score[sl], b.score[sl])  # NaN == NaN here
    np.testing.assert_array_equal(a.alarm[sl], b.alarm[sl])


def test_constructor_stores_hyper_parameters_only(unfitted, corpus):
    assert set(vars(unfitted)) == set(unfitted.get_params())
    before = set(vars(unfitted))
    fit(unfitted, corpus).reset()
    learned = set(vars(unfitted)) - before
    assert learned and all(a.endswith("_") for a in learned)


def test_calibrated_detectors_refuse_to_run_unfitted(unfitted, one_flight):
    if not unfitted.calibrated:
        assert unfitted.fitted() == {}
        return
    with pytest.raises(NotFittedError, match="fit"):
        run_detector(unfitted, load_flight(one_flight))


def test_fitted_values_are_json_ready(detector):
    json.dumps(detector.fitted(), allow_nan=False)


def test_outputs_have_the_declared_shape(detector, one_flight):
    trace = run_detector(detector, load_flight(one_flight))
    assert trace.score.shape == trace.alarm.shape == (trace.t.size, len(detector.channels()))
    assert trace.alarm.dtype == bool
    assert np.all(np.diff(trace.t) > 0)


def test_each_channel_names_the_measured_signal_it_scores(detector):
    outputs = detector.channel_outputs()
    assert len(outputs) == len(detector.channels())
    assert set(outputs) <= set(detector.signals()) and set(outputs) <= set(SIGNALS)


def test_alarm_is_score_above_threshold(detector, one_flight):
    """The contract that lets the threshold sweep re-threshold stored scores."""
    trace = run_detector(detector, load_flight(one_flight))
    assert trace.threshold.shape == (len(detector.channels()),)
    assert np.all(trace.threshold > 0)
    with np.errstate(invalid="ignore"):
        np.testing.assert_array_equal(trace.alarm, trace.score > trace.threshold)


def test_probes_are_named_once_and_do_not_change_the_run(detector, one_flight):
    flight = load_flight(one_flight)
    plain, probed = run_detector(detector, flight), run_detector(detector, flight, probes=True)
    assert_same(plain, probed)
    assert plain.probes == {}
    assert len(probed.probes) == len(set(probed.probes))
    for name, values in probed.probes.items():
        assert values.shape == probed.t.shape
        assert np.isfinite(values).any(), f"probe {name} is never computed"


def test_batch_run_equals_streaming(detector, one_flight):
    """A detector's own run() (batch or compiled) gives the scores and probes of update()
    step by step to rounding, and the same alarms wherever a score is not within
    rounding of its threshold."""
    if not causal_or_reference(detector):
        pytest.skip("a non-causal reference: its run() uses the whole flight by design")
    s = sample(load_flight(one_flight), detector.signals(), detector.rate_hz)
    score, alarm, probes = detector.run(s, probes=True)
    ref_score, ref_alarm, ref_probes = Detector.run(detector, s, probes=True)
    np.testing.assert_allclose(score, ref_score, rtol=1e-9, atol=1e-9)
    thr = detector.thresholds()
    tie = np.abs(ref_score - thr) <= 1e-9 * np.maximum(1.0, thr)
    np.testing.assert_array_equal(alarm[~tie], ref_alarm[~tie])
    assert list(probes) == list(ref_probes)
    for name in probes:
        np.testing.assert_allclose(probes[name], ref_probes[name], rtol=1e-9, atol=1e-9)


def test_deterministic(detector, one_flight):
    flight = load_flight(one_flight)
    assert_same(run_detector(detector, flight), run_detector(detector, flight))


def test_reset_forgets_the_previous_flight(detector, corpus, one_flight):
    other = load_flight(next(p for p in corpus.iterdir() if "no_failure" in p.name))
    flight = load_flight(one_flight)
    run_detector(detector, other)
    fresh = fit(type(detector)(**detector.get_params()), corpus)
    assert fresh.fitted() == detector.fitted()
    assert_same(run_detector(detector, flight), run_detector(fresh, flight))


def _scrambled(cell: str) -> str:
    try:
        return repr(float(cell) * -3.0 + 17.0)
    except ValueError:
        return cell


def test_causal(detector, one_flight, tmp_path):
    """Changing the data after time t changes no output before t."""
    if not causal_or_reference(detector):
        pytest.skip("a non-causal reference, ranked apart")
    flight = load_flight(one_flight)
    base = run_detector(detector, flight)
    cut_s = 0.7 * float(base.t[-1])
    altered = shutil.copytree(one_flight, tmp_path / "altered" / one_flight.name)
    for f in altered.glob("*mavros*.csv"):
        lines = f.read_text().splitlines()
        t_ns = np.array([int(line.split(",", 1)[0]) for line in lines[1:]])
        cut_ns = flight.t0_ns + int(cut_s * 1e9)
        out = [lines[0]]
        for line, t in zip(lines[1:], t_ns, strict=True):
            if t > cut_ns:  # scramble every field after the cut (not time, seq, stamp)
                cells = line.split(",")
                line = ",".join(cells[:3] + [_scrambled(c) for c in cells[3:]])
            out.append(line)
        f.write_text("\n".join(out) + "\n")
    changed = run_detector(detector, load_flight(altered))
    before = int(np.searchsorted(base.t, cut_s, side="right"))
    assert before > 0
    assert_same(base, changed, upto=before)
    # the alteration must reach the detector, or this test could not fail
    assert not np.array_equal(base.score[before:], changed.score[before:], equal_nan=True)
