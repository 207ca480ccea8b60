"""The features-by-learners table: a learner's runs side by side, counted on the
headline subset, with the configurations a fair-best run chose."""

import pandas as pd

from alfa_bench.analysis.features_learners import (
    chosen_configurations,
    features_learners,
    features_learners_markdown,
)

FLIGHTS = {"carbonZ_2018-07-18-15-53-31_1_engine_failure": ("engine", 100.0),
           "carbonZ_2018-07-30-16-39-00_1_engine_failure": ("engine", 80.0),
           "carbonZ_2018-09-11-14-16-55_no_failure": ("none", None)}


def _per_flight(run: str, alarms: list) -> pd.DataFrame:
    rows = []
    for (flight, (kind, onset)), alarm in zip(FLIGHTS.items(), alarms, strict=True):
        outcome = ("TP" if kind != "none" and alarm is not None and onset <= alarm <= onset + 5
                   else "FP" if alarm is not None else "FN" if kind != "none" else "TN")
        rows.append({"method": run, "flight": flight, "fault_class": kind, "onset_s": onset,
                     "first_alarm_s": alarm, "outcome": outcome, "survival": 1.0})
    return pd.DataFrame(rows)


MANIFEST = pd.DataFrame({"flight": list(FLIGHTS), "subsets": ["all;no_emr"] * 3,
                         "ground_truth": True})

#: no flight off the common ground (left_out.csv)
NONE_LEFT_OUT = pd.DataFrame(columns=["flight", "subsets", "stage", "runs", "error"])


def _comparison(runs: dict) -> pd.DataFrame:
    """The comparison's rows the table reads, on ``no_emr``: per run, its supervision,
    configurations, whether it beats silence and its scored flights."""
    return pd.DataFrame([{"subset": "no_emr", "method": m, "calibration": c,
                          "configurations": n, "beats_silence": b, "flights": f}
                         for m, (c, n, b, f) in runs.items()])


def test_each_learner_gets_a_cell_per_run_and_its_chosen_configurations():
    manifest = MANIFEST
    per_flight = pd.concat([_per_flight("knn", [101.0, None, 50.0]),
                            _per_flight("knn_nested", [101.0, 82.0, None])])
    comparison = pd.concat([_comparison({
        "knn": ("fault-free only", 1, False, 3),
        "knn_nested": ("supervised (labelled flights)", 9, True, 3)}), pd.DataFrame([{
            "subset": "all", "method": "knn", "calibration": "x", "configurations": 1,
            "beats_silence": True, "flights": 3}])], ignore_index=True)
    records = [{"calibration": {"fold": d, "fitted": {"chosen": {
        "window_s": 5.0, "params": {"n_neighbors": k}}}}}
        for d, k in [("a", 5), ("a", 5), ("b", 20), ("c", 5)]]
    chosen = chosen_configurations(records)
    assert chosen == "window 5 s, n_neighbors 5 (2 dates); window 5 s, n_neighbors 20 (1)"
    rows = [{"learner": "KNN", "windows": "knn", "windows_best": "knn_nested",
             "residuals": "knn_residuals"}]
    table = features_learners(per_flight, comparison, manifest, rows, "no_emr", 0.9,
                              {"knn_nested": chosen}, NONE_LEFT_OUT).set_index("run")
    assert list(table.index) == ["knn", "knn_nested"]            # the residual run: not run
    assert table.loc["knn", ["detected", "fault_free_alarmed"]].tolist() == [1, 1]
    assert table.loc["knn_nested", ["detected", "fault_free_alarmed"]].tolist() == [2, 0]
    assert not table.loc["knn", "supervised"] and table.loc["knn_nested", "supervised"]
    assert table.loc["knn", "beats_silence"] == False  # noqa: E712 (numpy bool)
    md = features_learners_markdown(table.reset_index(), "no_emr", 5.0)
    assert "| KNN | `knn`: 1 of 2, 1 of 1 fault-free alarmed" in md
    assert "best of 9: window 5 s, n_neighbors 5 (2 dates)" in md
    assert "does not beat silence" in md and "| physical residuals" not in md


def test_each_run_is_counted_on_the_common_ground():
    """A flight some ranked run failed on is off the common ground the comparison ranks
    on: no cell counts it, though the runs of the table scored it; a run the comparison
    scored on no flight has no cell."""
    second = list(FLIGHTS)[1]
    per_flight = pd.concat([_per_flight("knn", [101.0, None, 50.0]),
                            _per_flight("knn_nested", [101.0, 82.0, None])])
    comparison = _comparison({"knn": ("fault-free only", 1, False, 2),
                              "knn_nested": ("fault-free only", 9, True, 2),
                              "knn_residuals": ("fault-free only", 1, None, 0)})
    left_out = pd.DataFrame([{"flight": second, "subsets": "all;no_emr",
                              "stage": "calibration", "runs": "other",
                              "error": "other: too few dates"}])
    rows = [{"learner": "KNN", "windows": "knn", "windows_best": "knn_nested",
             "residuals": "knn_residuals"}]
    table = features_learners(per_flight, comparison, MANIFEST, rows, "no_emr", 0.9, {},
                              left_out).set_index("run")
    assert list(table.index) == ["knn", "knn_nested"]
    assert table.loc["knn_nested", ["faulty_flights", "detected"]].tolist() == [1, 1]
    assert table.loc["knn", ["faulty_flights", "detected", "fault_free_alarmed"]].tolist() == [
        1, 1, 1]
