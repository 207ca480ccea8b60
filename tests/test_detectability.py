"""Detectability table: detection and chance rates per method and fault."""

import pandas as pd
import pytest

from alfa_bench.analysis.detectability import detectability_markdown, detectability_table


def test_chance_rate_counts_the_source_flights_own_alarms_after_onset():
    manifest = pd.DataFrame({
        "flight": ["a", "b", "c"], "fault_sensor": ["roll"] * 3, "fault_kind": ["drift"] * 3,
        "fault_magnitude": [0.5] * 3, "fault_source": ["s", "s", "t"]})
    records = [{"method": "m", "flight": f, "onset_s": onset, "outcome": outcome,
                "detection_s": dt} for f, onset, outcome, dt in [
                    ("a", 20.0, "TP", 1.0), ("b", 40.0, "TP", 3.0), ("c", 20.0, "FN", None)]]
    clean = [{"method": "m", "flight": "s", "first_alarm_s": 30.0},   # after a's onset only
             {"method": "m", "flight": "t", "first_alarm_s": None}]
    table = detectability_table(records, manifest, clean)
    (row,) = table.to_dict(orient="records")
    assert (row["flights"], row["detected"], row["missed"]) == (3, 2, 1)
    assert row["detection_rate"] == pytest.approx(2 / 3)
    assert row["chance_rate"] == pytest.approx(1 / 3)
    assert row["mean_detection_s"] == 2.0
    assert "| drift 50 % | 67 [33] (2.0 s) |" in detectability_markdown(table)
