"""The leakage audit finds, from the data alone, the signals that carry the label: what
the fault emulation writes, and the commands an emergency trajectory switches."""

import numpy as np
import pytest

from alfa_bench.analysis.leakage import (
    flat_spell_starts,
    leakage_markdown,
    leakage_table,
    leaking_flights,
    step_ranks,
    step_sizes,
)
from alfa_bench.data import load_flight
from alfa_bench.data.manifest import manifest_of, manifest_row
from alfa_bench.data.synthetic import write_flight

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


#: as FLIGHTS, with three engine failures whose commands switch at onset
EMR = {f"carbonZ_2018-10-18-11-0{i}-00_engine_failure_with_emr_traj":
       dict(onset_s=45.0 + 2 * i, seed=20 + i, switch_deg=30.0) for i in range(3, 6)}


@pytest.fixture(scope="module")
def emr(tmp_path_factory):
    processed = tmp_path_factory.mktemp("emr") / "processed"
    flights = {n: load_flight(write_flight(processed, n, emulate_surfaces=True, **kw))
               for n, kw in {**FLIGHTS, **EMR}.items()}
    manifest = manifest_of([manifest_row(f, sha256="0" * 64) for f in flights.values()])
    return leakage_table(flights), manifest


def test_flat_spells_are_found_where_they_begin():
    t = np.arange(0.0, 10.0, 0.5)
    v = np.r_[np.arange(8.0), np.full(6, 8.0), np.arange(6.0)]
    assert flat_spell_starts(t, v, 1.0).tolist() == [4.0]
    assert flat_spell_starts(t, v, 3.5).size == 0


def test_the_failed_actuator_leaks_on_its_class_and_no_sensor_does(table):
    assert not table["emergency_trajectory"].any()
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
    assert row["flat_chance_before"] < 0.05 and row["flat_p"] < 0.01
    text = leakage_markdown(table)
    assert "| `servo_throttle` | actuator | engine |" in text
    assert "NO: it goes flat" not in text
    # channels 4 and 5 move together here and only the left aileron fails: the right
    # one is an actuator the data cannot show leaking
    assert "| `servo_aileron_right` | actuator | none |" in text
    assert "not shown: no leak" in text


def test_steps_are_how_far_a_signal_moves_from_its_recent_mean():
    t = np.arange(0.0, 10.0, 0.1)
    v = np.where(t >= 5.0, 3.0, 1.0)
    tau, d = step_sizes(t, v, rate_hz=10.0, window_s=1.0)
    assert d[np.searchsorted(tau, 5.0)] == pytest.approx(2.0)
    assert d[np.searchsorted(tau, 3.0)] == 0.0
    # half a window after the step: its mean is 2, the furthest value 3
    assert d[np.searchsorted(tau, 5.5)] == pytest.approx(1.0)
    ranks = step_ranks(np.r_[np.zeros(20), 5.0], np.array([20]), reference=10, gap=2)
    assert ranks.tolist() == [1.0]
    assert np.isnan(step_ranks(np.ones(5), np.array([4]), reference=10, gap=2, least=5)[0])


def test_a_command_switch_at_onset_leaks_on_the_emr_flights_only(emr):
    table, manifest = emr
    rows = table.set_index(["signal", "fault_class", "emergency_trajectory"])
    for signal in ("roll_cmd", "pitch_cmd", "roll_error", "pitch_error"):
        assert rows.loc[(signal, "engine", True), "leaks"], signal
        assert rows.loc[(signal, "engine", True), "step_at_onset"] == 3
        assert not rows.loc[(signal, "engine", False), "leaks"], signal
    leaking = table[table["leaks"] & (table["kind"] == "setpoint")]
    assert leaking["emergency_trajectory"].all()
    # the specific force responds to the thrust lost: it steps, it does not leak
    assert rows.loc[("accel_x", "engine", False), "steps"]
    assert not table.loc[table["kind"] == "sensor", "leaks"].any()


def test_leaking_flights_name_the_emr_flights_and_their_signals(emr):
    table, manifest = emr
    bad = leaking_flights(table, manifest, list(manifest["flight"]))
    assert set(bad) == set(EMR)
    assert {"roll_cmd", "pitch_cmd"} <= set(next(iter(bad.values())))
    no_emr = manifest.loc[~manifest["emergency_trajectory"], "flight"].tolist()
    assert leaking_flights(table, manifest, no_emr) == {}
    assert "engine (emr)" in leakage_markdown(table)
