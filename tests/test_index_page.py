"""The results page's note on a fault class no shown run detects: the ceiling's numbers."""

import pandas as pd

from alfa_bench.outputs.index_page import _apart, _beyond_reach


def test_a_class_no_shown_run_detects_is_explained_by_the_ceiling():
    per_class = pd.DataFrame({
        "method": ["a", "a", "b", "b", "c"],
        "fault_class": ["aileron", "engine", "aileron", "engine", "aileron"],
        "flights": [5, 7, 5, 7, 5], "detected": [0, 3, 0, 0, 2]})
    ceiling = pd.DataFrame({
        "subset": ["no_emr", "no_emr", "no_emr", "all"],
        "fault_class": ["aileron", "aileron", "engine", "aileron"],
        "feature": ["climb_rate_drop", "roll_step", "accel_x_drop", "roll_step"],
        "fault_flights": [5, 5, 7, 6], "auc": [0.3, 0.2, 0.73, 0.9],
        "auc_low": [0.0, 0.0, 0.45, 0.8], "auc_high": [0.646, 0.5, 0.96, 1.0],
        "above_free_max": [0, 0, 0, 4], "best": [True, False, True, True]})
    note = _beyond_reach(ceiling, per_class, ["a", "b"], "no_emr", "5.0")
    # aileron: missed by both shown runs (c is not shown); engine: a detects it
    assert "<code>aileron</code>: no single feature carries it within 5.0 s" in note
    assert ("<code>climb_rate_drop</code>, separates its 5 flights from fault-free "
            "flight with AUC 0.30 (95 % 0.00-0.65; 0.5 is chance) and passes every "
            "fault-free maximum on 0 of 5") in note
    assert "engine" not in note and 'href="tables/ceiling.md"' in note
    assert _beyond_reach(ceiling, per_class, ["a", "c"], "no_emr", "5.0") == ""


def test_a_ranking_on_flights_without_a_fault_names_no_leader():
    """Where the flights every ranked run scored hold no fault (a small corpus whose
    runs failed elsewhere), the top line says no run can be told ahead, not that the
    data cannot tell a 'leader' of 0 of 0 faults apart from the others."""
    table = pd.DataFrame({"method": ["a", "b"], "rank": [1, 2], "tp": [0, 0],
                          "fn": [0, 0], "flights": [1, 1], "vs_best_p": [None, 1.0]})
    line = _apart(table)
    assert "No run can be told ahead" in line and "1 flight(s)" in line
    assert "leader" not in line
    table[["tp", "fn"]] = [[3, 1], [1, 3]]
    assert "leader, <code>a</code> (3 of 4 faults in time)" in _apart(table)
