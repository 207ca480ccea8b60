"""The leakage audit finds, from the data alone, the signals the fault emulation writes."""

import numpy as np
import pytest

from alfa_bench.analysis.leakage import flat_spell_starts, leakage_markdown, leakage_table
from alfa_bench.data import load_flight
from synthetic import write_flight

FLIGHTS = {
    "carbonZ_2018-07-18-15-53-31_1_engine_failure": dict(onset_s=50.0),
    "carbonZ_2018-07-18-15-53-31_2_engine_failure": dict(onset_s=40.0, seed=8),
    "carbonZ_2018-09-11-15-06-34_1_rudder_right_failure":
        dict(onset_s=45.0, fault_topic="failure_status-rudder", code=3, seed=3),
    "carbonZ_2018-09-11-17-55-30_2_left_aileron_failure":
        dict(onset_s=52.0, fault_topic="failure_status-aileron", code=2, seed=4),
    "carbonZ_2018-09-11-14-41-51_elevator_failure":
        dict(onset_s=48.0, fault_topic="failure_status-elevator", code=1, seed=6),
    "carbonZ_2018-07-18-16-37-39_1_no_failure": dict(seed=1),
    "carbonZ_2018-10-05-14-34-20_1_no_failure": dict(seed=5),
}


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    processed = tmp_path_factory.mktemp("leak") / "processed"
    flights = {n: load_flight(write_flight(processed, n, emulate_surfaces=True, **kw))
               for n, kw in FLIGHTS.items()}
    return leakage_table(flights)


def test_flat_spells_are_found_where_they_begin():
    t = np.arange(0.0, 10.0, 0.5)
    v = np.r_[np.arange(8.0), np.full(6, 8.0), np.arange(6.0)]
    assert flat_spell_starts(t, v, 1.0).tolist() == [4.0]
    assert flat_spell_starts(t, v, 3.5).size == 0


def test_the_failed_actuator_leaks_on_its_class_and_no_sensor_does(table):
    leaks = set(map(tuple, table.loc[table["leaks"], ["signal", "fault_class"]].to_numpy()))
    assert leaks == {("servo_throttle", "engine"), ("throttle", "engine"),
                     ("servo_rudder", "rudder"), ("servo_aileron_left", "aileron"),
                     ("servo_elevator", "elevator")}
    sensors = table[table["kind"] == "sensor"]
    assert {"roll", "pitch", "roll_rate", "pitch_rate", "yaw_rate"} <= set(sensors["signal"])
    assert not sensors["leaks"].any()


def test_the_evidence_is_counted_against_chance(table):
    row = table.set_index(["signal", "fault_class"]).loc[("servo_throttle", "engine")]
    assert (row["flat_at_onset"], row["flights"]) == (2, 2)
    assert row["chance_before_onset"] < 0.05 and row["p_value"] < 0.01
    text = leakage_markdown(table)
    assert "| `servo_throttle` | actuator | engine | yes |" in text
    assert "NO: it leaks" not in text
    # channels 4 and 5 move together here and only the left aileron fails: the right
    # one is an actuator the data cannot show leaking
    assert "| `servo_aileron_right` | actuator | none | not shown" in text
