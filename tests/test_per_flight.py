"""The per-flight table: outcomes in words and margins from the traces."""

import math

import numpy as np
import pandas as pd

from alfa_bench.analysis.per_flight import margins, per_flight_table, verdict
from alfa_bench.methods import Trace


def trace(score):
    score = np.asarray(score, dtype=float)
    t = np.arange(score.shape[0], dtype=float)
    thr = np.array([2.0, 4.0])
    return Trace(t=t, score=score, alarm=score > thr, channels=("a", "b"), threshold=thr)


def test_verdicts():
    assert verdict(10.0, None, None, 5.0) == "no alarm"
    assert verdict(10.0, 10.48, "side", 5.0) == "detected in 0.48 s (side)"
    assert verdict(10.0, 6.0, "thrust", 5.0) == "alarm 4.0 s before onset (thrust)"
    assert verdict(10.0, 22.6, "pitch", 5.0) == \
        "first alarm 12.6 s after onset, past the deadline (pitch)"
    assert verdict(None, 72.0, "thrust", 5.0) == "false alarm at 72.0 s (thrust)"


def test_margins_are_scores_over_thresholds_in_their_spans():
    tr = trace([[1.0, 1.0], [np.nan, 3.0], [1.0, 6.0], [3.0, 0.0], [8.0, 0.0]])
    in_time, channel, before = margins(tr, onset_s=2.0, deadline_s=1.0)
    assert (in_time, channel, before) == (1.5, "b", 0.75)   # 6/4 at t=2; 3/4 at t=1
    in_time, channel, before = margins(tr, onset_s=None, deadline_s=1.0)
    assert math.isnan(in_time) and channel is None and before == 4.0


def test_table_rows_follow_the_records():
    manifest = pd.DataFrame({"flight": ["f1", "f2"], "emergency_trajectory": [False, True],
                             "subsets": ["all", "all"], "ground_truth": [True, True]})
    base = {"method": "m", "role": "method", "reads_actuators": False,
            "pair_first_alarm_s": {"a": 3.0, "b": None}}
    records = [{**base, "flight": "f1", "fault_class": "engine", "onset_s": 2.0,
                "first_alarm_s": 3.0},
               {**base, "flight": "f2", "fault_class": "none", "onset_s": None,
                "first_alarm_s": None, "pair_first_alarm_s": {}}]
    tr = trace([[1.0, 1.0], [1.0, 1.0], [1.0, 1.0], [3.0, 1.0], [1.0, 1.0]])
    table = per_flight_table(records, {("m", "f1"): tr, ("m", "f2"): tr}, manifest, 5.0)
    assert table["outcome"].tolist() == ["TP", "TN"]
    assert table.loc[0, "verdict"] == "detected in 1.00 s (a)"
    assert table.loc[0, "margin_in_time"] == 1.5 and table.loc[1, "margin_before"] == 1.5
    assert table["emergency_trajectory"].tolist() == [False, True]
    assert table["other_class"].tolist() == [False, False]


def test_a_detection_first_on_another_axis_is_flagged_not_removed():
    manifest = pd.DataFrame({"flight": ["f1", "f2"], "emergency_trajectory": [True, False],
                             "subsets": ["all", "all"], "ground_truth": [True, True]})
    base = {"method": "m", "role": "method", "reads_actuators": False, "onset_s": 2.0,
            "first_alarm_s": 3.0, "pair_first_alarm_s": {"a": 3.0, "b": None}}
    records = [{**base, "flight": "f1", "fault_class": "aileron", "isolated_sensor": "accel_x"},
               {**base, "flight": "f2", "fault_class": "rudder+aileron",
                "isolated_sensor": "roll_rate"}]
    tr = trace([[1.0, 1.0], [1.0, 1.0], [1.0, 1.0], [3.0, 1.0], [1.0, 1.0]])
    table = per_flight_table(records, {("m", "f1"): tr, ("m", "f2"): tr}, manifest, 5.0)
    assert table["outcome"].tolist() == ["TP", "TP"]
    assert table["detected_class"].tolist() == ["engine", "aileron"]
    assert table["other_class"].tolist() == [True, False]
    assert table.loc[0, "verdict"] == ("detected in 1.00 s (a), first on the engine axis, "
                                       "not aileron")
