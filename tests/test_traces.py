"""Stored traces: a lossless, byte-stable round trip."""

import numpy as np

from alfa_bench.data import load_flight
from alfa_bench.methods import make_detector, run_detector
from alfa_bench.outputs.provenance import read_provenance
from alfa_bench.outputs.traces import read_trace, read_traces, write_trace


def test_round_trip_keeps_every_value_and_rebuilds_alarms(one_flight, tmp_path):
    trace = run_detector(make_detector("rls_arx_zscore"), load_flight(one_flight),
                         probes=True)
    path = tmp_path / "rls" / "f.npz"
    write_trace(trace, path, {"config": {"a": 1}})
    back = read_trace(path)
    assert read_provenance(path) == {"config": {"a": 1}}
    np.testing.assert_array_equal(back.t, trace.t)
    np.testing.assert_array_equal(back.score, trace.score)
    np.testing.assert_array_equal(back.alarm, trace.alarm)
    np.testing.assert_array_equal(back.threshold, trace.threshold)
    assert back.channels == trace.channels
    assert list(back.probes) == list(trace.probes)
    for name in trace.probes:
        np.testing.assert_array_equal(back.probes[name], trace.probes[name])
    assert set(read_traces([tmp_path / "rls"])) == {("rls", "f")}
    bare = read_trace(path, probes=False)
    assert trace.probes and bare.probes == {}
    np.testing.assert_array_equal(bare.score, trace.score)
    np.testing.assert_array_equal(bare.alarm, trace.alarm)
    assert read_traces([tmp_path / "rls"], probes=False)["rls", "f"].probes == {}


def test_the_same_trace_gives_the_same_bytes(one_flight, tmp_path):
    trace = run_detector(make_detector("rls_arx_zscore"), load_flight(one_flight))
    write_trace(trace, tmp_path / "a.npz", {})
    write_trace(trace, tmp_path / "b.npz", {})
    assert (tmp_path / "a.npz").read_bytes() == (tmp_path / "b.npz").read_bytes()
    assert read_trace(tmp_path / "a.npz").probes == {}


def test_traces_are_read_when_looked_up(one_flight, tmp_path):
    """read_traces lists the traces without reading them, and reads one per lookup."""
    trace = run_detector(make_detector("rls_arx_zscore"), load_flight(one_flight))
    for name in ("f", "g"):
        write_trace(trace, tmp_path / "rls" / f"{name}.npz", {})
    traces = read_traces([tmp_path / "rls"])
    (tmp_path / "rls" / "g.npz").write_bytes(b"not a trace")
    assert len(traces) == 2 and ("rls", "g") in traces
    np.testing.assert_array_equal(traces["rls", "f"].score, trace.score)
    assert traces["rls", "f"] is not traces["rls", "f"]
