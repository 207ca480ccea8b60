"""A fitted detector on MAVLink (alfa_bench/live): a flight replayed as a .tlog, or over
UDP on localhost, gives the monitor the workflow's first alarm within one grid step; a
model reading the fault emulation's signals is refused for a link unless allowed."""

import math
import os
import socket
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from unavailable import unavailable
from workflow_runs import REPO

import alfa_bench as ab
from alfa_bench.data import hold, parse_flight_name, sample
from alfa_bench.live import mavlink, replay
from alfa_bench.live.monitor import Monitor, watch
from alfa_bench.methods import fault_free_segments, make_detector, run_detector

RUNS = ["residual_logistic_published_date", "coincidence", "residual_bank"]

pytest.importorskip("pymavlink")


def _date(name: str) -> str:
    return str(parse_flight_name(name)["date"])


@pytest.fixture(scope="module")
def local(corpus, tmp_path_factory):
    return ab.load_corpus(corpus.parent, cache=tmp_path_factory.mktemp("cache"))


def _batch_first_alarm(detector, flight) -> float | None:
    return run_detector(detector, flight).first_alarm_s()


def _same(live: float | None, batch: float | None, rate_hz: float) -> bool:
    if live is None or batch is None:
        return live is batch
    return abs(live - batch) <= 1.0 / rate_hz + 1e-9


def _tlog_first_alarm(detector, flight, path) -> float | None:
    replay.write_tlog(flight, path, detector.signals())
    monitor = watch(str(path), Monitor(detector))
    if monitor.first_alarm is None:
        return None
    return monitor.first_alarm.t + monitor.origin_s - replay.flight_epoch_s(flight)


def _check_flights(corpus, names, tmp_path) -> list[str]:
    """Per run and flight, the monitor's first alarm on the replayed .tlog against the
    batch run's, the run fitted without the flight's date; the differences, named."""
    wrong = []
    for run in RUNS:
        fits = {}
        for name in names:
            d = _date(name)
            if d not in fits:
                fits[d] = ab.fit_run(run, corpus, [n for n in corpus.flights if _date(n) != d])
            det, flight = fits[d], corpus.flight(name)
            batch = _batch_first_alarm(det, flight)
            live = _tlog_first_alarm(det, flight, tmp_path / f"{run}.tlog")
            if not _same(live, batch, det.rate_hz):
                wrong.append(f"{run} on {name}: monitor {live}, workflow {batch}")
    return wrong


def test_a_replayed_log_gives_the_workflows_first_alarm(local, tmp_path):
    """Every flight of a date, and one of another, each alarming in the batch run or not."""
    names = [n for n in local.flights if _date(n) in ("2018-07-18", "2018-10-05")]
    wrong = _check_flights(local, names, tmp_path)
    assert not wrong, wrong


def test_the_workflows_record_is_the_batch_run_the_monitor_matches(local):
    """The batch first alarm the monitor is held to is the record's: the same fold fit."""
    run = "coincidence"
    result = ab.evaluate(run, local, subsets=["all"])
    for record in result.records:
        d = _date(record["flight"])
        det = ab.fit_run(run, local, [n for n in local.flights if _date(n) != d])
        assert _batch_first_alarm(det, local.flight(record["flight"])) == record[
            "first_alarm_s"]


def test_the_hold_is_the_data_layers(local):
    """The monitor's grid values and freshness are sample()'s, on a flight replayed as
    real MAVLink packets: to float32 rounding, and an int16 field to its unit (cm/s for
    GLOBAL_POSITION_INT's velocities, a degree for nav_bearing), as a link rounds them."""
    from pymavlink.dialects.v20 import ardupilotmega

    det = make_detector("kalman_okid", {"inputs": ["roll_cmd", "yaw_cmd"],
                                        "outputs": ["roll", "nav_vel_north", "nav_vel_down"]})
    flights = [local.flight(n) for n in local.flights]
    det.fit(fault_free_segments(det, flights, 1.0))
    flight = flights[0]
    s = sample(flight, det.signals(), det.rate_hz)
    fed = []
    monitor = Monitor(det)
    update = monitor.detector.update
    monitor.detector.update = lambda x, f: fed.append((x.copy(), f.copy())) or update(x, f)
    parser = ardupilotmega.MAVLink(None)
    for t, packet in replay.packets(flight, det.signals()):
        msg = parser.decode(bytearray(packet))
        if msg.get_type() in mavlink.MESSAGES:
            monitor.feed(t, msg.get_type(),
                         mavlink.decode(msg.get_type(), lambda n, m=msg: getattr(m, n)))
    x = np.array([a for a, _ in fed])[:s.t.size]
    fresh = np.array([b for _, b in fed])[:s.t.size]
    assert x.shape == s.x.shape
    quantum = {"nav_vel_north": 0.01, "nav_vel_east": 0.01, "nav_vel_down": 0.01,
               "yaw_cmd": 1.0, "yaw_error": 1.0}
    for j, name in enumerate(s.names):
        atol = quantum.get(name, 0.0) / 2 + 1e-5
        np.testing.assert_allclose(x[:, j], s.x[:, j], rtol=1e-6, atol=atol, err_msg=name)
        if name not in quantum:     # a rounded value may repeat where the flight's moved
            np.testing.assert_array_equal(fresh[:, j], s.fresh[:, j], err_msg=name)


def test_the_grid_starts_at_a_step_that_holds_a_record():
    """ceil(1.7000000000000002 * 10) is 17, and 1.7 s is before the first record."""
    from alfa_bench.data import first_grid_step

    assert first_grid_step(1.7000000000000002, 10.0) == 18
    assert first_grid_step(1.7, 10.0) == 17 and first_grid_step(0.051, 20.0) == 2


def test_a_stamp_a_little_early_is_redated_a_late_one_dropped_a_clock_restart_rearms(
        quiet_flight, caplog):
    from alfa_bench.data import first_grid_step

    det, _ = quiet_flight
    monitor = Monitor(det)
    values = {n: 0.0 for n in monitor.measured}
    monitor.feed(10.0, "X", values)
    monitor.feed(10.0 - 0.001, "X", values)           # a millisecond stamp: re-dated
    assert monitor.last_t == 10.0 and not monitor.dropped
    monitor.feed(9.5, "X", values)                     # half a second late: dropped
    assert monitor.dropped["out of order"] == 1
    monitor.feed(1e9, "X", values)                     # one wild stamp: dropped
    assert monitor.dropped["time jump, not confirmed"] == 1 and monitor.last_t == 10.0
    with caplog.at_level("WARNING"):
        monitor.feed(2.0, "X", values)                 # a reboot: a new clock ...
        monitor.feed(2.1, "X", values)                 # ... once confirmed
    assert "the clock went back 7.9 s; re-arming" in caplog.text
    assert monitor.last_t == 2.1 and monitor.next_step == first_grid_step(2.1, det.rate_hz)
    monitor.feed(float("nan"), "X", values)
    assert monitor.dropped["no time"] == 1


def test_hold_counts_a_repeated_value_as_held_and_a_new_one_as_fresh():
    t = np.array([0.0, 0.1, 0.2, 0.3])
    changed = np.array([True, False, True, False])
    row, source = hold(t, changed, np.array([0.05, 0.15, 0.25, 0.3]))
    assert row.tolist() == [0, 1, 2, 3] and source.tolist() == [0, 0, 2, 2]


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_over_udp_on_localhost_the_first_alarm_is_the_workflows(local):
    from pymavlink import mavutil

    run = "coincidence"
    name = next(n for n in local.flights if "engine" in n)
    d = _date(name)
    det = ab.fit_run(run, local, [n for n in local.flights if _date(n) != d])
    flight = local.flight(name)
    port, done = _free_port(), threading.Event()
    monitor = Monitor(det)
    listener = threading.Thread(target=watch, args=(f"udpin:127.0.0.1:{port}", monitor),
                                kwargs={"stop": done.is_set})
    listener.start()
    try:
        link = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", input=False)
        replay.send(flight, link, det.signals(), speed=20.0)
    finally:
        threading.Timer(1.0, done.set).start()
        listener.join(10)
    batch = _batch_first_alarm(det, flight)
    live = None if monitor.first_alarm is None else monitor.first_alarm.t
    assert monitor.steps > 0
    assert _same(live, batch, det.rate_hz), (live, batch)


def test_a_model_reading_the_emulation_is_refused_for_a_link_unless_allowed():
    det = make_detector("emulation_oracle")
    with pytest.raises(ValueError, match="written by ALFA's fault emulation"):
        Monitor(det.fit([]))
    assert Monitor(det.fit([]), allow_actuators=True).names == tuple(det.signals())


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("ALFA_DIR"), reason="real ALFA flights: set ALFA_DIR")
def test_on_real_flights_a_replayed_log_gives_the_workflows_first_alarm(tmp_path):
    """The first flight of each date (every local flight with ALFA_LIVE_ALL=1: about 6
    minutes, run at each stop); each run fitted without the flight's date."""
    corpus = ab.load_corpus()
    names = list(corpus.flights)
    if not os.environ.get("ALFA_LIVE_ALL"):
        names = list({_date(n): n for n in reversed(names)}.values())
    wrong = _check_flights(corpus, names, tmp_path)
    assert not wrong, wrong


def _faulty_tlog(flight, signals, path, fault: str, seed: int = 0):
    """The flight's replay as a .tlog with one fault of the link applied."""
    import struct

    rng = np.random.default_rng(seed)
    epoch = replay.flight_epoch_s(flight)
    packets = list(replay.packets(flight, signals))
    times = np.array([t for t, _ in packets])
    mid = float(times[len(times) // 2])
    out, out_of_range = [], False
    for i, (t, p) in enumerate(packets):
        if fault == "loss" and rng.random() < 0.1:
            continue
        if fault == "corrupt" and rng.random() < 0.05:
            b = bytearray(p)
            b[len(b) // 2] ^= 0xFF
            p = bytes(b)
        if fault == "silence" and mid <= t < mid + 3.0:
            continue
        if fault == "jump_back" and t >= mid:
            t -= 10.0
        if fault == "range" and t >= mid and not out_of_range:
            p = _with_roll(p, 100.0)
            out_of_range = p != packets[i][1]
        out.append((t, p))
        if fault == "duplicate" and rng.random() < 0.05:
            out.append((t, p))
        if fault == "flood" and mid <= t < mid + 0.001:
            out += [(t + k / 2000.0, p) for k in range(4000)]
    if fault == "reorder":
        for i in range(0, len(out) - 1, 20):
            out[i], out[i + 1] = (out[i][0], out[i + 1][1]), (out[i + 1][0], out[i][1])
    with open(path, "wb") as f:
        for t, p in out:
            f.write(struct.pack(">Q", round((epoch + t) * 1e6)) + p)
    return path


def _with_roll(packet: bytes, roll_rad: float) -> bytes:
    """An ATTITUDE packet (any other is returned as it is) with its roll set."""
    from pymavlink.dialects.v20 import ardupilotmega as mav

    m = mav.MAVLink(None, srcSystem=1, srcComponent=1)
    msg = m.parse_char(packet)
    if msg is None or msg.get_type() != "ATTITUDE":
        return packet
    msg.roll = roll_rad
    return mav.MAVLink_attitude_message(
        msg.time_boot_ms, msg.roll, msg.pitch, msg.yaw, msg.rollspeed, msg.pitchspeed,
        msg.yawspeed).pack(m)


FAULTS = {"loss": None, "reorder": None, "duplicate": None, "corrupt": None,
          "silence": "stale", "jump_back": "the clock went back", "flood": None,
          "range": "implausible roll"}


@pytest.fixture(scope="module")
def quiet_flight(local, tmp_path_factory):
    """A fault-free flight, and a detector fitted without its date that does not alarm
    on its clean replay."""
    name = next(n for n in local.flights if "no_failure" in n and "2018-10-05" in n)
    d = _date(name)
    det = ab.fit_run("residual_logistic_published_date", local,
                     [n for n in local.flights if _date(n) != d])
    flight = local.flight(name)
    assert _tlog_first_alarm(det, flight, tmp_path_factory.mktemp("clean") / "c.tlog") is None
    return det, flight


@pytest.mark.parametrize("fault", list(FAULTS))
def test_a_fault_of_the_link_alone_raises_no_fault_alarm(fault, quiet_flight, tmp_path,
                                                         caplog):
    """With each fault of the link the monitor neither crashes nor alarms on a flight
    whose clean replay is quiet; a silence (stale) and a clock jump back re-arm it, a
    value out of range is dropped (implausible), each named in the log."""
    det, flight = quiet_flight
    path = _faulty_tlog(flight, det.signals(), tmp_path / f"{fault}.tlog", fault)
    with caplog.at_level("WARNING"):
        monitor = watch(str(path), Monitor(det))
    assert monitor.first_alarm is None
    assert monitor.steps > 0
    if FAULTS[fault]:
        assert FAULTS[fault] in caplog.text


def test_the_command_names_a_missing_log_and_a_monitor_that_never_armed(
        local, quiet_flight, tmp_path, capsys):
    from alfa_bench import cli
    from alfa_bench.methods.model_files import save_model

    _, flight = quiet_flight
    det = ab.fit_run("residual_logistic_published_date", local)
    model = save_model(det, tmp_path / "m.abm", run="residual_logistic_published_date")
    assert cli.main(["monitor", str(model), str(tmp_path / "nothere.tlog")]) == 1
    assert "nothere.tlog: no such log, device or link" in capsys.readouterr().err
    # a log holding only the IMU: the other signals never come
    imu = [s for s in det.signals() if mavlink.FIELDS.get(s, None) is not None
           and mavlink.FIELDS[s].message == "HIGHRES_IMU"]
    replay.write_tlog(flight, tmp_path / "imu.tlog", imu)
    assert cli.main(["monitor", str(model), str(tmp_path / "imu.tlog")]) == 1
    err = capsys.readouterr().err
    assert "never armed: no message gave" in err and "roll" in err


def _heartbeat(t: float, armed: bool) -> bytes:
    from pymavlink.dialects.v20 import ardupilotmega as mav

    m = mav.MAVLink(None, srcSystem=1, srcComponent=1)
    mode = mav.MAV_MODE_FLAG_SAFETY_ARMED if armed else 0
    return m.heartbeat_encode(mav.MAV_TYPE_FIXED_WING, mav.MAV_AUTOPILOT_ARDUPILOTMEGA,
                              mode, 0, mav.MAV_STATE_ACTIVE).pack(m)


def test_a_log_cut_mid_flight_ends_with_a_line_saying_so(local, quiet_flight, tmp_path,
                                                          capsys):
    """The autopilot's HEARTBEAT says armed to the last one: the log stopped mid-flight,
    at its last message's time; one ending disarmed ends with the summary."""
    import struct

    from alfa_bench import cli
    from alfa_bench.methods.model_files import save_model

    _, flight = quiet_flight
    det = ab.fit_run("residual_logistic_published_date", local)
    model = save_model(det, tmp_path / "m.abm", run="residual_logistic_published_date")
    epoch = replay.flight_epoch_s(flight)
    packets = list(replay.packets(flight, det.signals()))
    cut = packets[: len(packets) // 2]
    beats = [(t, _heartbeat(t, True)) for t in np.arange(cut[0][0], cut[-1][0], 1.0)]
    logs = {"cut": sorted(cut + beats, key=lambda p: p[0]),
            "disarmed": sorted(cut + beats, key=lambda p: p[0])
            + [(cut[-1][0], _heartbeat(cut[-1][0], False))]}
    for name, out in logs.items():
        with open(tmp_path / f"{name}.tlog", "wb") as f:
            for t, p in out:
                f.write(struct.pack(">Q", round((epoch + t) * 1e6)) + p)
    assert cli.main(["monitor", str(model), str(tmp_path / "cut.tlog")]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last == ("residual_logistic_published_date: the log stopped mid-flight at "
                    f"{cut[-1][0] + epoch - math.floor(epoch + cut[0][0]):.2f} s: the "
                    "vehicle was still armed")
    assert cli.main(["monitor", str(model), str(tmp_path / "disarmed.tlog")]) == 0
    assert "grid steps" in capsys.readouterr().out.strip().splitlines()[-1]


def test_a_ulog_or_a_dataflash_log_is_refused_by_name(local, tmp_path, capsys):
    """Real logs of other formats (the folder of tests/README's flight logs, or
    ALFA_LOGS): each named as a format the monitor does not read, no crash."""
    from alfa_bench import cli
    from alfa_bench.methods.model_files import save_model

    logs = Path(os.environ.get("ALFA_LOGS", REPO.parent / "shared" / "logs"))
    if not (logs / "ardupilot" / "test.BIN").is_file():
        unavailable(f"the flight logs of other formats are not at {logs}: set ALFA_LOGS")
    model = save_model(ab.fit_run("coincidence", local), tmp_path / "m.abm", run="coincidence")
    for path, named in [(logs / "px4" / "sample.ulg", "a PX4 ULog, not read"),
                        (logs / "ardupilot" / "test.BIN",
                         "an ArduPilot DataFlash log, not read")]:
        assert cli.main(["monitor", str(model), str(path)]) == 1
        assert f"{path}: {named}" in capsys.readouterr().err


def test_without_pymavlink_the_command_names_the_extra(local, tmp_path, monkeypatch, capsys):
    from alfa_bench import cli
    from alfa_bench.methods.model_files import save_model

    model = save_model(ab.fit_run("coincidence", local), tmp_path / "m.abm", run="coincidence")
    monkeypatch.setitem(sys.modules, "pymavlink", None)
    assert cli.main(["monitor", str(model), "udpin:127.0.0.1:14550"]) == 1
    assert 'pip install "alfa-bench[live]"' in capsys.readouterr().err
