"""The sensor-fault injector: the original before onset, the fault exactly from it."""

import numpy as np
import pytest

from alfa_bench.data import load_flight, series
from alfa_bench.data.inject import KINDS, RAMP_S, inject_sensor_fault
from alfa_bench.data.manifest import manifest_row

SOURCE = "carbonZ_2018-07-18-16-37-39_1_no_failure"
ONSET = 40.0


@pytest.fixture
def source(corpus):
    return corpus / SOURCE


@pytest.mark.parametrize("sensor", ["roll", "pitch_rate"])
@pytest.mark.parametrize("kind, magnitude", [
    ("stuck", 0.0), ("zero", 0.0), ("drift", 0.5), ("drift", 0.1), ("scale", 0.5),
    ("scale", 0.9), ("noise", 0.1), ("ramp", 0.5)])
def test_injected_flight_is_the_original_until_onset_and_faulty_from_it(
        source, tmp_path, sensor, kind, magnitude):
    dest = inject_sensor_fault(source, tmp_path / "processed", sensor, kind, magnitude, ONSET)
    original, injected = load_flight(source), load_flight(dest)
    topic = original.topic({"roll": "mavros-nav_info-roll",
                            "pitch_rate": "mavros-imu-data_raw"}[sensor])
    # every other topic byte for byte; the sensor's topic byte for byte before onset
    for f in source.glob("*.csv"):
        new = dest / f.name.replace(SOURCE, dest.name)
        if topic.name not in f.name:
            assert new.read_bytes() == f.read_bytes(), f.name
    t, v = series(original, sensor)
    t_new, v_new = series(injected, sensor)
    before = t < ONSET
    np.testing.assert_array_equal(t_new, t)
    np.testing.assert_array_equal(v_new[before], v[before])
    lines = (source / f"{SOURCE}-{topic.name}.csv").read_text().splitlines()
    new_lines = (dest / f"{dest.name}-{topic.name}.csv").read_text().splitlines()
    n_before = 1 + int(before.sum())
    assert new_lines[:n_before] == lines[:n_before]
    # the fault from the first row at or after onset, as the ground truth says
    after = ~before
    span = v.max() - v.min()
    expected = {"stuck": np.full(after.sum(), v[before][-1]), "zero": np.zeros(after.sum()),
                "drift": v[after] + magnitude * span, "scale": magnitude * v[after],
                "ramp": v[after] + magnitude * span * (t[after] - ONSET) / RAMP_S}
    if kind == "noise":
        residual = v_new[after] - v[after]
        assert abs(residual.std() / (magnitude * span) - 1) < 0.2
    else:
        np.testing.assert_allclose(v_new[after], expected[kind], rtol=1e-12, atol=1e-9)
    fault = injected.fault
    assert (fault.fault_class, fault.sensor, fault.kind, fault.magnitude, fault.source) == (
        "sensor", sensor, kind, magnitude, SOURCE)
    assert fault.onset_s == t[after][0]
    row = manifest_row(injected)
    assert (row["fault_sensor"], row["fault_kind"], row["fault_magnitude"]) == (
        sensor, kind, magnitude)


def test_same_arguments_give_the_same_bytes(source, tmp_path):
    a = inject_sensor_fault(source, tmp_path / "a", "roll", "noise", 0.1, ONSET)
    b = inject_sensor_fault(source, tmp_path / "b", "roll", "noise", 0.1, ONSET)
    assert {f.name: f.read_bytes() for f in a.iterdir()} == {
        f.name: f.read_bytes() for f in b.iterdir()}


def test_only_fault_free_flights_take_an_injection(corpus, tmp_path):
    faulty = next(p for p in corpus.iterdir() if "engine" in p.name)
    with pytest.raises(ValueError, match="fault-free flights only"):
        inject_sensor_fault(faulty, tmp_path, "roll", "drift", 0.5, ONSET)
    with pytest.raises(ValueError, match="kind must be one of"):
        inject_sensor_fault(corpus / SOURCE, tmp_path, "roll", "bias", 0.5, ONSET)
    assert set(KINDS) == {"stuck", "zero", "drift", "scale", "noise", "ramp"}
