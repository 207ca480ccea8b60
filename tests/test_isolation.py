"""Isolation: the OKID observer bank and the RLS-ARX pairs name the faulty sensor."""

import numpy as np
import pytest

from alfa_bench.analysis.isolation import (
    MISSED,
    SENSOR_ACTUATOR,
    confusion,
    isolate,
    isolation_rows,
    measured_sensor,
)
from alfa_bench.data import load_flight
from alfa_bench.data.inject import inject_sensor_fault
from alfa_bench.methods import Trace, fault_free_segments, make_detector, run_detector

SOURCE = "carbonZ_2018-07-18-16-37-39_1_no_failure"


FULL_BANK = {"inputs": ["roll_cmd", "pitch_cmd", "airspeed_cmd", "servo_aileron_left",
                        "servo_elevator"],
             "outputs": ["roll", "pitch", "airspeed", "roll_rate", "pitch_rate", "yaw_rate"]}


def fitted_bank(corpus, params=None):
    """The paper's bank, fitted on the corpus's other fault-free flights and the faulty
    ones' pre-fault data."""
    training = [load_flight(p) for p in sorted(corpus.iterdir()) if p.name != SOURCE]
    detector = make_detector("kalman_okid", params)
    return detector.fit(fault_free_segments(detector, training, margin_s=1.0))


@pytest.fixture(scope="module")
def bank(corpus):
    """On the synthetic roll and pitch loops."""
    return fitted_bank(corpus)


@pytest.fixture(scope="module")
def full_bank(corpus):
    """Over every sensor of the injected grid."""
    return fitted_bank(corpus, FULL_BANK)


@pytest.mark.parametrize("sensor", ["roll", "pitch"])
@pytest.mark.parametrize("kind, magnitude", [("drift", 0.5), ("stuck", 0.0), ("scale", 0.5)])
def test_the_bank_names_the_faulty_sensor(bank, corpus, tmp_path, sensor, kind, magnitude):
    flight = load_flight(inject_sensor_fault(corpus / SOURCE, tmp_path, sensor, kind,
                                             magnitude, 40.0))
    trace = run_detector(bank, flight)
    outputs = dict(zip(bank.channels(), bank.channel_outputs(), strict=True))
    assert isolate(trace, flight.fault.onset_s, outputs) == sensor


@pytest.mark.parametrize("sensor", FULL_BANK["outputs"])
def test_the_full_bank_names_the_faulty_sensor(full_bank, corpus, tmp_path, sensor):
    flight = load_flight(inject_sensor_fault(corpus / SOURCE, tmp_path, sensor, "drift",
                                             0.5, 40.0))
    trace = run_detector(full_bank, flight)
    outputs = dict(zip(full_bank.channels(), full_bank.channel_outputs(), strict=True))
    assert isolate(trace, flight.fault.onset_s, outputs) == sensor


@pytest.mark.parametrize("sensor", ["roll", "pitch"])
def test_the_rls_arx_pairs_name_the_faulty_sensor(corpus, tmp_path, sensor):
    # stuck: on this short flight RLS-ARX arms only after 41 s, and absorbs a drift
    # that starts before it judges
    flight = load_flight(inject_sensor_fault(corpus / SOURCE, tmp_path, sensor, "stuck",
                                             0.0, 40.0))
    detector = make_detector("rls_arx_zscore")
    trace = run_detector(detector, flight)
    outputs = dict(zip(detector.channels(), detector.channel_outputs(), strict=True))
    assert isolate(trace, flight.fault.onset_s, outputs) == sensor


def test_an_alarm_on_no_sensor_isolates_nothing_and_cannot_be_scored():
    t = np.arange(3.0)
    trace = Trace(t=t, score=np.full((3, 1), 2.0), alarm=np.ones((3, 1), bool),
                  channels=("servo",), threshold=np.ones(1))
    assert isolate(trace, 1.0, {"servo": "servo_rudder"}) is None
    record = {"method": "oracle", "flight": "f", "fault_class": "rudder", "onset_s": 1.0,
              "fault_sensor": None, "isolated_sensor": None}
    with pytest.raises(ValueError, match="oracle on f: its alarm scores no sensor"):
        isolation_rows([record], truth="actuator")


def test_a_signal_names_the_sensor_it_reads():
    assert measured_sensor("roll_error") == "roll" and measured_sensor("pitch") == "pitch"
    assert measured_sensor("roll_rate") == "roll_rate"
    assert measured_sensor("accel_x") == "accel_x"     # a sensor faults are not injected into
    with pytest.raises(KeyError):
        measured_sensor("servo_aileron_left")
    assert SENSOR_ACTUATOR["airspeed"] == SENSOR_ACTUATOR["accel_x"] == "engine"


def test_confusion_counts_true_against_predicted():
    t = np.arange(5.0)

    def record(i, k, channel):
        score = np.zeros((5, 2))
        score[k:, channel] = 2.0
        trace = Trace(t=t, score=score, alarm=score > 1.0, channels=("a", "b"),
                      threshold=np.ones(2))
        outputs = {"a": "roll", "b": "pitch"}
        return {"method": "m", "flight": f"f{i}", "fault_class": "aileron", "onset_s": 1.0,
                "fault_sensor": None, "isolated_sensor": isolate(trace, 1.0, outputs)}
    records = [record(0, 2, 0), record(1, 3, 1), record(2, 5, 0)]
    rows = isolation_rows(records, truth="actuator")
    assert rows["predicted"].tolist() == ["aileron", "elevator", MISSED]
    assert rows["correct"].tolist() == [True, False, False]
    table = confusion(rows, ["engine", "aileron", "elevator", "rudder"])["m"]
    assert table.loc["aileron"].tolist() == [0, 1, 1, 0, 1]
