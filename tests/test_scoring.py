"""Scoring rules of Keipour et al. (ICRA 2019, Sec. V-C)."""

import math

import pytest

from alfa_bench.analysis import flight_outcome, summarize


@pytest.mark.parametrize("onset, first, outcome", [
    (100.0, 101.5, "TP"),
    (100.0, 100.0, "TP"),
    (100.0, 99.9, "FP+FN"),
    (100.0, None, "FN"),
    (None, 10.0, "FP"),
    (None, None, "TN"),
])
def test_flight_outcome(onset, first, outcome):
    assert flight_outcome(onset, first) == outcome


def test_papers_counts_give_papers_rates():
    """2 FP and 2 FN over 22 flights, one flight with both (17 faulty, 5 fault-free)."""
    outcomes = ["TP"] * 15 + ["FP+FN", "FN"] + ["FP"] + ["TN"] * 4
    s = summarize(outcomes)
    assert (s["flights"], s["tp"], s["fp"], s["fn"], s["tn"]) == (22, 15, 2, 2, 4)
    assert math.floor(s["precision"] * 10000) / 100 == 88.23
    assert math.floor(s["recall"] * 10000) / 100 == 88.23
    assert round(s["accuracy"] * 100, 2) == 86.36


def test_detection_times_only_of_true_positives():
    s = summarize(["TP", "TP", "FN"], [1.0, 3.0, None])
    assert s["mean_detection_s"] == 2.0 and s["max_detection_s"] == 3.0
    empty = summarize(["FN", "TN"])
    assert math.isnan(empty["mean_detection_s"]) and math.isnan(empty["precision"])


def test_unknown_outcome_is_refused():
    with pytest.raises(ValueError, match="unknown outcomes"):
        summarize(["TP", "maybe"])
