"""Read one ALFA flight folder into a typed, validated object.

A processed ALFA flight is a folder ``<flight>/`` holding one CSV per ROS topic,
``<flight>-<topic>.csv``, as exported by ``rostopic echo -p``: the first column
``%time`` is the record time in ns (UTC epoch), the others are ``field.*``.
Ground truth is the ``failure_status-*`` topics, whose rows exist only while a
fault is active.

All times of a flight are put on one clock, seconds from the flight's first
sample (the earliest ``%time`` of any topic).

Bad input policy (also in docs/bad-data.md):

- raised as :class:`AlfaDataError`, naming flight, file, column and line: an empty
  file, a header without rows, a row with the wrong number of fields, a
  ``%time`` that is not an integer, timestamps that go backwards, a
  non-numeric, NaN or infinite cell in a column that is used, a
  ``failure_status`` topic without rows, a ground-truth topic that is not one of
  ALFA's four, a ``no_failure`` flight with ground truth rows, a label naming
  control surfaces other than its ground-truth topics, a row more than
  :data:`MAX_OUTSIDE_S` before the topics' median first row or after their median
  last row (a clock jump or a stray row that would move the flight clock or the
  onset), a fault onset outside the span of the other topics (no data holds the
  fault; scored, the flight would calibrate as fault-free); a file that starts with a
  UTF-16 byte-order mark or holds NUL bytes (binary), named as such;
- logged and kept: a label that names no fault class ALFA knows (the class is
  then read from the ground-truth topics alone);
- repaired and logged (warning on the ``alfa_bench.data`` logger, and kept in
  :attr:`Flight.repairs` so that results record it): a UTF-8 byte-order mark before
  the header is dropped; a last line cut short
  (no final newline, as left by an interrupted copy) is dropped; rows that repeat
  the previous row's ``%time`` are dropped, keeping the last, since ROS
  re-publishes a message rather than sampling twice in one nanosecond.
"""

from __future__ import annotations

import io
import logging
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import AlfaDataError, MissingFolderError, MissingTopicError

__all__ = [
    "FAULT_CLASSES",
    "MAX_OUTSIDE_S",
    "Fault",
    "Flight",
    "Topic",
    "assemble_flight",
    "entries",
    "find_flights",
    "load_flight",
    "not_a_flight",
    "parse_flight_name",
]

log = logging.getLogger("alfa_bench.data")

FAULT_CLASSES = ("engine", "rudder", "elevator", "aileron", "rudder+aileron", "sensor", "none")

#: ground-truth topic -> fault class, in the order used to name combined faults
_GROUND_TRUTH_TOPICS = {
    "failure_status-engines": "engine",
    "failure_status-elevator": "elevator",
    "failure_status-rudder": "rudder",
    "failure_status-aileron": "aileron",
    # not ALFA's: written by data.inject for an injected sensor fault
    "failure_status-sensor": "sensor",
}

#: How far a row may lie outside the flight's span (the topics' median first and
#: last rows), s. In ALFA every topic starts and ends within 0.3 s of the median.
MAX_OUTSIDE_S = 60.0

_LABEL_CLASSES = re.compile(r"engine|rudder|elevator|aileron|sensor")

_FLIGHT_NAME = re.compile(
    r"^carbonZ_(?P<date>\d{4}-\d{2}-\d{2})-(?P<time>\d{2}-\d{2}-\d{2})"
    r"(?:_(?P<part>\d+))?_(?P<label>[A-Za-z0-9_]+)$"
)
#: a flight converted from a log (alfa_bench.logs.corpus): its group in the date's place
_LOG_FLIGHT_NAME = re.compile(
    r"^log_(?P<date>[A-Za-z0-9]+(?:-[A-Za-z0-9]+)*?)-(?P<time>\d{2}-\d{2}-\d{2})"
    r"_(?P<part>\d+)_(?P<label>[A-Za-z0-9_]+)$"
)


def parse_flight_name(name: str) -> dict[str, str | int | None]:
    """Split an ALFA flight folder name into date, time, part and fault label; a flight
    converted from a log (``log_<group>-hh-mm-ss_<N>_<label>``) gives its group as the
    date, the unit its folds leave out.

    >>> parse_flight_name("carbonZ_2018-07-18-15-53-31_1_engine_failure")["label"]
    'engine_failure'
    """
    m = _FLIGHT_NAME.match(name) or _LOG_FLIGHT_NAME.match(name)
    if m is None:
        raise AlfaDataError(
            "folder name is not an ALFA flight name "
            "(carbonZ_YYYY-MM-DD-hh-mm-ss[_N]_<label>) nor a converted log's "
            "(log_<group>-hh-mm-ss_N_<label>)",
            flight=name,
        )
    part = m["part"]
    return {
        "date": m["date"],
        "time": m["time"],
        "part": int(part) if part else None,
        "label": m["label"],
    }


@dataclass(frozen=True, eq=False)
class Topic:
    """One topic of a flight: its sample times and raw columns.

    Attributes
    ----------
    name : str
        Topic name as in the file name, e.g. ``mavros-nav_info-roll``.
    file : str
        File name, for messages.
    t : ndarray of float64
        Record times in seconds on the flight clock, strictly increasing.
    frame : DataFrame
        The ``field.*`` columns as read; use :meth:`values` for numbers. Given as a
        function, it is called when first needed: the parsed-flight cache passes one,
        since building the frames took most of its reading time, and most jobs read
        only numbers, which it hands to :meth:`values` directly.
    lines : ndarray of int
        1-based line of each row in the file, for messages.

    :meth:`values` keeps what it parsed; :func:`dataclasses.replace` passes that cache
    on, so a copy must keep the frame (or be given a new cache).
    """

    flight: str
    name: str
    file: str
    t: np.ndarray
    _frame: pd.DataFrame | Callable[[], pd.DataFrame]
    lines: np.ndarray
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def frame(self) -> pd.DataFrame:
        return self._frame() if callable(self._frame) else self._frame

    def has(self, column: str) -> bool:
        """Whether the topic has ``column``; a column already parsed to numbers builds no
        frame to say so."""
        return column in self._cache or column in self.frame.columns

    def values(self, column: str) -> np.ndarray:
        """Return ``column`` as float64, checked to be finite in every row."""
        if column in self._cache:
            return self._cache[column]
        if column not in self.frame.columns:
            raise AlfaDataError("no such column", flight=self.flight, file=self.file,
                                column=column)
        raw = self.frame[column]
        v = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=np.float64)
        bad = ~np.isfinite(v)
        if bad.any():
            i = int(np.argmax(bad))
            cell = raw.iloc[i]
            if isinstance(cell, str):
                what = f"non-numeric cell {cell!r}"
            elif np.isnan(v[i]):
                what = "empty or NaN cell"
            else:
                what = f"infinite value {v[i]}"
            raise AlfaDataError(f"{what} ({int(bad.sum())} bad cells in all)",
                                flight=self.flight, file=self.file, column=column,
                                line=int(self.lines[i]))
        v.setflags(write=False)
        self._cache[column] = v
        return v


@dataclass(frozen=True)
class Fault:
    """Ground truth of a flight.

    Attributes
    ----------
    fault_class : str
        One of :data:`FAULT_CLASSES`.
    onset_s, end_s : float or None
        First and last ground-truth row on the flight clock (None without fault).
        The onset is known only to the ground-truth topic's period
        (0.2 s in July 2018, 0.5 s later).
    topics : tuple of str
        The ``failure_status-*`` topics present.
    sensor, kind, magnitude, source : str, str, float, str or None
        For an injected sensor fault (:mod:`.inject`): the sensor, the kind of fault,
        its magnitude and the fault-free flight it was injected into.
    codes : dict
        Topic -> distinct ``field.data`` codes in order of appearance.
    """

    fault_class: str
    onset_s: float | None = None
    end_s: float | None = None
    topics: tuple[str, ...] = ()
    codes: dict = field(default_factory=dict)
    sensor: str | None = None
    kind: str | None = None
    magnitude: float | None = None
    source: str | None = None


@dataclass(frozen=True)
class Flight:
    """A loaded ALFA flight.

    Attributes
    ----------
    id : str
        Folder name.
    date, label : str
        From the folder name; ``label`` is the raw fault label.
    emergency_trajectory : bool
        The label ends in ``with_emr_traj``: the commands change at the fault.
    t0_ns : int
        Epoch time of the flight clock's zero.
    duration_s : float
        Last sample of any topic on the flight clock.
    fault : Fault or None
        None when the flight has no ground truth.
    topics : dict
        Topic name -> :class:`Topic`.
    repairs : tuple of str
        Repairs made while reading, also logged.
    """

    id: str
    path: Path
    date: str
    label: str
    emergency_trajectory: bool
    t0_ns: int
    duration_s: float
    fault: Fault | None
    topics: dict
    repairs: tuple[str, ...] = ()

    @property
    def has_ground_truth(self) -> bool:
        return self.fault is not None

    def topic(self, name: str) -> Topic:
        """Return topic ``name``, or raise :class:`MissingTopicError`."""
        try:
            return self.topics[name]
        except KeyError:
            raise MissingTopicError("topic file is missing", flight=self.id,
                                    file=f"{self.id}-{name}.csv") from None


def not_a_flight(entry: Path) -> str | None:
    """Why the entry ``entry`` of a ``processed/`` folder is no flight folder to read
    (a broken link, not a folder, unreadable, no ``<folder>-*.csv`` file), or None."""
    if entry.is_symlink() and not entry.exists():
        return "not a flight folder: a broken link, unreadable"
    if not entry.is_dir():
        return "not a flight folder: a file"
    try:
        found = any(entry.glob(f"{_glob_escape(entry.name)}-*.csv"))
    except OSError as e:
        return f"not a flight folder: unreadable ({e.strerror or e})"
    return None if found else f"not a flight folder: no {entry.name}-<topic>.csv files"


def entries(processed: Path) -> list[Path]:
    """Every entry of ``processed`` but hidden ones (``.name``), sorted by name."""
    processed = Path(processed)
    if not processed.is_dir():
        raise MissingFolderError(f"no such folder: {processed}")
    return sorted(p for p in processed.iterdir() if not p.name.startswith("."))


def find_flights(processed: Path) -> list[Path]:
    """Flight folders under ``processed``, sorted by name; any other entry is skipped
    with a warning saying why (:func:`not_a_flight`)."""
    flights = []
    for entry in entries(processed):
        if (why := not_a_flight(entry)) is None:
            flights.append(entry)
        else:
            log.warning("skipped %s: %s", entry, why)
    return flights


def _glob_escape(s: str) -> str:
    return re.sub(r"([*?\[])", r"[\1]", s)


def load_flight(path: str | Path) -> Flight:
    """Read and validate the flight folder at ``path``.

    Raises
    ------
    AlfaDataError
        For any input that cannot be read safely; see the module docstring.
    """
    path = Path(path)
    name = path.name
    parse_flight_name(name)      # a folder that is not an ALFA flight fails before any read
    prefix = f"{name}-"
    raw: dict[str, tuple] = {}
    repairs: list[str] = []
    for f in sorted(path.glob(f"{_glob_escape(name)}-*.csv")):
        topic = f.name[len(prefix):-len(".csv")]
        t_ns, frame, lines = _read_topic(f, name, repairs)
        raw[topic] = (f.name, t_ns, frame, lines)
    if not raw:
        raise AlfaDataError("no topic files (<flight>-<topic>.csv)", flight=name)
    _check_span(name, raw)

    t0 = min(int(v[1][0]) for v in raw.values())
    topics = {
        topic: Topic(name, topic, file, (t_ns - t0) * 1e-9, frame, lines)
        for topic, (file, t_ns, frame, lines) in raw.items()
    }
    return assemble_flight(path, t0, topics, repairs)


def assemble_flight(path: str | Path, t0_ns: int, topics: dict[str, Topic],
                    repairs=(), ground_truth: Fault | None = None) -> Flight:
    """The :class:`Flight` of already-read ``topics`` (times on the clock of
    ``t0_ns``), its ground truth read from them: what :func:`load_flight` returns
    after parsing, and what the parsed-flight cache (:mod:`.cache`) and in-memory
    injection (:mod:`.inject`) rebuild. In-memory injection, which writes the
    ground-truth topic from a known fault, gives that fault as ``ground_truth``,
    so that the topic's frame need not be built to read it back."""
    path = Path(path)
    name = path.name
    meta = parse_flight_name(name)
    duration = max(float(tp.t[-1]) for tp in topics.values())
    label = str(meta["label"])
    return Flight(
        id=name,
        path=path,
        date=str(meta["date"]),
        label=label,
        emergency_trajectory=label.endswith("with_emr_traj"),
        t0_ns=t0_ns,
        duration_s=duration,
        fault=(_ground_truth(name, label, topics) if ground_truth is None
               else ground_truth),
        topics=topics,
        repairs=tuple(repairs),
    )


def _classes(flight: str) -> dict[str, str]:
    """Ground-truth topic -> fault class: ALFA's, and on a flight converted from a log
    any ``failure_status-<class>`` its ``labels.csv`` named."""
    return _GROUND_TRUTH_TOPICS if not flight.startswith("log_") else _AnyClass()


class _AnyClass(dict):
    def __init__(self):
        super().__init__(_GROUND_TRUTH_TOPICS)

    def __missing__(self, topic: str) -> str:
        return topic.removeprefix("failure_status-")

    def __contains__(self, topic) -> bool:
        return str(topic).startswith("failure_status-")


def _ground_truth(flight: str, label: str, topics: dict[str, Topic]) -> Fault | None:
    gt = sorted(t for t in topics if t.startswith("failure_status"))
    classes = _classes(flight)
    unknown = [t for t in gt if t not in classes]
    if unknown:
        raise AlfaDataError(f"unknown ground-truth topic (known: "
                            f"{', '.join(_GROUND_TRUTH_TOPICS)})",
                            flight=flight, file=f"{flight}-{unknown[0]}.csv")
    if not gt:
        if label == "no_failure":
            return Fault("none")
        log.warning("flight %s: label %r names no ground truth and no failure_status "
                    "topic exists: it is kept out of labelled scoring", flight, label)
        return None
    if label == "no_failure":
        raise AlfaDataError("labelled no_failure but has ground-truth rows",
                            flight=flight, file=f"{flight}-{gt[0]}.csv")
    order = list(_GROUND_TRUTH_TOPICS)
    gt.sort(key=lambda t: (order.index(t) if t in order else len(order), t))
    _check_label(flight, label, {classes[t] for t in gt}, gt)
    codes = {t: tuple(dict.fromkeys(topics[t].values("field.data").astype(int).tolist()))
             for t in gt}
    first_gt = min(gt, key=lambda t: float(topics[t].t[0]))
    onset = float(topics[first_gt].t[0])
    sensors = [tp for name, tp in topics.items() if not name.startswith("failure_status")]
    first = min((float(tp.t[0]) for tp in sensors), default=onset)
    last = max((float(tp.t[-1]) for tp in sensors), default=onset)
    if not first <= onset <= last:
        raise AlfaDataError(f"the fault's onset ({onset:.2f} s on the flight clock) is outside "
                            f"the recorded data ({first:.2f} to {last:.2f} s): no data holds "
                            "the fault",
                            flight=flight, file=f"{flight}-{first_gt}.csv", column="%time",
                            line=int(topics[first_gt].lines[0]))
    return Fault(
        fault_class="+".join(classes[t] for t in gt),
        onset_s=onset,
        end_s=max(float(topics[t].t[-1]) for t in gt),
        topics=tuple(gt),
        codes=codes,
        **_injected(topics.get("failure_status-sensor")),
    )


def _injected(topic: Topic | None) -> dict:
    if topic is None:
        return {}
    first = {c: topic.frame[c].iloc[0] if c in topic.frame else None
             for c in ("field.sensor", "field.kind", "field.source")}
    if None in first.values():
        raise AlfaDataError("an injected fault's ground truth needs field.sensor, "
                            "field.kind and field.source", flight=topic.flight,
                            file=topic.file)
    return {"sensor": str(first["field.sensor"]), "kind": str(first["field.kind"]),
            "magnitude": float(topic.values("field.magnitude")[0]),
            "source": str(first["field.source"])}


def _check_span(flight: str, raw: dict[str, tuple]) -> None:
    first = np.median([int(v[1][0]) for v in raw.values()])
    last = np.median([int(v[1][-1]) for v in raw.values()])
    lo, hi = first - MAX_OUTSIDE_S * 1e9, last + MAX_OUTSIDE_S * 1e9
    for file, t_ns, _, lines in raw.values():
        out = (t_ns < lo) | (t_ns > hi)
        if out.any():
            i = int(np.argmax(out))
            where = (f"{(first - t_ns[i]) * 1e-9:.0f} s before the topics' median first row"
                     if t_ns[i] < lo else
                     f"{(t_ns[i] - last) * 1e-9:.0f} s after the topics' median last row")
            raise AlfaDataError(f"%time {t_ns[i]} is {where} (limit {MAX_OUTSIDE_S:.0f} s)",
                                flight=flight, file=file, column="%time", line=int(lines[i]))


def _check_label(flight: str, label: str, classes: set[str], gt: list[str]) -> None:
    named = set(_LABEL_CLASSES.findall(label))
    if not named:
        log.warning("flight %s: label %r names no known fault class; the class is read from "
                    "the ground-truth topics (%s)", flight, label, ", ".join(sorted(classes)))
    elif named != classes:
        raise AlfaDataError(f"label {label!r} names {', '.join(sorted(named))} but the "
                            f"ground-truth topics name {', '.join(sorted(classes))}",
                            flight=flight, file=f"{flight}-{gt[0]}.csv")


def _read_topic(path: Path, flight: str, repairs: list[str]):
    """Parse one topic CSV; returns (%time in ns, field frame, line numbers)."""
    file = path.name

    def fail(msg, **where):
        return AlfaDataError(msg, flight=flight, file=file, **where)

    data = path.read_bytes()
    if not data:
        raise fail("empty file (0 bytes)")
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise fail("UTF-16 text (it starts with a UTF-16 byte-order mark); re-export it as "
                   "UTF-8")
    if b"\0" in data:
        nul = data.index(b"\0")
        raise fail(f"binary data, not CSV text (a NUL byte at offset {nul})")
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
        repairs.append(f"{file}: dropped the UTF-8 byte-order mark before the header")
        log.warning("flight %s: %s", flight, repairs[-1])
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise fail(f"not UTF-8 text ({e.reason} at byte {e.start})") from None
    lines = text.split("\n")
    complete = text.endswith("\n")
    if complete:
        lines.pop()
    if len(lines) == 1 and not complete:
        raise fail("file ends inside the header line (truncated)", line=1)
    header = lines[0].split(",")
    if header[0] != "%time":
        raise fail("header must start with %time", line=1)
    if not complete:
        lines.pop()
        repairs.append(f"{file}: dropped truncated last line {len(lines) + 1} "
                       "(file does not end with a newline)")
        log.warning("flight %s: %s", flight, repairs[-1])
    if len(lines) == 1:
        raise fail("header only, no data rows")
    commas = len(header) - 1
    for i, line in enumerate(lines[1:], start=2):
        if line.count(",") != commas:
            raise fail(f"row has {line.count(',') + 1} fields, header has {len(header)}",
                       line=i)

    frame = pd.read_csv(io.StringIO("\n".join(lines)), dtype={"%time": str},
                        keep_default_na=True)
    line_no = np.arange(2, len(frame) + 2)
    t_text = frame.pop("%time")
    bad = ~t_text.str.fullmatch(r"\d{1,19}").fillna(False).to_numpy()
    if bad.any():
        i = int(np.argmax(bad))
        raise fail(f"%time {t_text.iloc[i]!r} is not an integer number of ns",
                   column="%time", line=int(line_no[i]))
    t_ns = t_text.astype(np.int64).to_numpy()

    step = np.diff(t_ns)
    if (step < 0).any():
        i = int(np.argmax(step < 0))
        raise fail(f"timestamps go backwards ({t_ns[i + 1]} after {t_ns[i]})",
                   column="%time", line=int(line_no[i + 1]))
    if (step == 0).any():
        keep = np.r_[step != 0, True]
        repairs.append(f"{file}: dropped {int((~keep).sum())} rows repeating the previous "
                       "row's %time (kept the last of each run)")
        log.warning("flight %s: %s", flight, repairs[-1])
        t_ns, frame, line_no = t_ns[keep], frame[keep].reset_index(drop=True), line_no[keep]
    return t_ns, frame, line_no
