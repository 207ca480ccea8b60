"""A sensor that is not measured on a flight (constant over all of it) is never modelled,
never alarmed on and never injected into; a constant command is not missing data. Its
channels are not scored until it moves, a causal rule the batch run and the live monitor
share."""

from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from alfa_bench.data import AlfaDataError, build_manifest, load_flight, not_measured
from alfa_bench.data.inject import inject_grid, inject_sensor_fault
from alfa_bench.data.synthetic import write_flight
from alfa_bench.live import replay
from alfa_bench.live.monitor import Monitor
from alfa_bench.methods import (
    UnmovedSensors,
    fault_free_segments,
    make_detector,
    run_detector,
    skipped_channels,
)

FREE = "carbonZ_2018-09-11-14-16-55_no_failure"
BANK = {"inputs": ["roll_cmd", "pitch_cmd"], "outputs": ["roll", "airspeed"]}


def kill(folder: Path, topic: str, column: str, value: str = "0.0",
         rows_dead: int | None = None) -> None:
    """Set ``column`` of ``topic`` to ``value`` in every row (or its first ``rows_dead``),
    as ALFA's dead airspeed."""
    path = folder / f"{folder.name}-{topic}.csv"
    lines = path.read_text().splitlines()
    i = lines[0].split(",").index(column)
    dead = len(lines) if rows_dead is None else rows_dead
    rows = [",".join(c if j != i or r >= dead else value
                     for j, c in enumerate(line.split(",")))
            for r, line in enumerate(lines[1:])]
    path.write_text("\n".join([lines[0], *rows]) + "\n")


@pytest.fixture
def dead_airspeed(tmp_path):
    folder = write_flight(tmp_path / "processed", FREE, seed=7)
    kill(folder, "mavros-nav_info-airspeed", "field.measured")
    return folder


def test_a_constant_sensor_is_not_measured_but_a_constant_command_is_fine(dead_airspeed):
    kill(dead_airspeed, "mavros-nav_info-airspeed", "field.commanded", "15.0")
    flight = load_flight(dead_airspeed)
    assert not_measured(flight) == ("airspeed",)
    assert build_manifest(dead_airspeed.parent)["not_measured"].tolist() == ["airspeed"]


def test_its_channel_is_skipped_and_the_others_still_judge(dead_airspeed, corpus):
    detector = make_detector("kalman_okid", BANK)
    detector.fit(fault_free_segments(detector, [load_flight(p) for p in corpus.iterdir()], 1.0))
    trace = run_detector(detector, load_flight(dead_airspeed))
    assert trace.skipped == {"airspeed": "airspeed not measured"}
    assert np.isnan(trace.score[:, 1]).all() and not trace.alarm[:, 1].any()
    assert np.isfinite(trace.score[:, 0]).any()


def _monitor_scores(detector, flight) -> np.ndarray:
    """The live monitor's scores on ``flight`` fed through the MAVLink map."""
    decisions = []
    monitor = Monitor(detector, on_decision=decisions.append)
    for t, message, values in replay.messages(flight, detector.signals()):
        monitor.feed(t, message, values)
    return np.array([[d.scores[c] for c in detector.channels()] for d in decisions])


@pytest.mark.parametrize("rows_dead", [None, 800])
def test_a_sensor_unmoved_since_arming_is_not_scored_until_it_moves_live_as_in_batch(
        rows_dead, tmp_path, corpus):
    """Dead all flight, or for its first half: the batch run cannot know which while it
    is unmoved, and the monitor, fed the same flight, leaves the same steps unscored."""
    folder = write_flight(tmp_path / "processed", FREE, seed=7)
    kill(folder, "mavros-nav_info-airspeed", "field.measured", "0.0", rows_dead)
    detector = make_detector("kalman_okid", BANK)
    detector.fit(fault_free_segments(detector, [load_flight(p) for p in corpus.iterdir()], 1.0))
    flight = load_flight(folder)
    trace = run_detector(detector, flight)
    blank = np.isnan(trace.score[:, 1])
    assert blank[0] and np.isfinite(trace.score[:, 0]).any()
    if rows_dead is None:
        assert blank.all() and trace.skipped == {"airspeed": "airspeed not measured"}
    else:       # moving from about 40 s: scored from then on
        moved = trace.t >= flight.topic("mavros-nav_info-airspeed").t[rows_dead]
        assert blank.tolist() == (~moved).tolist() and not trace.skipped
    live = _monitor_scores(detector, flight)
    n = min(len(live), len(trace.t))
    assert n >= len(trace.t) - 1
    np.testing.assert_array_equal(np.isnan(live[:n]), np.isnan(trace.score[:n]))


def test_a_dead_input_skips_every_channel(dead_airspeed, corpus):
    detector = make_detector("kalman_okid", {"inputs": ["roll_cmd", "airspeed"],
                                             "outputs": ["roll", "pitch"]})
    detector.fit(fault_free_segments(detector, [load_flight(p) for p in corpus.iterdir()], 1.0))
    trace = run_detector(detector, load_flight(dead_airspeed))
    assert set(trace.skipped) == {"roll", "pitch"} and not trace.alarm.any()


def test_the_rule_reads_a_detectors_layout_once_however_many_sensors(monkeypatch):
    """A nested selection builds its base detector each time it is asked its signals,
    outputs or channels, and every flight of every fit's calibration starts the rule:
    it asks each once, and says what skipped_channels says."""
    detector = make_detector("nested_selection", {
        "detector": "kalman_okid", "params": BANK, "grid": {"false_alarm": [0.05, 0.1]}})
    signals = detector.signals()
    dead = [n for n in signals if n in ("roll", "airspeed")]
    expected = skipped_channels(detector, dead)
    asked = Counter()

    def counted(name):
        method = getattr(detector, name)
        return lambda: (asked.update([name]), method())[1]

    for name in ("signals", "channel_outputs", "channels"):
        monkeypatch.setattr(detector, name, counted(name))
    unmoved = UnmovedSensors(detector)
    x = np.ones((4, len(signals)))
    x[1:, [i for i, n in enumerate(signals) if n not in dead]] += 1.0   # commands move
    unmoved.blanked(x)
    assert len(unmoved.names) == 2 and unmoved.skipped() == expected and expected
    assert asked == {"signals": 1, "channel_outputs": 1, "channels": 1}


def test_calibration_leaves_the_flight_out(dead_airspeed):
    detector = make_detector("kalman_okid", BANK)
    assert fault_free_segments(detector, [load_flight(dead_airspeed)], 1.0) == []
    honest = make_detector("kalman_okid", {})          # roll and pitch only: it is used
    assert len(fault_free_segments(honest, [load_flight(dead_airspeed)], 1.0)) == 1


def test_no_fault_is_injected_into_it(dead_airspeed, tmp_path):
    with pytest.raises(AlfaDataError, match="not measured") as err:
        inject_sensor_fault(dead_airspeed, tmp_path / "out", "airspeed", "drift", 0.5, 40.0)
    assert err.value.column == "field.measured"
    manifest = build_manifest(dead_airspeed.parent)
    written, skipped = inject_grid(dead_airspeed.parent, manifest, tmp_path / "grid",
                                   ["airspeed", "roll"], [{"kind": "drift", "magnitude": 0.5}],
                                   [0.5])
    assert [p.name.split("_sensor_")[1].split("_")[0] for p in written] == ["roll"]
    assert skipped == [{"flight": FREE, "sensor": "airspeed",
                        "reason": "not measured (constant over the flight)"}]
