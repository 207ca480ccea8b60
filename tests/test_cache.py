"""The parsed-flight cache and the injected flights built in memory give exactly what
parsing the CSVs gives: every array, frame, clock, fault and repair."""

import numpy as np
import pandas as pd
import pytest

from alfa_bench.data import (
    SIGNALS,
    AlfaDataError,
    StaleCacheError,
    build_manifest,
    load_flight,
    read_cached,
)
from alfa_bench.data.cache import write_cached
from alfa_bench.data.inject import (
    KINDS,
    InjectedGrid,
    grid_specs,
    inject_flight,
    inject_sensor_fault,
    injected_sha256,
)
from alfa_bench.data.manifest import flight_sha256
from alfa_bench.methods import make_detector, run_detector

SOURCE = "carbonZ_2018-07-18-16-37-39_1_no_failure"


def assert_same_flight(a, b):
    assert (a.id, a.path, a.date, a.label, a.emergency_trajectory, a.t0_ns, a.duration_s,
            a.fault, a.repairs) == (b.id, b.path, b.date, b.label, b.emergency_trajectory,
                                    b.t0_ns, b.duration_s, b.fault, b.repairs)
    assert list(a.topics) == list(b.topics)
    for name, x in a.topics.items():
        y = b.topics[name]
        assert (x.flight, x.name, x.file) == (y.flight, y.name, y.file)
        assert x.t.dtype == y.t.dtype and np.array_equal(x.t, y.t), name
        assert np.array_equal(x.lines, y.lines), name
        pd.testing.assert_frame_equal(x.frame, y.frame, check_exact=True)
        for column in y.frame.columns:
            assert_same_values(x, y, column)


def assert_same_values(x, y, column):
    """values() gives the same numbers, or the same error, for the cached topic ``x``
    (which hands out numbers without building its frame) and the parsed one ``y``."""
    try:
        expected = y.values(column)
    except AlfaDataError as e:
        with pytest.raises(AlfaDataError) as got:
            x.values(column)
        assert str(got.value) == str(e)
        return
    v = x.values(column)
    assert v.dtype == np.float64 and not v.flags.writeable
    assert np.array_equal(v, expected), (x.name, column)


def test_a_cached_flight_is_the_parsed_flight(corpus, tmp_path):
    for folder in sorted(corpus.iterdir()):
        flight = load_flight(folder)
        write_cached(flight, tmp_path / f"{flight.id}.npz", flight_sha256(folder))
        assert_same_flight(read_cached(tmp_path / f"{flight.id}.npz", flight_sha256(folder)),
                           flight)


def test_repairs_and_text_columns_survive_the_cache(corpus, tmp_path):
    """A flight with repaired rows and a text column with missing cells."""
    folder = tmp_path / "processed" / SOURCE
    folder.mkdir(parents=True)
    for f in (corpus / SOURCE).iterdir():
        (folder / f.name).write_bytes(f.read_bytes())
    roll = folder / f"{SOURCE}-mavros-nav_info-roll.csv"
    lines = roll.read_text().splitlines()
    lines.insert(5, lines[5])                                   # a repeated %time
    roll.write_text("\n".join(lines))                          # no final newline
    times = [line.split(",")[0] for line in lines[1:6]]
    modes = ["AUTO", "", "AUTO", "MANUAL", "AUTO"]                # a missing text cell
    counts = ["1", "2", "", "4", "5"]                             # a missing number
    (folder / f"{SOURCE}-mavros-state.csv").write_text(
        "%time,field.mode,field.armed,field.count\n" + "".join(
            f"{t},{m},True,{c}\n" for t, m, c in zip(times, modes, counts, strict=True)))
    flight = load_flight(folder)
    with pytest.raises(AlfaDataError, match="empty or NaN cell"):
        flight.topic("mavros-state").values("field.count")
    assert len(flight.repairs) == 2
    state = flight.topic("mavros-state").frame
    assert state["field.mode"].isna().sum() == 1 and state["field.armed"].dtype == bool
    write_cached(flight, tmp_path / "c.npz", "0" * 64)
    assert_same_flight(read_cached(tmp_path / "c.npz"), flight)


def test_a_stale_cache_is_refused(corpus, tmp_path):
    flight = load_flight(corpus / SOURCE)
    write_cached(flight, tmp_path / "c.npz", "a" * 64)
    with pytest.raises(StaleCacheError, match="re-run the manifest rule"):
        read_cached(tmp_path / "c.npz", "b" * 64)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("sensor", ["roll", "pitch_rate"])
def test_an_injected_flight_in_memory_is_its_csv_copy_read_back(corpus, tmp_path, kind,
                                                                 sensor):
    source = load_flight(corpus / SOURCE)
    topics = {s.topic for s in SIGNALS.values()}
    spec = (sensor, kind, 0.25, 40.0)
    written = load_flight(inject_sensor_fault(source, tmp_path, *spec, topics=topics))
    built = inject_flight(source, tmp_path, *spec, topics=topics)
    assert_same_flight(built, written)
    detector = make_detector("rls_arx_zscore", {"pairs": [
        {"name": "roll", "input": "roll_cmd", "output": "roll"}]})
    a, b = run_detector(detector, built), run_detector(detector, written)
    assert np.array_equal(a.score, b.score, equal_nan=True)


@pytest.mark.parametrize("sensor", ["pitch", "pitch_rate"])
def test_an_injected_flight_without_the_first_topic_is_retimed_as_read_back(corpus, tmp_path,
                                                                           sensor):
    """Left without the topic that starts the source's clock, the flight starts later:
    every time moves, as reading the written files moves it."""
    source = load_flight(corpus / SOURCE)
    earliest = min(source.topics, key=lambda t: float(source.topics[t].t[0]))
    topics = {"mavros-nav_info-pitch", "mavros-imu-data"}
    assert earliest not in topics
    spec = (sensor, "drift", 0.5, 40.0)
    written = load_flight(inject_sensor_fault(source, tmp_path, *spec, topics=topics))
    built = inject_flight(source, tmp_path, *spec, topics=topics)
    assert built.t0_ns != source.t0_ns
    assert_same_flight(built, written)


def test_the_grid_builds_each_flight_when_looked_up_and_keeps_none(corpus, tmp_path):
    """Names and checksums come from the specs alone; a lookup builds the flight that
    inject_flight builds, afresh each time (a large grid is never held in memory)."""
    manifest = build_manifest(corpus)
    free = manifest.loc[manifest["fault_class"] == "none", "flight"]
    sources = {name: load_flight(corpus / name) for name in free}
    faults = [{"kind": "drift", "magnitude": 0.5}, {"kind": "stuck", "magnitude": 0.0}]
    grid = InjectedGrid(sources, manifest, tmp_path, ["roll", "pitch"], faults, [0.4])
    specs, skipped = grid_specs(sources, manifest, ["roll", "pitch"], faults, [0.4])
    assert len(grid) == len(specs) == 4 * len(free) and grid.skipped == skipped
    sha = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
    assert sorted(grid.sha256.values()) == sorted(
        injected_sha256(sha[s["source"]], s["sensor"], s["kind"], s["magnitude"],
                        s["onset_s"]) for s in specs)
    name, spec = next(iter(grid.specs.items()))
    topics = {s.topic for s in SIGNALS.values()}
    assert_same_flight(grid[name], inject_flight(
        sources[spec["source"]], tmp_path, spec["sensor"], spec["kind"], spec["magnitude"],
        spec["onset_s"], topics=topics))
    assert grid[name] is not grid[name]
    grid.sources = {}                                   # a lookup now fails, a test not
    assert name in grid and "no such flight" not in grid
    assert list(grid) == list(grid.sha256)
