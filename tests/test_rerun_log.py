"""Rerun recordings: read back with rerun's own reader."""

import numpy as np
import pytest
import rerun.chunk as rc
from recordings import content

from alfa_bench.analysis.rerun_log import read_rerun_provenance, write_rerun_log
from alfa_bench.data import load_flight, series
from alfa_bench.methods import make_detector, run_detector

SIGNALS = ["roll_cmd", "roll", "roll_error", "roll_rate", "servo_aileron_left"]


@pytest.fixture(scope="module")
def recording(tmp_path_factory, corpus):
    flight = load_flight(next(p for p in sorted(corpus.iterdir()) if "engine" in p.name))
    detector = make_detector("rls_arx_zscore", {"pairs": [
        {"name": "roll", "input": "roll_cmd", "output": "roll"}]})
    traces = {"rls": run_detector(detector, flight, probes=True)}
    paths = [tmp_path_factory.mktemp("rrd") / f"{flight.id}.rrd" for _ in range(2)]
    for path in paths:
        write_rerun_log(flight, traces, SIGNALS, path, {"inputs": {"a": "0" * 64}})
    return flight, traces["rls"], paths


def test_the_recording_holds_signals_scores_probes_and_events(recording):
    flight, trace, (path, _) = recording
    reader = rc.RrdReader(path)
    (entry,) = reader.recordings()
    assert entry.recording_id == flight.id
    assert len(reader.blueprints()) == 1
    rows = {}
    for line in reader.store().summary().splitlines():
        entity, n, static = line.split()[:3]
        if static == "static=False":
            rows[entity] = int(n.removeprefix("rows="))
    for s in SIGNALS:
        (entity,) = [e for e in rows if e.startswith("/signals/") and e.endswith(f"/{s}")]
        assert rows[entity] == series(flight, s)[0].size
    armed = int(np.isfinite(trace.score[:, 0]).sum())
    assert armed > 0
    assert rows["/methods/rls/scores/roll/score"] == armed
    assert rows["/methods/rls/scores/roll/threshold"] == 2
    assert rows["/methods/rls/probes/roll/residual"] == int(
        np.isfinite(trace.probes["roll/residual"]).sum())
    assert rows["/overview/rls"] == armed
    alarms = len(trace.alarm_intervals())
    assert rows["/events"] == 2 + alarms        # onset, end, one per alarm


def test_the_fault_and_flight_are_recording_properties(recording):
    flight, _, (path, _) = recording
    store = rc.RrdReader(path).store()
    props = [c for c in store.stream().to_chunks() if c.entity_path == "/__properties/flight"]
    values = {f.name: props[0].to_record_batch().column(f.name).to_pylist()[0]
              for f in props[0].to_record_batch().schema if f.name in ("fault_class", "onset_s")}
    assert values["fault_class"] == [flight.fault.fault_class]
    assert values["onset_s"] == [pytest.approx(flight.fault.onset_s)]


def test_the_same_run_writes_the_same_content(recording):
    _, _, (a, b) = recording
    assert content(a) == content(b)


def test_the_recording_carries_its_provenance(recording):
    _, _, (path, _) = recording
    assert read_rerun_provenance(path) == {"inputs": {"a": "0" * 64}}
