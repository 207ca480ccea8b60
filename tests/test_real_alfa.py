"""Checks on the real ALFA flights (skipped, and said so in the header, without ALFA_DIR)."""

import json

import numpy as np
import pandas as pd
import pytest
from config_runs import CONFIG

from alfa_bench.analysis import detection_record
from alfa_bench.data import build_manifest, load_flight, subset_flights
from alfa_bench.methods import REGISTRY, make_detector, run_detector, training_segments


@pytest.fixture(scope="module")
def manifest(real_processed):
    return build_manifest(real_processed)


def test_icra22_subset_has_the_papers_flights(manifest):
    icra = manifest[manifest["flight"].isin(subset_flights(manifest, "icra22"))]
    assert len(icra) == 22
    assert icra["fault_class"].value_counts().to_dict() == {
        "engine": 7, "none": 5, "aileron": 4, "rudder": 3, "elevator": 2, "rudder+aileron": 1}


def test_all_subset_is_every_flight_with_ground_truth(manifest):
    everything = subset_flights(manifest, "all")
    assert len(everything) == manifest["ground_truth"].sum()
    assert not any("no_ground_truth" in f for f in everything)


def test_onsets_match_the_authors_table(manifest, real_processed):
    table = real_processed.parent / "sequences.csv"
    if not table.exists():
        pytest.skip(f"{table} not present")
    seq = pd.read_csv(table).set_index("sequence")
    for row in manifest[manifest["onset_s"].notna()].itertuples():
        flight = load_flight(real_processed / row.flight)
        onset_ns = flight.t0_ns + round(row.onset_s * 1e9)
        assert abs(onset_ns - int(seq.loc[row.flight, "onset_time_ns"])) < 1000, row.flight


def test_a_real_flight_gives_a_complete_record(manifest, real_processed):
    row = manifest[manifest["fault_class"] == "engine"].iloc[0]
    record, trace = detection_record("rls_arx_zscore", {"detector": "rls_arx_zscore"},
                                     make_detector("rls_arx_zscore"),
                                     load_flight(real_processed / row["flight"]),
                                     {row["flight"]: row["sha256"]})
    assert record["first_alarm_s"] == trace.first_alarm_s()
    assert record["outcome"] in {"TP", "FP", "FN", "TN", "FP+FN"}
    assert record["grid"]["samples"] > 25 * 60
    assert set(record["pair_first_alarm_s"]) == {"roll", "roll_error", "pitch", "pitch_error"}


@pytest.mark.parametrize("name", sorted(n for n, c in REGISTRY.items() if c.calibrated))
def test_calibrated_detectors_fit_and_run_on_real_flights(name, manifest, real_processed):
    """Fitted on the first day's flights (the first two days' for a detector that leaves
    a day out inside its fit: a supervised one, a nested selection, an outlier model's
    out-of-sample maxima), run on a flight of another day."""
    leaves_a_day_out = REGISTRY[name].supervised or name in ("nested_selection", "pyod",
                                                             "river")
    days = list(dict.fromkeys(manifest["date"]))[:2 if leaves_a_day_out else 1]
    training = [load_flight(real_processed / f) for f in
                manifest.loc[manifest["date"].isin(days) & manifest["ground_truth"], "flight"]]
    scored = manifest.loc[~manifest["date"].isin(days), "flight"].iloc[0]
    det = make_detector(name).fit(training_segments(make_detector(name), training, 1.0))
    trace = run_detector(det, load_flight(real_processed / scored))
    assert np.isfinite(trace.score).any(axis=0).all()     # every channel arms
    json.dumps(det.fitted(), allow_nan=False)             # finite, JSON-ready


@pytest.fixture(scope="module")
def leakage(manifest, real_processed):
    from alfa_bench.analysis.leakage import leakage_table
    return leakage_table({n: load_flight(real_processed / n)
                          for n in manifest.loc[manifest["ground_truth"], "flight"]})


def test_the_leakage_audit_finds_the_emulation_and_no_sensor(leakage):
    """On ALFA itself: the failed actuator's output goes flat at onset, measured, on its
    own fault class; no attitude, gyro or setpoint signal does, and no sensor leaks."""
    table = leakage
    flat = set(map(tuple, table.loc[table["goes_flat"], ["signal", "fault_class"]].to_numpy()))
    expected = {("servo_throttle", "engine"), ("throttle", "engine")}
    classes = set(table["fault_class"])
    expected |= {("servo_rudder", "rudder")} if "rudder" in classes else set()
    expected |= {("servo_elevator", "elevator")} if "elevator" in classes else set()
    assert expected <= flat
    assert not set(table.loc[table["goes_flat"], "kind"]) - {"actuator"}
    for sensor in ("roll", "pitch", "roll_rate", "pitch_rate", "yaw_rate", "accel_x"):
        assert not table.loc[table["signal"] == sensor, "leaks"].any(), sensor


def test_the_emergency_trajectory_switches_the_commands_and_only_there(leakage):
    """The commanded attitude steps at onset on the emr engine flights, and no
    setpoint leaks on a flight without an emergency trajectory."""
    rows = leakage.set_index(["signal", "fault_class", "emergency_trajectory"])
    for signal in ("roll_cmd", "pitch_cmd", "roll_error", "pitch_error"):
        assert rows.loc[(signal, "engine", True), "leaks"], signal
    setpoints = leakage[leakage["kind"] == "setpoint"]
    assert not setpoints.loc[~setpoints["emergency_trajectory"], "leaks"].any()


def test_the_headline_subset_holds_no_flight_an_honest_signal_leaks_on(leakage, manifest):
    from alfa_bench.analysis.leakage import leaking_flights
    primary = CONFIG["primary_subset"]
    assert leaking_flights(leakage, manifest, subset_flights(manifest, primary)) == {}
    assert leaking_flights(leakage, manifest, subset_flights(manifest, "all"))


def test_measured_airspeed_is_not_measured_from_2018_09_11_on(manifest):
    dead = manifest["not_measured"].str.split(";").apply(lambda s: "airspeed" in s)
    assert (dead == (manifest["date"] >= "2018-09-11")
            | (manifest["label"] == "no_ground_truth")).all()


def test_damaged_real_flights_are_refused_at_load_for_every_run(real_processed, tmp_path):
    """Four flights of 2018-09-11, copied and damaged one way each (a topic going back in
    time, a word in a number's cell, an empty cell, a missing topic file), are refused
    at load, where every run would otherwise have read them differently; an undamaged
    copy of the same day loads. (The ranking on the flights left, with the workflow, is
    tests/test_workflow.py's, on the synthetic corpus.)"""
    import shutil

    from broken import edit, set_cell, topic_file

    from alfa_bench.data import scan_flights

    names = ["carbonZ_2018-09-11-14-16-55_no_failure",
             "carbonZ_2018-09-11-15-06-34_1_rudder_right_failure",
             "carbonZ_2018-09-11-14-41-38_no_failure",
             "carbonZ_2018-09-11-17-55-30_1_right_aileron_failure",
             "carbonZ_2018-09-11-15-05-11_2_no_failure"]
    for name in names:
        shutil.copytree(real_processed / name, tmp_path / "processed" / name)
    back, word, empty, gone, clean = (tmp_path / "processed" / n for n in names)
    edit("mavros-nav_info-yaw", lambda ls: ls[:3] + [ls[4], ls[3]] + ls[5:])(back)
    edit("mavros-wind_estimation", lambda ls: ls[:5] + [set_cell(ls[5], 4, "abc")]
         + ls[6:])(word)
    edit("mavros-nav_info-roll", lambda ls: ls[:7] + [set_cell(ls[7], 5, "")] + ls[8:])(empty)
    topic_file(gone, "mavros-nav_info-errors").unlink()
    manifest, failures = scan_flights(tmp_path / "processed")
    assert list(manifest["flight"]) == [clean.name]
    why = failures.set_index("flight")["error"]
    assert set(failures["stage"]) == {"load"}
    assert "timestamps go backwards" in why[back.name]
    assert "non-numeric cell 'abc'" in why[word.name]
    assert "empty or NaN cell" in why[empty.name]
    assert "topic file is missing" in why[gone.name]
