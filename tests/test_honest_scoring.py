"""The deadline, the intervals and the paired test of the honest benchmark."""

import io
import math

import numpy as np
import pandas as pd
import pytest
from scipy.stats import binomtest

from alfa_bench.analysis.blocks import block
from alfa_bench.analysis.scoring import (
    flight_outcome,
    mcnemar_exact,
    score_records,
    summarize,
    wilson_interval,
)
from alfa_bench.data import read_manifest
from alfa_bench.outputs.tables import _total, comparison_table


def test_a_first_alarm_after_the_deadline_is_a_miss():
    assert flight_outcome(10.0, 14.9, deadline_s=5.0) == "TP"
    assert flight_outcome(10.0, 15.0, deadline_s=5.0) == "TP"
    assert flight_outcome(10.0, 15.1, deadline_s=5.0) == "FN"
    assert flight_outcome(10.0, 99.0) == "TP"              # the paper's rule
    assert flight_outcome(10.0, 9.0, deadline_s=5.0) == "FP+FN"
    assert flight_outcome(None, 1.0, deadline_s=5.0) == "FP"


def test_end_of_flight_scores_well_without_a_deadline_and_nothing_with_one():
    records = [{"onset_s": 50.0, "first_alarm_s": 66.0}] * 7 + [
        {"onset_s": None, "first_alarm_s": 80.0}] * 2
    _, late = score_records(records)
    _, timely = score_records(records, deadline_s=5.0)
    assert late["accuracy"] == pytest.approx(7 / 9) and late["mean_detection_s"] == 16.0
    assert timely["tp"] == 0 and timely["accuracy"] == 0.0


def test_wilson_interval_is_scipys_to_the_bit_and_holds_the_rate():
    for n in range(1, 60):
        for k in range(n + 1):
            for level in (0.9, 0.95):
                ci = binomtest(k, n).proportion_ci(confidence_level=level, method="wilson")
                assert wilson_interval(k, n, level) == (ci.low, ci.high), (k, n, level)
    low, high = wilson_interval(15, 17)
    assert low < 15 / 17 < high
    assert all(math.isnan(v) for v in wilson_interval(0, 0))
    s = summarize(["TP", "TP", "FN", "TN"])
    assert s["recall_low"] < s["recall"] < s["recall_high"]


def test_mcnemar_counts_only_the_discordant_flights():
    a = [True] * 10 + [True] * 6 + [False] * 4
    b = [True] * 10 + [False] * 6 + [False] * 4
    test = mcnemar_exact(a, b)
    assert (test["only_a"], test["only_b"]) == (6, 0)
    assert test["p_value"] == pytest.approx(2 * 0.5 ** 6)
    assert mcnemar_exact([True, False], [True, False])["p_value"] == 1.0
    with pytest.raises(ValueError, match="same flights"):
        mcnemar_exact([True], [True, False])


def test_mcnemar_is_scipys_binomial_test():
    for b in range(40):
        for c in range(40):
            p = mcnemar_exact([True] * b + [False] * c, [False] * b + [True] * c)["p_value"]
            expected = binomtest(b, b + c, 0.5).pvalue if b + c else 1.0
            assert p == pytest.approx(expected, rel=1e-12, abs=0), (b, c)


def test_blocks_follow_the_role_and_the_inputs():
    assert block({"role": "reference", "reads_actuators": True}) == "reference"
    assert block({"role": "method", "reads_actuators": True}) == "reads actuators"
    assert block({"role": "method", "reads_actuators": False}) == "honest"
    # what the detector declares: one that sees the whole flight is a reference row
    assert block({"role": "method", "reads_actuators": False, "causal": False}) == "reference"
    assert block({"role": "method", "reads_actuators": False, "causal": True}) == "honest"


def test_only_a_calibration_by_date_is_ranked_honest():
    """A run whose calibration grouped flights by recording or flight was trained on
    flights of the dates it scored: a reference row, whatever its config's role."""
    for grouping, expected in [("date", "honest"), ("recording", "reference"),
                               ("flight", "reference")]:
        record = {"role": "method", "reads_actuators": False,
                  "calibration": {"group_by": grouping, "margin_s": 1.0}}
        assert block(record) == expected, grouping
    assert block({"role": "method", "reads_actuators": False, "calibration": None}) == "honest"


def _record(method, flight, onset, first, actuators=False, role="method"):
    return {"method": method, "flight": flight, "onset_s": onset, "first_alarm_s": first,
            "fault_class": "none" if onset is None else "engine", "detector": method,
            "reads_actuators": actuators, "role": role, "calibration": None,
            "pair_armed_s": {"c": 0.0}}


def test_a_marked_method_is_never_ranked_however_accurate(corpus):
    from alfa_bench.data import build_manifest
    manifest = build_manifest(corpus)
    flights = manifest.loc[manifest["ground_truth"]]
    records = []
    for r in flights.itertuples():
        onset = None if math.isnan(r.onset_s) else r.onset_s
        perfect = None if onset is None else onset + 0.5
        records += [_record("servo_reader", r.flight, onset, perfect, actuators=True),
                    _record("slow", r.flight, onset, None if onset is None else onset + 9),
                    _record("early", r.flight, onset, 1.0)]
    table = comparison_table(records, manifest, ["all"], deadline_s=5.0)
    table = table.set_index("method")
    assert table.loc["servo_reader", "accuracy"] == 1.0
    assert math.isnan(table.loc["servo_reader", "rank"])
    assert table.loc["slow", "rank"] == 1 and table.loc["early", "rank"] == 2
    assert table.loc["slow", "accuracy_paper"] > table.loc["slow", "accuracy"]
    assert list(table.index) == ["slow", "early", "servo_reader"]


def test_the_manifest_reads_back_its_not_measured_column(corpus, tmp_path):
    from alfa_bench.data import build_manifest
    manifest = build_manifest(corpus)
    manifest.to_csv(tmp_path / "m.csv", index=False)
    assert list(read_manifest(tmp_path / "m.csv")["not_measured"]) == [""] * len(manifest)


def test_a_subset_without_flights_has_no_rows_and_a_fully_excluded_run_is_named(corpus):
    """A flight set without emergency-trajectory flights scores `emr` as nothing, not as
    an error; a run every flight of which was excluded is listed as not scored."""
    import pandas as pd

    from alfa_bench.data import build_manifest
    from alfa_bench.outputs.tables import unscored_notes
    manifest = build_manifest(corpus)
    manifest = manifest[~manifest["emergency_trajectory"]]
    flights = manifest.loc[manifest["ground_truth"]]
    records = [_record("a", r.flight, None if math.isnan(r.onset_s) else r.onset_s, None)
               for r in flights.itertuples()]
    table = comparison_table(records, manifest, ["all", "emr"], deadline_s=5.0)
    assert set(table["subset"]) == {"all"}
    failures = pd.DataFrame([{"flight": f, "stage": "calibration", "method": "b"}
                             for f in flights["flight"]])
    notes = unscored_notes(table, failures, manifest, ["all", "emr"])
    assert f"`b` on `all`: all {len(flights)} flights excluded (calibration)" in notes
    assert "`a`" not in notes and "`emr`" not in notes


def test_runs_are_ranked_on_the_common_ground_and_a_run_that_failed_is_flagged(
        corpus_manifest):
    """A run that failed on a flight the others scored is ranked all the same, on the
    flights every run scored, and flagged; that flight is left out for every run, with
    the run that failed and why. A run that never armed is not ranked."""
    import pandas as pd

    from alfa_bench.outputs.tables import common_ground, comparison_markdown

    flights = corpus_manifest.loc[corpus_manifest["ground_truth"]]
    first = flights["flight"].iloc[0]
    records = []
    for r in flights.itertuples():
        onset = None if math.isnan(r.onset_s) else r.onset_s
        records += [_record("fair", r.flight, onset, None if onset is None else onset + 9),
                    {**_record("silent", r.flight, onset, None), "pair_armed_s": {"c": None}}]
        if r.flight != first:       # perfect, but on one flight fewer
            records.append(_record("partial", r.flight, onset,
                                   None if onset is None else onset + 0.5))
    failures = pd.DataFrame([{"flight": first, "stage": "calibration", "method": "partial",
                              "error": "too few fault-free flights", "subsets": ""}])
    table = comparison_table(records, corpus_manifest, ["all"], 5.0, failures)
    table = table.set_index("method")
    assert table.loc["partial", "rank"] == 1 and table.loc["fair", "rank"] == 2
    assert (table["flights"] == len(flights) - 1).all() and (table["excluded"] == 1).all()
    assert table.loc["partial", "failed_flights"] == 1 and table.loc["fair", "failed_flights"] == 0
    assert math.isnan(table.loc["silent", "rank"])
    assert table.loc["silent", "not_ranked"] == "never armed"
    assert list(table.index) == ["partial", "fair", "silent"]
    kept, left_out = common_ground(records, corpus_manifest, failures)
    assert first not in {r["flight"] for r in kept}
    assert left_out.to_dict(orient="records") == [{
        "flight": first, "subsets": corpus_manifest.set_index("flight").at[first, "subsets"],
        "stage": "calibration", "runs": "partial",
        "error": "partial: too few fault-free flights"}]
    text = comparison_markdown(table.reset_index())
    assert "partial (FLAGGED: failed on 1 flight; ranked on the common ground)" in text
    assert f"({len(flights)} flights, {len(flights) - 1} on the common ground, 1 left out" in text


def _failure(flight, method, error, stage="calibration"):
    return {"flight": flight, "stage": stage, "method": method, "error": error, "subsets": ""}


def test_only_the_ranked_runs_decide_the_common_ground(corpus_manifest):
    """A reference run and an actuator-reading one that failed on a flight leave it on
    the common ground: the ranked runs are scored on every flight, and each of the two
    on those it scored, which its row counts and its flag in the Markdown says."""
    import pandas as pd

    from alfa_bench.outputs.tables import common_ground, comparison_markdown, summary_table

    flights = corpus_manifest.loc[corpus_manifest["ground_truth"]]
    second, third = flights["flight"].iloc[1], flights["flight"].iloc[2]
    records = []
    for r in flights.itertuples():
        onset = None if math.isnan(r.onset_s) else r.onset_s
        late = None if onset is None else onset + 1
        records.append(_record("fair", r.flight, onset, late))
        if r.flight != second:
            records.append(_record("ref", r.flight, onset, late, role="reference"))
        if r.flight != third:
            records.append(_record("servo", r.flight, onset, late, actuators=True))
    failures = pd.DataFrame([_failure(second, "ref", "no fold"),
                             _failure(third, "servo", "no fold")])
    kept, left_out = common_ground(records, corpus_manifest, failures)
    assert left_out.empty and len(kept) == len(records)
    table = comparison_table(records, corpus_manifest, ["all"], 5.0, failures)
    table = table.set_index("method")
    n = len(flights)
    assert table.loc["fair", "flights"] == n and table.loc["fair", "rank"] == 1
    assert table.loc["ref", "flights"] == table.loc["servo", "flights"] == n - 1
    assert (table["excluded"] == 0).all()
    assert list(table["failed_flights"]) == [0, 1, 1]
    summary = summary_table(records, corpus_manifest, ["all"], 5.0, failures)
    assert dict(zip(summary["method"], summary["flights"], strict=True)) == {
        "fair": n, "ref": n - 1, "servo": n - 1}
    text = comparison_markdown(table.reset_index())
    assert f"ref (FLAGGED: failed on 1 flight; scored on {n - 1} flights of the" in text
    assert f"`all` ({n} flights;" in text and "left out" not in text


def test_a_left_out_flight_quotes_every_runs_error(corpus_manifest):
    import pandas as pd

    from alfa_bench.outputs.tables import common_ground, left_out_markdown

    flights = corpus_manifest.loc[corpus_manifest["ground_truth"], "flight"]
    first = flights.iloc[0]
    records = [_record(m, f, None, None) for m in ("a", "b", "c") for f in flights
               if f != first or m == "c"]
    failures = pd.DataFrame([_failure(first, "b", "too few dates"),
                             _failure(first, "a", "scores do not vary")])
    _, left_out = common_ground(records, corpus_manifest, failures)
    assert list(left_out["runs"]) == ["a;b"]
    assert list(left_out["error"]) == ["a: scores do not vary | b: too few dates"]
    assert "a: scores do not vary | b: too few dates" in left_out_markdown(left_out, ["all"])


def test_a_run_that_scored_no_flight_has_a_row_saying_so(corpus_manifest):
    """A run that failed on every flight of a subset has a comparison row with no
    flight scored and no scores, as the Markdown's list of runs not scored says; it
    takes no flight from the others and no line of the Markdown's tables."""
    import pandas as pd

    from alfa_bench.outputs.tables import comparison_markdown, unscored_notes

    flights = corpus_manifest.loc[corpus_manifest["ground_truth"], "flight"]
    records = [_record("a", f, None, None) for f in flights]
    failures = pd.DataFrame([_failure(f, "b", "scores do not vary") for f in flights])
    table = comparison_table(records, corpus_manifest, ["all", "icra22"], 5.0, failures)
    for subset in ("all", "icra22"):
        rows = table[table["subset"] == subset].set_index("method")
        assert list(rows.index) == ["a", "b"]
        assert rows.loc["a", "flights"] == len(
            [f for f in flights if subset in corpus_manifest.set_index("flight").at[f, "subsets"]])
        assert rows.loc["b", "flights"] == 0 and rows.loc["b", "not_ranked"] == "not scored"
        assert rows.loc["b", "failed_flights"] == rows.loc["a", "flights"]
        assert math.isnan(rows.loc["b", "accuracy"]) and rows.loc["b", "block"] == ""
    assert list(table.columns[:3]) == ["subset", "method", "block"]
    notes = unscored_notes(table, failures, corpus_manifest, ["all", "icra22"])
    assert "`b` on `all`" in notes and "`b` on `icra22`" in notes
    text = comparison_markdown(table, notes)
    assert "| not scored |" not in text and "`b` on `all`" in text
    # the counts of the scored rows stay whole numbers beside the empty cells
    assert "| 0 of " in text and ".0 of " not in text
    csv = pd.read_csv(io.StringIO(table.to_csv(index=False)))
    assert list(csv["flights"]) == list(table["flights"]) and csv["tn"].iloc[0] == len(flights)


def test_a_run_with_no_record_and_no_failure_is_an_error(corpus_manifest):
    from alfa_bench.outputs.tables import common_ground

    flights = corpus_manifest.loc[corpus_manifest["ground_truth"], "flight"]
    records = [_record("a", f, None, None) for f in flights[1:]]
    with pytest.raises(ValueError, match="no detection for 1 flight"):
        common_ground(records, corpus_manifest)


def test_a_run_no_better_than_silence_is_flagged(corpus_manifest):
    """Beside a run that arms and never alarms, a run whose accuracy under the deadline
    is not above it is flagged, in the table and its Markdown; one above it is not."""
    from alfa_bench.outputs.tables import comparison_markdown

    flights = corpus_manifest.loc[corpus_manifest["ground_truth"]]
    records = []
    for r in flights.itertuples():
        onset = None if math.isnan(r.onset_s) else r.onset_s
        records += [{**_record("silent", r.flight, onset, None, role="reference"),
                     "detector": "silent"},
                    _record("quiet", r.flight, onset, None),
                    _record("timely", r.flight, onset, None if onset is None else onset + 1)]
    table = comparison_table(records, corpus_manifest, ["all"], 5.0).set_index("method")
    assert table.loc["timely", "beats_silence"] and not table.loc["quiet", "beats_silence"]
    assert table.loc["quiet", "accuracy"] == table.loc["silent", "accuracy"]
    assert table.loc["silent", "beats_silence"] is None
    text = comparison_markdown(table.reset_index())
    assert "quiet (no better than silence)" in text and "timely (no" not in text


def test_the_by_fault_tables_flight_times_sum_as_pandas_sums_a_column():
    """The per-fault table sums flight and pre-fault times from dictionaries, not a
    frame's rows: the same float, bit for bit, NaN (a fault-free flight's pre-fault
    time) counted as 0."""
    # a draw whose sum in Python's order and math.fsum's both differ from pandas's
    rng = np.random.default_rng(13)
    values = rng.uniform(0, 400, size=40) * 10.0 ** rng.integers(-3, 3, size=40)
    values[::7] = np.nan
    frame = pd.Series(values, index=[f"f{i}" for i in range(40)])
    flights = [f"f{i}" for i in rng.permutation(40)[:23]]
    assert _total(frame.to_dict(), flights) == float(frame.loc[flights].sum())
    assert _total(frame.to_dict(), ["f0"]) == 0.0
