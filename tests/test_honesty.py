"""Which runs read what ALFA's fault emulation writes, checked at the data itself.

Whether a run reads an ``actuator`` signal follows from its ``signals()``; nobody sets
it. These tests watch every column a run actually reads (fitting included) and fail
when one the emulation writes is read by a run that is not marked, whichever catalogue
name led there.
"""

from pathlib import Path

import pytest
from config_runs import CONFIG, one_run_per

from alfa_bench.data import SIGNALS, Signal, Topic, load_flight, reads_actuators
from alfa_bench.methods import REGISTRY, make_detector, run_detector, training_segments

RUNS = {name: spec for name, spec in CONFIG["methods"].items()}
# the columns a run reads follow from its detector and the signals it names: one of each
READING = one_run_per(lambda spec: (spec["detector"], make_detector(
    spec["detector"], spec.get("params")).signals()))


def actuator_columns() -> set[tuple[str, str]]:
    return {(s.topic, c) for s in SIGNALS.values() if s.kind == "actuator"
            for c in (s.column, s.minus) if c}


def columns_read(detector, corpus: Path, flight: Path, monkeypatch) -> set[tuple[str, str]]:
    """Every (topic, column) ``detector`` reads while it is fitted on the corpus and run
    on ``flight``."""
    seen = set()
    values = Topic.values

    def spy(self, column):
        seen.add((self.name, column))
        return values(self, column)

    monkeypatch.setattr(Topic, "values", spy)
    if detector.calibrated:
        detector.fit(training_segments(
            detector, [load_flight(p) for p in sorted(corpus.iterdir())], margin_s=1.0))
    run_detector(detector, load_flight(flight))
    return seen


def assert_marked_if_reading_actuators(detector, seen) -> None:
    leaked = seen & actuator_columns()
    assert reads_actuators(detector.signals()) == bool(leaked), (
        f"{type(detector).__name__} reads {sorted(leaked) or 'no actuator column'} but is "
        f"marked reads_actuators={reads_actuators(detector.signals())}")


@pytest.mark.slow
@pytest.mark.parametrize("run", READING)
def test_a_run_is_marked_exactly_when_it_reads_an_actuator_column(run, corpus, monkeypatch):
    spec = RUNS[run]
    detector = make_detector(spec["detector"], spec.get("params"))
    flight = corpus / "carbonZ_2018-07-18-15-53-31_1_engine_failure"
    assert_marked_if_reading_actuators(detector, columns_read(detector, corpus, flight,
                                                               monkeypatch))


def test_the_servo_runs_are_marked_and_their_honest_forms_are_not():
    marked = {n for n, spec in RUNS.items()
              if reads_actuators(make_detector(spec["detector"], spec.get("params")).signals())}
    assert {"ffrls_monitor_servo", "okid_bank_servo", "emulation_oracle"} <= marked
    assert not {"ffrls_monitor", "okid_bank", "rls_arx_zscore", "glrt_arx"} & marked


def test_a_servo_column_under_another_name_and_kind_is_still_caught(corpus, monkeypatch):
    """A catalogue entry that reads the throttle channel but calls itself a sensor: the
    run looks honest by its names, and the column-level check must fail it."""
    monkeypatch.setitem(SIGNALS, "sneaky", Signal("mavros-rc-out", "field.channels2", "sensor"))
    detector = REGISTRY["kalman_okid"](inputs=("roll_cmd", "sneaky"), outputs=("roll",))
    flight = corpus / "carbonZ_2018-07-18-15-53-31_1_engine_failure"
    seen = columns_read(detector, corpus, flight, monkeypatch)
    with pytest.raises(AssertionError, match="channels2"):
        assert_marked_if_reading_actuators(detector, seen)


def test_one_quantity_has_one_kind_and_the_emulated_topics_are_actuators():
    kinds: dict[tuple, set[str]] = {}
    for s in SIGNALS.values():
        kinds.setdefault((s.topic, s.column, s.minus), set()).add(s.kind)
    assert all(len(k) == 1 for k in kinds.values()), kinds
    for s in SIGNALS.values():
        if s.topic == "mavros-rc-out" or (s.topic, s.column) == ("mavros-vfr_hud",
                                                                 "field.throttle"):
            assert s.kind == "actuator", s
