"""Threshold sweeps from stored scores."""

import math

import numpy as np
import pandas as pd
import pytest

from alfa_bench.analysis.scoring import flight_outcome
from alfa_bench.analysis.sweep import DEFAULT_SCALES, flight_curves, ratio, sweep_table
from alfa_bench.methods import Trace


def make_trace(score, threshold, rate_hz=10.0):
    score = np.asarray(score, dtype=float).reshape(len(score), -1)
    threshold = np.asarray(threshold, dtype=float)
    with np.errstate(invalid="ignore"):
        alarm = score > threshold
    t = np.arange(score.shape[0]) / rate_hz
    return Trace(t=t, score=score, alarm=alarm,
                 channels=tuple(f"c{i}" for i in range(score.shape[1])), threshold=threshold)


def test_scale_one_is_the_configured_run_exactly():
    rng = np.random.default_rng(3)
    # scores at and one ulp around the threshold: division must not move the decision
    thr = np.array([3.0, 0.7])
    base = rng.uniform(0, 1.2, size=(500, 2)) * thr
    base[10] = thr
    base[20] = np.nextafter(thr, np.inf)
    base[30] = np.nextafter(thr, 0)
    base[:5, 1] = np.nan
    trace = make_trace(base, thr)
    r = ratio(trace)
    np.testing.assert_array_equal(r > 1.0, trace.alarm.any(axis=1))
    first = flight_curves(trace, None, np.array([1.0]))["first_alarm_s"][0]
    assert first == trace.first_alarm_s()


def test_events_are_rising_edges_before_onset_counted_by_brute_force():
    rng = np.random.default_rng(4)
    trace = make_trace(rng.gamma(1.0, 1.0, size=(400, 3)), [1.0, 2.0, 0.5])
    onset = 30.0
    scales = np.array([0.3, 1.0, 2.5, 7.0])
    c = flight_curves(trace, onset, scales)
    r = ratio(trace)[trace.t < onset]
    for i, kappa in enumerate(scales):
        up = r > kappa
        assert c["events"][i] == np.sum(up & ~np.r_[False, up[:-1]])
        first = np.argmax(ratio(trace) > kappa)
        assert c["first_alarm_s"][i] == trace.t[first]
    assert c["free_s"] == pytest.approx(30.0)


def test_sweep_table_scores_like_the_records_at_scale_one():
    onset = {"f1": 5.0, "f2": 5.0, "f3": None}
    scores = {"f1": [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0] * 3 + [9] * 10,
              "f2": [0] * 20 + [2] * 5 + [0] * 45,
              "f3": [0] * 60 + [1.5] * 10}
    traces = {("m", f): make_trace(s, [1.0]) for f, s in scores.items()}
    records = []
    for f, tr in traces.items():
        first = tr.first_alarm_s()
        records.append({"method": "m", "flight": f[1], "onset_s": onset[f[1]],
                        "outcome": flight_outcome(onset[f[1]], first)})
    manifest = pd.DataFrame({"flight": list(onset), "subsets": ["all"] * 3,
                             "ground_truth": [True] * 3})
    table = sweep_table(records, traces, manifest, ["all"], math.inf, DEFAULT_SCALES)
    at_one = table[table["scale"] == 1.0].iloc[0]
    assert (at_one["tp"], at_one["fp"], at_one["fn"], at_one["tn"]) == (1, 2, 1, 0)
    # f2 alarms at 2.0 s (before onset) and f3 (fault-free) at 6.0 s: 2 events in
    # 5 + 5 + 7 s of fault-free flight
    assert at_one["false_alarms_per_hour"] == pytest.approx(2 / (17 / 3600))
    high = table[table["scale"] == 4.0].iloc[0] if 4.0 in set(table["scale"]) else \
        table[table["scale"] > 4.0].iloc[0]
    assert (high["tp"], high["fp"], high["tn"]) == (1, 0, 1)
    assert high["recall"] == 0.5
    # lowering every threshold never removes a false alarm
    fa = table.sort_values("scale")["false_alarm_flights"].to_numpy()
    assert np.all(np.diff(fa) <= 0)
