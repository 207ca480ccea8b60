"""A corpus of broken flights in ALFA's on-disk format, and what each must give.

Every case corrupts a copy of one valid synthetic engine-failure flight (onset
50 s) in one way. :func:`outcome` runs the per-flight part of the pipeline on a
folder (find, load, the physical bounds, manifest row, and a detector reading the
attitude, servo and IMU topics) and says how it ended; each case states the outcome it must have:

``error``
    an :class:`~alfa_bench.data.AlfaDataError` naming the flight, and the file,
    column and line where given;
``repair``
    a result, with the repair in ``Flight.repairs`` and in the log;
``excluded``
    no score: the flight has no ground truth, which is logged;
``warning``
    a result, with the oddity in the log;
``skipped``
    the folder is not taken for a flight, which is logged.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from alfa_bench.data import AlfaDataError, find_flights, load_flight
from alfa_bench.data.manifest import manifest_row
from alfa_bench.data.signals import check_signals
from alfa_bench.methods import make_detector, run_detector

NAME = "carbonZ_2018-07-18-15-53-31_1_engine_failure"
ROLL = "mavros-nav_info-roll"
IMU = "mavros-imu-data_raw"
GT = "failure_status-engines"

#: the detector of :func:`outcome`: one pair per topic family a method reads
PAIRS = [{"name": "roll", "input": "roll_cmd", "output": "roll"},
         {"name": "p", "input": "servo_aileron_left", "output": "roll_rate"}]


@dataclass(frozen=True)
class Expect:
    kind: str
    message: str
    file: str | None = None      # topic, or None
    column: str | None = None
    line: int | None = None


@dataclass(frozen=True)
class Case:
    id: str
    corrupt: Callable[[Path], Path]   # corrupts the flight folder, returns it (maybe renamed)
    expect: Expect


def topic_file(folder: Path, topic: str) -> Path:
    return folder / f"{folder.name}-{topic}.csv"


def edit(topic: str, fn: Callable[[list[str]], list[str]]) -> Callable[[Path], Path]:
    """A corruption that rewrites the lines (header first) of ``topic``."""
    def corrupt(folder: Path) -> Path:
        path = topic_file(folder, topic)
        path.write_text("\n".join(fn(path.read_text().splitlines())) + "\n")
        return folder
    return corrupt


def set_cell(line: str, column: int, value: str) -> str:
    cells = line.split(",")
    cells[column] = value
    return ",".join(cells)


def shift_time(line: str, ns: int) -> str:
    return set_cell(line, 0, str(int(line.split(",")[0]) + ns))


def _write(topic: str, text: str) -> Callable[[Path], Path]:
    def corrupt(folder: Path) -> Path:
        topic_file(folder, topic).write_text(text)
        return folder
    return corrupt


def _truncate_last_line(folder: Path) -> Path:
    path = topic_file(folder, ROLL)
    path.write_text(path.read_text()[:-7])
    return folder


def _remove(topic: str) -> Callable[[Path], Path]:
    def corrupt(folder: Path) -> Path:
        topic_file(folder, topic).unlink()
        return folder
    return corrupt


def _rename_topic(topic: str, new: str) -> Callable[[Path], Path]:
    def corrupt(folder: Path) -> Path:
        topic_file(folder, topic).rename(topic_file(folder, new))
        return folder
    return corrupt


def _rename(name: str) -> Callable[[Path], Path]:
    def corrupt(folder: Path) -> Path:
        new = folder.with_name(name)
        folder.rename(new)
        for f in new.iterdir():
            f.rename(new / f.name.replace(folder.name, name, 1))
        return new
    return corrupt


def _gap(lines: list[str]) -> list[str]:
    """Drop the rows of 30-34 s: a 5 s gap in the IMU topic, as a dropped link leaves."""
    t = np.array([int(line.split(",")[0]) for line in lines[1:]])
    t = (t - t[0]) * 1e-9
    return [lines[0]] + [line for line, s in zip(lines[1:], t, strict=True)
                         if not 30.0 <= s < 35.0]


def _slow(lines: list[str]) -> list[str]:
    """Keep every 40th row: the 10 Hz IMU topic at 0.25 Hz."""
    return [lines[0]] + lines[1::40]


def _fast(lines: list[str]) -> list[str]:
    """Every row twice more, 1 ms apart: the 10 Hz IMU topic at 30 Hz."""
    return [lines[0]] + [shift_time(line, k * 1_000_000) for line in lines[1:] for k in range(3)]


def _bytes(topic: str, fn: Callable[[bytes], bytes]) -> Callable[[Path], Path]:
    """A corruption that rewrites the bytes of ``topic``."""
    def corrupt(folder: Path) -> Path:
        path = topic_file(folder, topic)
        path.write_bytes(fn(path.read_bytes()))
        return folder
    return corrupt


def _late_start(lines: list[str]) -> list[str]:
    """Drop the first 30 s of rows: a topic whose recording started late."""
    t = np.array([int(line.split(",")[0]) for line in lines[1:]])
    return [lines[0]] + [line for line, s in zip(lines[1:], (t - t[0]) * 1e-9, strict=True)
                         if s >= 30.0]


def _not_a_flight(folder: Path) -> Path:
    other = folder.with_name("notes")
    other.mkdir()
    (other / "readme.txt").write_text("not a flight\n")
    shutil.rmtree(folder)
    return other


CASES = [
    Case("missing topic file", _remove(IMU),
         Expect("error", "topic file is missing", IMU)),
    Case("empty file", _write(ROLL, ""), Expect("error", "empty file (0 bytes)", ROLL)),
    Case("header only", edit(ROLL, lambda ls: ls[:1]),
         Expect("error", "header only, no data rows", ROLL)),
    Case("truncated last line", _truncate_last_line,
         Expect("repair", "dropped truncated last line")),
    Case("non-numeric cell", edit(ROLL, lambda ls: ls[:5] + [set_cell(ls[5], 5, "abc")] + ls[6:]),
         Expect("error", "non-numeric cell 'abc'", ROLL, "field.measured", 6)),
    Case("NaN cell", edit(ROLL, lambda ls: ls[:7] + [set_cell(ls[7], 4, "nan")] + ls[8:]),
         Expect("error", "empty or NaN cell", ROLL, "field.commanded", 8)),
    Case("inf cell", edit(IMU, lambda ls: ls[:9] + [set_cell(ls[9], 4, "inf")] + ls[10:]),
         Expect("error", "infinite value", IMU, "field.angular_velocity.x", 10)),
    Case("duplicate timestamps",
         edit(ROLL, lambda ls: ls[:11] + [set_cell(ls[11], 5, "99.0")] + ls[11:]),
         Expect("repair", "repeating the previous row's %time")),
    Case("non-monotonic timestamps", edit(ROLL, lambda ls: ls[:3] + [ls[4], ls[3]] + ls[5:]),
         Expect("error", "timestamps go backwards", ROLL, "%time", 5)),
    Case("gap of several seconds", edit(IMU, _gap),
         Expect("error", "a value would be held longer than 1.0 s", IMU, "%time")),
    Case("topic at a much lower rate", edit(IMU, _slow),
         Expect("error", "a value would be held longer than 1.0 s", IMU, "%time", 3)),
    # a faster topic is read as it is: the causal hold takes the latest row
    Case("topic at a much higher rate", edit(IMU, _fast), Expect("ok", "")),
    Case("stray row from another time", edit(GT, lambda ls: ls[:1] + ["1,2"] + ls[1:]),
         Expect("error", "before the topics' median first row", GT, "%time", 2)),
    Case("failure_status without rows", edit(GT, lambda ls: ls[:1]),
         Expect("error", "header only, no data rows", GT)),
    Case("failure_status file missing", _remove(GT),
         Expect("excluded", "kept out of labelled scoring")),
    Case("unknown ground-truth topic", _rename_topic(GT, "failure_status-propeller"),
         Expect("error", "unknown ground-truth topic", "failure_status-propeller")),
    Case("unknown fault label", _rename("carbonZ_2018-07-18-15-53-31_1_propeller_failure"),
         Expect("warning", "names no known fault class")),
    Case("label contradicting the ground truth",
         _rename("carbonZ_2018-07-18-15-53-31_1_rudder_left_failure"),
         Expect("error", "names rudder but the ground-truth topics name engine", GT)),
    Case("folder name that is not an ALFA name", _rename("my_flight"),
         Expect("error", "not an ALFA flight name")),
    Case("folder that is not a flight", _not_a_flight, Expect("skipped", "not a flight folder")),
    Case("UTF-8 byte-order mark", _bytes(ROLL, lambda b: b"\xef\xbb\xbf" + b),
         Expect("repair", "dropped the UTF-8 byte-order mark")),
    Case("UTF-16 file", _bytes(ROLL, lambda b: b.decode().encode("utf-16")),
         Expect("error", "UTF-16 text", ROLL)),
    Case("binary file", _bytes(ROLL, lambda b: b[:40] + b"\0\x01\x02" + b[40:]),
         Expect("error", "binary data, not CSV text (a NUL byte at offset 40)", ROLL)),
    Case("gyro sample no gyro can read",
         edit(IMU, lambda ls: ls[:9] + [set_cell(ls[9], 4, "1e12")] + ls[10:]),
         Expect("error", "outside what roll_rate can read", IMU, "field.angular_velocity.x",
                10)),
    Case("onset after the last sensor row",
         edit(GT, lambda ls: ls[:1] + [shift_time(line, 35 * 10**9) for line in ls[1:]]),
         Expect("error", "outside the recorded data", GT, "%time", 2)),
    Case("topic that starts 30 s late", edit(IMU, _late_start),
         Expect("error", "starts 30.5 s after the flight's first row", IMU, "%time", 2)),
]


def outcome(folder: Path) -> tuple[str, object]:
    """Run the per-flight pipeline on ``folder``: ``("error", AlfaDataError)``,
    ``("skipped", None)``, ``("excluded", flight)`` or ``("ok", (flight, trace))``.
    Any other exception propagates."""
    try:
        if not find_flights(folder.parent):
            return "skipped", None
        flight = load_flight(folder)
        check_signals(flight)
        row = manifest_row(flight)
        if not row["ground_truth"]:
            return "excluded", flight
        trace = run_detector(make_detector("rls_arx_zscore", {"pairs": PAIRS}), flight)
    except AlfaDataError as e:
        return "error", e
    return "ok", (flight, trace)
