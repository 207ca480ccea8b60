"""Rerun recordings: read back with rerun's own reader."""


import numpy as np
import pytest
import rerun.blueprint as rrb
import rerun.chunk as rc
from recordings import content

from alfa_bench.data import load_flight, series
from alfa_bench.methods import make_detector, run_detector
from alfa_bench.outputs.provenance import read_provenance
from alfa_bench.outputs.rerun_log import (
    TIMELINE,
    blueprint,
    write_flight_part,
    write_rerun_log,
    write_run_part,
)

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
    assert rows["/methods/rls/scores/0"] == armed
    assert rows["/methods/rls/scores/threshold"] == 2
    # probes finite at the same steps share an entity, one scalar each
    sets = {}
    for name, v in trace.probes.items():
        sets.setdefault(np.isfinite(v).tobytes(), []).append(name)
    assert len(sets) < len(trace.probes)
    for k, names in enumerate(sets.values()):
        assert rows[f"/methods/rls/probes/{k}"] == int(
            np.isfinite(trace.probes[names[0]]).sum())
    assert {e for e in rows if e.startswith("/methods/rls/probes/")} == {
        f"/methods/rls/probes/{k}" for k in range(len(sets))}
    names = {}
    for chunk in reader.store().stream().to_chunks():
        batch = chunk.to_record_batch()
        for f in batch.schema:
            if chunk.is_static and f.name.endswith(":names"):
                names[chunk.entity_path] = batch.column(f.name).to_pylist()[0]
    assert [names[f"/methods/rls/probes/{k}"] for k in range(len(sets))] == list(sets.values())
    assert rows["/overview/rls"] == armed
    assert rows["/overview/fault"] == 2            # the bar from onset to the fault's end
    alarms = len(trace.alarm_intervals())
    assert rows["/events"] == 2 + alarms        # onset, end, one per alarm


def _rows(path) -> dict[tuple[str, bool], int]:
    """Rows per entity (and whether static) of a recording file."""
    rows = {}
    for line in rc.RrdReader(path).store().summary().splitlines():
        entity, n, static = line.split()[:3]
        rows[entity, static == "static=True"] = int(n.removeprefix("rows="))
    return rows


def test_a_flights_parts_hold_its_whole_recording(recording, tmp_path):
    """The flight's part and each run's, written apart (as the workflow does, so that
    a changed run rewrites its own), are one recording for the viewer: the same id,
    and together the entities and rows of the recording written whole; the layout is
    the flight's part's alone, and each part carries its own provenance."""
    flight, trace, (whole, _) = recording
    own, run = tmp_path / "flight.rrd", tmp_path / "run.rrd"
    write_flight_part(flight, ["rls"], SIGNALS, own, {"inputs": {"flight": "0" * 64}})
    write_run_part(flight.id, "rls", trace, run, {"inputs": {"run": "1" * 64}})
    readers = [rc.RrdReader(p) for p in (own, run)]
    assert [[e.recording_id for e in r.recordings()] for r in readers] == [[flight.id]] * 2
    assert [len(r.blueprints()) for r in readers] == [1, 0]
    parts = {}
    for path in (own, run):
        for key, n in _rows(path).items():
            parts[key] = parts.get(key, 0) + n
    # one provenance property in each file, where the whole has one
    assert parts.pop(("/__properties/provenance", True)) == 2
    whole_rows = _rows(whole)
    assert whole_rows.pop(("/__properties/provenance", True)) == 1
    assert parts == whole_rows
    assert ("/methods/rls/scores/0", False) in _rows(run)
    assert not any(e.startswith("/signals/") for e, _ in _rows(run))
    assert read_provenance(own) == {"inputs": {"flight": "0" * 64}}
    assert read_provenance(run) == {"inputs": {"run": "1" * 64}}


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
    assert read_provenance(path) == {"inputs": {"a": "0" * 64}}


def test_the_viewer_opens_paused_on_the_fault_with_the_whole_flight_in_view():
    bp = blueprint(["m"], ["attitude"], "engine: carbonZ_x", (50.0, 62.5))
    panel = bp.time_panel
    assert str(panel.play_state).lower().endswith("paused")
    assert TIMELINE in repr(panel.timeline)
    sel = panel.time_selection
    assert (sel.min.value, sel.max.value) == (50_000_000_000, 62_500_000_000)
    views = []

    def walk(node):
        if isinstance(node, rrb.View):
            views.append(node)
        else:
            for child in node.contents:
                walk(child)

    walk(bp.root_container)
    plots = [v for v in views if isinstance(v, rrb.TimeSeriesView)]
    assert len(plots) == 4 and all("VisibleTimeRanges" in v.properties for v in plots)
    assert sum("engine: carbonZ_x" in str(v.name) for v in views) == 3   # signals, overview
    assert blueprint(["m"], ["attitude"]).time_panel.time_selection is None


def test_every_signal_has_a_view_of_its_own_unit():
    from alfa_bench.data import SIGNALS as CATALOGUE
    from alfa_bench.outputs.rerun_log import _GROUPS, signal_group

    assert {signal_group(name) for name in CATALOGUE} <= set(_GROUPS)
