"""Flight logs as a corpus (alfa_bench/logs): each format read through its map, a folder
of logs with a labels.csv converted into flights, bad labels and logs left out and named,
and the synthetic flights round-tripped through MAVLink logs."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from unavailable import require_module, unavailable

from alfa_bench.data import SIGNALS, build_manifest, load_flight, sample, scan_flights
from alfa_bench.logs.corpus import CorpusError, convert_corpus, read_labels, read_log
from alfa_bench.workflow.corpus import corpus_config, not_applicable

SHARED_LOGS = Path(__file__).resolve().parents[2] / "shared" / "logs"


def _shared(name: str) -> Path:
    path = SHARED_LOGS / name
    if not path.is_file():
        unavailable(f"{path} (the readers' real logs, ../shared/logs) is not here")
    return path


@pytest.fixture(scope="module")
def tlogs(corpus, corpus_manifest, tmp_path_factory) -> Path:
    """The synthetic flights as .tlog logs, with a labels.csv from their manifest."""
    require_module("pymavlink")
    from alfa_bench.live import replay

    folder = tmp_path_factory.mktemp("tlogs")
    rows = []
    for r in corpus_manifest.itertuples():
        replay.write_tlog(load_flight(corpus / r.flight), folder / f"{r.flight}.tlog")
        fault = "" if r.fault_class == "none" else r.fault_class
        rows.append({"log": f"{r.flight}.tlog", "fault": fault,
                     "onset_s": repr(r.onset_s) if fault else "", "group": r.date,
                     "emergency_trajectory": str(r.emergency_trajectory).lower()})
    pd.DataFrame(rows).to_csv(folder / "labels.csv", index=False)
    return folder


@pytest.fixture(scope="module")
def converted(tlogs, tmp_path_factory):
    return convert_corpus(tlogs, tmp_path_factory.mktemp("converted"))


#: what the MAVLink link keeps of a value: float32 fields, and the integer fields' units
QUANTUM = {"yaw_cmd": 1.0, "yaw_error": 1.0, "rel_alt": 1e-3, "nav_vel_north": 1e-2,
           "nav_vel_east": 1e-2, "nav_vel_down": 1e-2, "throttle": 1e-2,
           **dict.fromkeys(["servo_elevator", "servo_throttle", "servo_rudder",
                            "servo_aileron_left", "servo_aileron_right"], 1.0)}


def test_the_synthetic_flights_come_back_from_their_tlogs(corpus, converted):
    """Each flight, written as MAVLink and read back: the same fault, onset, date and
    grid, each signal's value within what the link keeps of it (float32, or its
    integer field's unit) wherever the grid steps hold the same record."""
    names = dict(zip(converted.flights["flight"], converted.flights["log"], strict=True))
    assert len(names) == 6 and converted.left_out.empty
    assert converted.signals["airspeed_cmd"] is not None     # no MAVLink field gives it
    for flight, log in names.items():
        a = load_flight(corpus / log.removesuffix(".tlog"))
        b = load_flight(converted.processed / flight)
        assert b.date == a.date and b.emergency_trajectory == a.emergency_trajectory
        assert (b.fault is None) == (a.fault is None)
        if a.fault is not None and a.fault.onset_s is not None:
            assert b.fault.fault_class == a.fault.fault_class
            assert b.fault.onset_s == pytest.approx(a.fault.onset_s, abs=1e-6)
        sa, sb = sample(a, converted.has, 20.0), sample(b, converted.has, 20.0)
        np.testing.assert_array_equal(sa.t, sb.t)
        for j, name in enumerate(converted.has):
            x, y = sa.x[:, j], sb.x[:, j]
            # a row on the grid step itself moves across it by the log's 1 µs stamps
            same = (x == np.roll(x, 1)) & (x == np.roll(x, -1))
            tol = QUANTUM.get(name, 0.0) + 1e-6 * np.abs(x) + 1e-9
            assert np.all(np.abs(x - y)[same] <= tol[same]), name


def test_the_converted_flights_pass_the_data_checks(converted):
    manifest, failures = scan_flights(converted.processed, signals=converted.has)
    assert failures.empty and len(manifest) == 6
    assert set(manifest["subsets"].str.split(";").explode()) == {"all", "no_emr", "emr"}
    assert manifest["flight"].str.startswith("log_").all()


def test_a_log_is_converted_once(tlogs, tmp_path):
    out = tmp_path / "out"
    first = convert_corpus(tlogs, out)
    stamps = {p: p.stat().st_mtime_ns for p in out.glob("processed/*/*.csv")}
    again = convert_corpus(tlogs, out)
    assert {p: p.stat().st_mtime_ns for p in out.glob("processed/*/*.csv")} == stamps
    assert again.flights.equals(first.flights)


def test_a_changed_label_converts_its_log_again(tlogs, tmp_path):
    folder = tmp_path / "logs"
    shutil.copytree(tlogs, folder)
    out = tmp_path / "out"
    convert_corpus(folder, out)
    labels = pd.read_csv(folder / "labels.csv", dtype=str, keep_default_na=False)
    labels.loc[0, "onset_s"] = "40.0"
    labels.to_csv(folder / "labels.csv", index=False)
    corpus = convert_corpus(folder, out)
    flight = load_flight(corpus.processed / corpus.flights["flight"].iloc[0])
    assert flight.fault.onset_s == pytest.approx(40.0)


def test_bad_labels_and_logs_are_left_out_and_named(tlogs, tmp_path):
    folder = tmp_path / "logs"
    shutil.copytree(tlogs, folder)
    labels = pd.read_csv(folder / "labels.csv", dtype=str, keep_default_na=False)
    good = labels.iloc[1].to_dict()
    (folder / "broken.tlog").write_bytes(b"\xfe" * 300)
    (folder / "notes.txt").write_text("not a log")
    bad = pd.DataFrame([
        {**good, "log": "missing.tlog"},
        {**labels.iloc[0].to_dict(), "onset_s": "soon"},
        {**labels.iloc[0].to_dict(), "log": labels.iloc[2]["log"], "onset_s": "9999"},
        {**good, "log": labels.iloc[3]["log"], "fault": "Bad Class"},
        {**good, "log": labels.iloc[4]["log"], "group": "a/b"},
        {**good, "log": "broken.tlog"},
        {**good, "log": "notes.txt"},
    ])
    pd.concat([labels.iloc[[5]], bad]).to_csv(folder / "labels.csv", index=False)
    corpus = convert_corpus(folder, tmp_path / "out")
    assert list(corpus.flights["log"]) == [labels.iloc[5]["log"]]
    left = corpus.left_out.set_index("line")
    assert list(left.index) == [3, 4, 6, 7, 5, 8, 9]
    assert list(left["field"]) == ["log", "onset_s", "fault", "group", "onset_s", "log", "log"]
    assert "no such file" in left.at[3, "error"] and "'soon'" in left.at[4, "error"]
    assert "outside the log" in left.at[5, "error"]
    assert "not a log format" in left.at[9, "error"]
    assert (tmp_path / "out" / "left_out.csv").is_file()


def test_labels_without_their_columns_stop(tmp_path):
    with pytest.raises(CorpusError, match="no labels.csv"):
        read_labels(tmp_path)
    (tmp_path / "labels.csv").write_text("log,fault\nx.tlog,\n")
    with pytest.raises(CorpusError, match="no column 'onset_s', 'group'"):
        read_labels(tmp_path)


def test_a_run_reading_a_signal_the_corpus_lacks_is_not_applicable(converted):
    from alfa_bench.config import load_config

    methods = {k: v for k, v in load_config()["methods"].items() if k in ("okid_bank", "silent")}
    out = not_applicable(methods, converted.signals)
    assert list(out) == ["okid_bank"] and out["okid_bank"].startswith("airspeed_cmd (no MAVLink")


def test_the_config_of_a_corpus_names_only_runs_it_runs(converted):
    from alfa_bench.config import load_config

    config = load_config()
    corpus_config(config, converted.signals, emr=False)
    runs = set(config["methods"])
    assert config["not_applicable"] and not runs & set(config["not_applicable"])
    assert set(config["stability"]["refit"]["runs"]) <= runs
    assert {s["run"] for s in config["public_study"]["steps"]} <= runs
    assert all(v in runs for row in config["features_learners"]
               for k, v in row.items() if k != "learner")
    assert "icra22" not in config["subsets"] and "emr" not in config["subsets"]


@pytest.mark.parametrize("name", ["sample.ulg", "sample_appended_multiple.ulg",
                                  "sample_log_small.ulg",
                                  "sample_logging_tagged_and_default_params.ulg",
                                  "sample_px4_events.ulg"])
def test_px4_ulogs_read_through_their_map(name):
    require_module("pyulog")
    records = read_log(_shared(f"px4/{name}"))
    assert records.format == "ulog"
    for signal in ("roll", "pitch", "yaw", "roll_cmd", "roll_rate", "accel_x", "vel_up"):
        t, v = records.records[signal]
        assert t.size > 10 and np.all(np.diff(t) > 0) and np.all(np.isfinite(v))
        lo, hi = SIGNALS[signal].bounds
        assert np.all((v >= lo) & (v <= hi)), signal
    # a multicopter: no energy controller, and no output is one of ALFA's servos
    assert "tecs_status" in records.not_given["altitude_error"]
    assert "mixer" in records.not_given["servo_elevator"]


def test_px4_attitude_agrees_with_its_own_rates():
    """Roll from the quaternion moves as the gyro's roll rate integrates (the sign and
    axis of the map): over sample.ulg's manoeuvres the two agree in direction."""
    require_module("pyulog")
    records = read_log(_shared("px4/sample.ulg"))
    t, roll = records.records["roll"]
    tr, rate = records.records["roll_rate"]
    step = np.diff(roll)
    mid = t[:-1] + np.diff(t) / 2
    predicted = np.interp(mid, tr, np.degrees(rate)) * np.diff(t)
    moving = np.abs(step) > 0.05
    assert np.mean(np.sign(step[moving]) == np.sign(predicted[moving])) > 0.8


def test_the_ardupilot_dataflash_log_reads_through_its_map():
    require_module("pymavlink")
    records = read_log(_shared("ardupilot/test.BIN"))
    assert records.format == "dataflash"
    assert records.utc_start_s is not None                       # from its GPS fix
    t, roll = records.records["roll"]
    assert t.size == 24 and np.all(np.abs(roll) < 90)
    # NavRoll is the roll the plane controller commands; the servo outputs are actuators
    assert records.records["roll_cmd"][1].size == 23
    assert SIGNALS["servo_elevator"].kind == "actuator"
    assert "servo_elevator" in records.records
    assert "airspeed_cmd" in records.not_given


def test_a_ulog_corpus_has_the_signals_every_log_gives(tmp_path):
    require_module("pyulog")
    folder = tmp_path / "logs"
    folder.mkdir()
    names = ["sample.ulg", "sample_px4_events.ulg"]
    for name in names:
        shutil.copy(_shared(f"px4/{name}"), folder / name)
    pd.DataFrame({"log": names, "fault": ["", ""], "onset_s": ["", ""],
                  "group": ["a", "b"]}).to_csv(folder / "labels.csv", index=False)
    corpus = convert_corpus(folder, tmp_path / "out")
    assert corpus.left_out.empty and len(corpus.flights) == 2
    # sample_px4_events.ulg logs no actuator_controls_0: the corpus has no throttle
    assert "1 of 2 logs" in corpus.signals["throttle"]
    manifest = build_manifest(corpus.processed, signals=corpus.has)
    assert list(manifest["date"]) == ["a", "b"] and (manifest["fault_class"] == "none").all()


def test_the_guide_tabulates_every_entry_of_each_map():
    """docs/own-flights.md lists each entry of the DataFlash and ULog maps, and each
    signal they cannot give, as the code has them."""
    from alfa_bench.logs import dataflash, ulog

    text = (Path(__file__).resolve().parents[1] / "docs/own-flights.md").read_text()
    for module in (dataflash, ulog):
        for e in module.MAP:
            fields = ", ".join(f"`{f}`" for f in e.fields)
            row = (f"| `{e.message}` | {fields} | {e.how} | `{e.signal}` | "
                   f"{SIGNALS[e.signal].kind} |")
            assert row in text, row
        for signal, why in module.NOT_GIVEN.items():
            assert f"| `{signal}` | {why} |" in text, signal


def test_the_python_route_reads_a_converted_corpus(converted, tmp_path):
    import alfa_bench as ab

    corpus = ab.load_corpus(converted.processed.parent, cache=tmp_path / "cache")
    assert corpus.failures.empty and len(corpus.flights) == 6


def test_the_tlog_entries_convert_as_the_monitors_map():
    from alfa_bench.live import mavlink
    from alfa_bench.logs import tlog

    fields = {"direction": 200.0, "speed": 4.0, **{f.field: 3.5 for f in
                                                    mavlink.FIELDS.values()}}
    for e in tlog.MAP:
        decoded = mavlink.decode(e.message, fields.__getitem__)
        got = float(e.convert(*(np.asarray(fields[f]) for f in e.fields)))
        assert got == pytest.approx(decoded[e.signal]), e.signal
