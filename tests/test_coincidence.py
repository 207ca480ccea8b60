"""The coincidence detector and the nested selection on synthetic flights with known
faults: a synthetic energy loss is found within the designed delay and never before,
and the inner leave-one-date-out chooses the candidate that gets its held-out flights
right."""

import numpy as np
import pytest

from alfa_bench.data import load_flight
from alfa_bench.data.synthetic import write_flight
from alfa_bench.methods import (
    fault_free_segments,
    labelled_segments,
    make_detector,
    run_detector,
)

#: the energy signatures the synthetic engine loss writes (its pitch is not modelled)
ENERGY = {"engine": ["accel_x_drop", "energy_rate_drop", "climb_rate_drop"],
          "side": ["accel_y_shift"]}
DATES = ("2018-07-18", "2018-07-30", "2018-09-11", "2018-10-05")


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """Per date two fault-free flights, an engine failure and a stuck rudder."""
    processed = tmp_path_factory.mktemp("fleet") / "processed"
    flights, seed = [], 10
    for i, date in enumerate(DATES):
        for part, kw in ((1, {}), (2, {}),
                         (3, dict(onset_s=50.0 + 5 * i)),
                         (4, dict(onset_s=55.0, fault_topic="failure_status-rudder", code=2))):
            label = ("no_failure" if not kw else "engine_failure" if "fault_topic" not in kw
                     else "rudder_left_failure")
            name = f"carbonZ_{date}-1{i}-00-00_{part}_{label}"
            flights.append(load_flight(write_flight(processed, name, seed=seed, **kw)))
            seed += 1
    return flights


def test_a_synthetic_energy_loss_alarms_the_engine_channel_within_its_windows(fleet):
    """With a budget of one fault-free flight in a hundred, so that the test does not
    hang on the 10 % it would otherwise allow."""
    det = make_detector("coincidence", {"signatures": ENERGY, "false_alarm": 0.01})
    scored = [f for f in fleet if "2018-09-11" in f.id]
    det.fit(fault_free_segments(det, [f for f in fleet if f not in scored], margin_s=1.0))
    assert set(det.scale_) == {f for fs in ENERGY.values() for f in fs}
    for flight in scored:
        trace = run_detector(det, flight)
        first = trace.first_alarm_s()
        if flight.fault.onset_s is None:
            assert first is None, flight.id
            continue
        onset = flight.fault.onset_s
        channel = "engine" if flight.fault.fault_class == "engine" else "side"
        c = trace.channels.index(channel)
        assert first is not None and onset <= first <= onset + 2.5, (flight.id, first)
        assert trace.first_alarm_s(c) == first                     # its own channel first


def test_a_channel_needs_every_signature_at_once(fleet):
    """The engine channel is the least of its scaled features: a lateral step alone,
    which moves one of them a lot, leaves it down."""
    det = make_detector("coincidence", {"signatures": {"engine": ["accel_x_drop",
                                                                  "accel_y_shift"]},
                                        "false_alarm": 0.01})
    rudder = next(f for f in fleet if "rudder" in f.id)
    det.fit(fault_free_segments(det, [f for f in fleet if f is not rudder], margin_s=1.0))
    trace = run_detector(det, rudder, probes=True)
    after = trace.t >= rudder.fault.onset_s
    assert np.nanmax(trace.probes["engine/accel_y_shift"][after]) > trace.threshold[0]
    assert not trace.alarm[after].any()


def test_nested_selection_chooses_the_candidate_its_held_out_flights_favour(fleet):
    """An engine channel on a roll feature misses every engine loss; the inner
    leave-one-date-out sees it on the training dates and keeps the energy signatures,
    though the blind candidate comes first (a tie would keep it)."""
    blind = {"engine": ["roll_asymmetry"], "side": ["accel_y_shift"]}
    det = make_detector("nested_selection", {
        "detector": "coincidence", "params": {"false_alarm": 0.01},
        "grid": {"signatures": [blind, ENERGY]}})
    training = [f for f in fleet if "2018-10-05" not in f.id]
    det.fit(labelled_segments(det, training))
    record = det.fitted()
    assert det.chosen_ == record["chosen"] == {"signatures": ENERGY}
    assert record["candidates"] == 2
    missed, found = record["inner"]
    assert missed["scored"] == found["scored"] == 12               # three dates of four
    assert found["right"] > missed["right"]
    held = next(f for f in fleet if "2018-10-05" in f.id and "engine" in f.id)
    assert run_detector(det, held).first_alarm_s() is not None


def test_nested_selection_refuses_a_grid_that_reshapes_the_detector(fleet):
    det = make_detector("nested_selection", {
        "detector": "coincidence",
        "grid": {"signatures": [ENERGY, {"engine": ["accel_x_drop"]}]}})
    with pytest.raises(ValueError, match="may only tune"):
        det.fit(labelled_segments(det, fleet))
