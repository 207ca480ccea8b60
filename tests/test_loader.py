"""The flight reader on synthetic flights in ALFA's on-disk format."""

import numpy as np
import pytest

from alfa_bench.data import AlfaDataError, MissingTopicError, find_flights, load_flight
from alfa_bench.data.flight import parse_flight_name
from alfa_bench.data.synthetic import rename_flight


def test_clock_onset_class_and_label(one_flight):
    f = load_flight(one_flight)
    assert f.id == one_flight.name
    assert f.date == "2018-07-18"
    assert f.label == "engine_failure"
    assert not f.emergency_trajectory
    roll = f.topic("mavros-nav_info-roll")
    gt = f.topic("failure_status-engines")
    # zero of the clock is the earliest sample of any topic
    assert min(float(t.t[0]) for t in f.topics.values()) == 0.0
    assert f.fault.fault_class == "engine"
    assert f.fault.onset_s == pytest.approx(50.0, abs=1e-9)
    assert f.fault.onset_s == float(gt.t[0])
    assert f.fault.end_s == float(gt.t[-1])
    assert f.fault.codes == {"failure_status-engines": (1,)}
    assert np.all(np.diff(roll.t) > 0)
    assert f.duration_s == pytest.approx(max(float(t.t[-1]) for t in f.topics.values()))
    assert f.repairs == ()


def test_fault_free_flight_has_class_none(corpus):
    f = load_flight(corpus / "carbonZ_2018-07-18-16-37-39_1_no_failure")
    assert f.has_ground_truth and f.fault.fault_class == "none" and f.fault.onset_s is None


def test_combined_fault_is_named_rudder_plus_aileron(one_flight):
    one_flight = rename_flight(one_flight,
                               "carbonZ_2018-09-11-17-27-13_1_rudder_zero__left_aileron_failure")
    name = one_flight.name
    gt = one_flight / f"{name}-failure_status-engines.csv"
    gt.rename(one_flight / f"{name}-failure_status-aileron.csv")
    (one_flight / f"{name}-failure_status-rudder.csv").write_text(
        gt.with_name(f"{name}-failure_status-aileron.csv").read_text())
    assert load_flight(one_flight).fault.fault_class == "rudder+aileron"


def test_emergency_trajectory_flag(corpus):
    f = load_flight(corpus / "carbonZ_2018-07-30-16-29-45_engine_failure_with_emr_traj")
    assert f.emergency_trajectory and f.label == "engine_failure_with_emr_traj"


def test_missing_topic_names_flight_and_file(one_flight):
    f = load_flight(one_flight)
    with pytest.raises(MissingTopicError, match=r"flight carbonZ_.*mavros-imu-data\.csv"):
        f.topic("mavros-imu-data")


def test_folder_without_flight_files_is_skipped(tmp_path, caplog):
    processed = tmp_path / "processed"
    processed.mkdir()
    (processed / "notes").mkdir()
    assert find_flights(processed) == []
    assert "not a flight folder" in caplog.text


def test_bad_folder_name_is_an_error(tmp_path):
    with pytest.raises(AlfaDataError, match="not an ALFA flight name"):
        parse_flight_name("my_flight")


def test_no_ground_truth_flight_is_kept_out_of_scoring(tmp_path, caplog):
    from alfa_bench.data.synthetic import write_flight
    f = load_flight(write_flight(tmp_path, "carbonZ_2018-07-18-12-10-11_no_ground_truth"))
    assert f.fault is None and not f.has_ground_truth
    assert "kept out of labelled scoring" in caplog.text
