"""The public study's published table, its rule, and the tables that set a run beside it."""

import math

import pandas as pd

from alfa_bench.analysis.public_study import (
    STUDY_FLIGHTS,
    STUDY_SUMMARY,
    against_study,
    against_study_markdown,
    protocol_steps,
    protocol_steps_markdown,
    study_counts,
    study_outcome,
)


def test_the_published_rows_add_up_to_the_published_summary():
    """A row copied wrong would show here: the outcomes, the alarm times and the
    counts of the study's summary must agree."""
    assert len(STUDY_FLIGHTS) == STUDY_SUMMARY["flights"] == len({f for f, *_ in STUDY_FLIGHTS})
    assert study_counts(o for *_, o in STUDY_FLIGHTS) == {
        k: STUDY_SUMMARY[k] for k in ("tp", "fp", "fn", "tn")}
    assert all(study_outcome(onset, alarm) == outcome for _, onset, alarm, outcome in STUDY_FLIGHTS)


def test_one_outcome_a_flight_an_early_alarm_a_false_positive():
    assert study_outcome(50.0, 49.9) == "FP"
    assert study_outcome(50.0, 50.0) == "TP"
    assert study_outcome(50.0, 500.0) == "TP"          # however late
    assert study_outcome(50.0, math.nan) == "FN"
    assert study_outcome(None, 10.0) == "FP"
    assert study_outcome(math.nan, None) == "TN"


def _per_flight(method, alarms):
    """Per-flight rows for the study's first flights, with these first alarms."""
    rows = []
    for (flight, onset, _, _), alarm in zip(STUDY_FLIGHTS, alarms, strict=False):
        rows.append({"method": method, "flight": flight, "onset_s": onset,
                     "first_alarm_s": alarm, "fault_class": "none" if onset is None else "engine",
                     "delay_s": None if alarm is None or onset is None else alarm - onset,
                     "outcome": "TP" if onset is not None and alarm is not None
                     and 0 <= alarm - onset <= 5 else "other",
                     "margin_before": 0.5, "margin_in_time": 2.0,
                     "survival": 1.0 if method == "pooled" else math.nan})
    return pd.DataFrame(rows)


def test_a_flight_whose_outcome_differs_is_named_with_why():
    # the study's first four flights: TP at 119.7, TP at 75.5, FP at 51.1, TN
    table = against_study(_per_flight("mine", [119.7, None, 51.1, 30.0]), "mine")
    assert list(table["same"]) == [True, False, True, False]
    assert list(table.loc[~table["same"], "outcome"]) == ["FN", "FP"]
    assert table.loc[1, "why"].startswith("no alarm") and "0.50 x" in table.loc[3, "why"]
    text = against_study_markdown(table, "mine")
    assert "2 of 4 have the study's outcome" in text
    assert "carbonZ_2018-07-18-16-37-39_1_no_failure" in text           # the flight named
    assert "| the study, published, all its flights | 46 | 24 | 6 | 7 | 9 |" in text


def test_the_protocol_steps_count_in_time_early_and_fault_free_alarms():
    per_flight = pd.concat([_per_flight("published", [119.7, 75.5, 51.1, 30.0]),
                            _per_flight("pooled", [119.7, 90.0, None, None])])
    flights = per_flight["flight"].unique()
    manifest = pd.DataFrame({"flight": flights, "subsets": ["no_emr;all"] * len(flights)})
    steps = [{"run": "published", "change": "as published"},
             {"run": "absent", "change": "never scored"},
             {"run": "pooled", "change": "pools"}]
    table = protocol_steps(per_flight, manifest, steps, "no_emr", 0.9)
    assert list(table["run"]) == ["published", "pooled"]
    first, second = table.to_dict(orient="records")
    assert (first["detected"], first["early_alarms"], first["fault_free_alarmed"]) == (2, 1, 1)
    assert first["stable_detections"] is None or math.isnan(first["stable_detections"])
    assert (second["detected"], second["early_alarms"], second["fault_free_alarmed"]) == (1, 0, 0)
    assert second["stable_detections"] == 1
    assert (second["tp_study_rule"], second["fn_study_rule"], second["tn_study_rule"]) == (2, 1, 1)
    text = protocol_steps_markdown(table, "no_emr", 5.0)
    assert "| 0 | `published` | as published | 2 of 3 | 1 | 1 of 1 | - | 2 / 2 / 0 / 0 |" in text
