"""A folder of flight logs and a ``labels.csv``, turned into flights the workflow scores.

``labels.csv`` has one row per log:

``log``
    the log's path, relative to the folder: a MAVLink telemetry log (``.tlog``), an
    ArduPilot DataFlash log (``.bin``) or a PX4 ULog (``.ulg``);
``fault``
    empty for a fault-free flight, else its class: ALFA's (``engine``, ``aileron``,
    ``elevator``, ``rudder``, ``rudder+aileron``) or any other name of lower-case
    letters, digits and ``_``;
``onset_s``
    the fault's onset on the log's clock, s (empty for a fault-free flight): the log's
    times less the whole second before its first record, as the monitor reports a
    ``.tlog`` (for an ALFA flight written by ``alfa-bench replay``, the flight's own
    clock, as in ``results/flights.csv``); a DataFlash log's times are its ``TimeUS``,
    a ULog's its ``timestamp`` (both from the autopilot's boot). It is the flight
    clock of the converted flight;
``group``
    the fold unit: the flights of one group are scored by fits that saw none of it
    (letters, digits and ``-``); empty, the date the log started (UTC) where it says;
``emergency_trajectory`` (optional)
    ``true`` where the commands switch at onset, as on ALFA's ``with_emr_traj`` flights:
    such a flight goes to the ``emr`` subset, the others to ``no_emr``.

Each log is read through its format's map (:mod:`.tlog`, :mod:`.dataflash`,
:mod:`.ulog`) and written as a flight folder of the data layer's format: one CSV per
catalogue topic, rows at every time one of its signals has a record (from when all
of them have begun), each signal's last record held; the fault's rows
(``failure_status-<class>``, 10 Hz from onset to the log's end); and ``log-origin``,
one row at the whole second before the first record, from which the flight clock
counts (the log's clock less that second). A flight is named
``log_<group>-<hh-mm-ss>_<row>_<label>``, its time the log's UTC start where known;
``flights.csv`` beside ``processed/`` maps each log to its flight.

The corpus has the signals every converted log gives (``signals.csv``: each catalogue
signal, whether the corpus has it, and why not); the data checks read those, and a run
that reads another is not applicable. A bad row of ``labels.csv`` or a log that cannot
be read is left out and named in ``left_out.csv`` (file, line, field, why), with the
rest converted; a ``labels.csv`` without its columns stops the run (:class:`CorpusError`).
A log is converted again only when its bytes, its row or the readers change.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import re
import shutil
import struct
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd

from alfa_bench.data import SIGNALS, AlfaDataError
from alfa_bench.live import mavlink

from .records import LogRecords

__all__ = ["ALFA_FAULTS", "CorpusError", "LEFT_OUT_COLUMNS", "LogCorpus", "convert_corpus",
           "read_labels", "read_log", "read_signals"]

log = logging.getLogger("alfa_bench.logs")

#: ALFA's fault classes and their ground-truth topics
ALFA_FAULTS = {"engine": ["engines"], "aileron": ["aileron"], "elevator": ["elevator"],
               "rudder": ["rudder"], "rudder+aileron": ["rudder", "aileron"]}
REQUIRED = ("log", "fault", "onset_s", "group")
LEFT_OUT_COLUMNS = ["log", "file", "line", "field", "error"]
#: the rate of a converted fault's ground-truth rows, Hz
GROUND_TRUTH_HZ = 10.0
_CLASS = re.compile(r"^[a-z][a-z0-9_]*$")
_GROUP = re.compile(r"^[A-Za-z0-9]+(?:-[A-Za-z0-9]+)*$")
_READERS = {".tlog": "tlog", ".bin": "dataflash", ".ulg": "ulog"}


class CorpusError(ValueError):
    """A corpus folder the workflow cannot read at all: no ``labels.csv``, or one without
    its columns."""


@dataclass(frozen=True)
class LogCorpus:
    """A converted corpus: ``processed`` (flight folders), ``flights`` (log -> flight),
    ``signals`` (catalogue signal -> why the corpus lacks it, or None where it has it)
    and ``left_out`` (:data:`LEFT_OUT_COLUMNS`)."""

    processed: Path
    flights: pd.DataFrame
    signals: dict[str, str | None]
    left_out: pd.DataFrame

    @property
    def has(self) -> list[str]:
        """The catalogue signals the corpus has, in catalogue order."""
        return [s for s, why in self.signals.items() if why is None]


class _LeftOut(Exception):
    def __init__(self, field: str, error: str):
        super().__init__(error)
        self.field = field


def read_log(path: str | Path) -> LogRecords:
    """The catalogue signals of the log at ``path``, by its format (its extension; a
    ULog also by its first bytes)."""
    path = Path(path)
    kind = _READERS.get(path.suffix.lower())
    with path.open("rb") as f:
        if f.read(4) == b"ULog":
            kind = "ulog"
    if kind is None:
        raise AlfaDataError(f"not a log format read here (.tlog, .bin, .ulg): "
                            f"{path.suffix or 'no extension'}", file=path.name)
    module = __import__(f"alfa_bench.logs.{kind}", fromlist=["read"])
    try:
        return module.read(str(path))
    except ImportError as e:
        raise CorpusError(f"{path.name}: {e.name} is not installed; the log readers come "
                          "with the logs extra: pip install \"alfa-bench[logs]\"") from None


def read_labels(folder: str | Path) -> tuple[list[dict], list[dict]]:
    """The rows of ``folder/labels.csv`` that are sound, each with its ``line``, and the
    left-out rows (:data:`LEFT_OUT_COLUMNS`). Raises :class:`CorpusError` when the file
    or one of its columns is missing."""
    folder = Path(folder)
    path = folder / "labels.csv"
    if not path.is_file():
        raise CorpusError(f"{folder}: no labels.csv (columns {', '.join(REQUIRED)}); "
                          "docs/own-flights.md")
    try:
        table = pd.read_csv(path, dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, UnicodeDecodeError) as e:
        raise CorpusError(f"{path}: not a CSV file: {e}") from None
    missing = [c for c in REQUIRED if c not in table.columns]
    if missing:
        raise CorpusError(f"{path}: no column {', '.join(map(repr, missing))} (it has "
                          f"{', '.join(table.columns)}); docs/own-flights.md")
    rows, left_out, seen = [], [], {}
    for i, raw in enumerate(table.to_dict(orient="records"), start=2):
        row = {k: str(v).strip() for k, v in raw.items()}
        try:
            rows.append({**_check_row(folder, row, seen, i), "line": i})
        except _LeftOut as e:
            left_out.append({"log": row.get("log", ""), "file": "labels.csv", "line": i,
                             "field": e.field, "error": str(e)})
            log.error("labels.csv line %d, field %s: %s: the log is left out", i, e.field, e)
    return rows, left_out


def _check_row(folder: Path, row: dict, seen: dict, line: int) -> dict:
    name = row["log"]
    if not name:
        raise _LeftOut("log", "empty: name the log")
    if name in seen:
        raise _LeftOut("log", f"{name} is labelled twice (first on line {seen[name]})")
    seen[name] = line
    if not (folder / name).is_file():
        raise _LeftOut("log", f"no such file in {folder}: {name}")
    fault = row["fault"].lower()
    if fault and fault not in ALFA_FAULTS and not _CLASS.match(fault):
        raise _LeftOut("fault", f"{row['fault']!r} is not a class name (lower-case letters, "
                                "digits and _, or one of ALFA's: "
                                f"{', '.join(ALFA_FAULTS)})")
    onset = row["onset_s"]
    if fault:
        try:
            onset_s = float(onset)
        except ValueError:
            raise _LeftOut("onset_s", f"{onset!r} is not a number of seconds") from None
        if not math.isfinite(onset_s) or onset_s < 0:
            raise _LeftOut("onset_s", f"{onset!r} is not a time on the log's clock (s, >= 0)")
    elif onset:
        raise _LeftOut("onset_s", f"{onset!r} given for a fault-free flight (fault empty)")
    else:
        onset_s = None
    group = row["group"]
    if group and not _GROUP.match(group):
        raise _LeftOut("group", f"{group!r}: a group is letters, digits and '-'")
    emr = row.get("emergency_trajectory", "").lower()
    if emr not in ("", "true", "false", "1", "0", "yes", "no"):
        raise _LeftOut("emergency_trajectory", f"{row['emergency_trajectory']!r} is not "
                                               "true or false")
    return {"log": name, "fault": fault, "onset_s": onset_s, "group": group,
            "emergency_trajectory": emr in ("true", "1", "yes")}


def _readers_digest() -> str:
    h = hashlib.sha256()
    for f in sorted(Path(__file__).parent.glob("*.py")):
        h.update(f.read_bytes())
    h.update(Path(mavlink.__file__).read_bytes())
    return h.hexdigest()


def _file_sha256(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _label(fault: str, emr: bool) -> str:
    if not fault:
        return "no_failure"
    return fault.replace("+", "_") + "_failure" + ("_with_emr_traj" if emr else "")


def convert_corpus(folder: str | Path, out: str | Path) -> LogCorpus:
    """Convert the corpus at ``folder`` into ``out/processed`` (module docstring) and
    write ``out/flights.csv``, ``out/signals.csv`` and ``out/left_out.csv``."""
    folder, out = Path(folder), Path(out)
    rows, left_out = read_labels(folder)
    processed = out / "processed"
    processed.mkdir(parents=True, exist_ok=True)
    readers = _readers_digest()
    converted, gives = [], []
    for row in rows:
        path = folder / row["log"]
        try:
            key = {"sha256": _file_sha256(path), "readers": readers,
                   "row": {k: v for k, v in row.items() if k != "line"}}
            flight, given = _convert_once(path, row, key, processed)
        except CorpusError:
            raise
        except (_LeftOut, AlfaDataError, OSError, ValueError, KeyError, IndexError,
                TypeError, struct.error) as e:
            # a reader meets what the log's writer wrote: a broken log is that log's
            # trouble, named, and the others are converted
            field = e.field if isinstance(e, _LeftOut) else "log"
            left_out.append({"log": row["log"], "file": row["log"], "line": row["line"],
                             "field": field, "error": str(e) if isinstance(
                                 e, (_LeftOut, AlfaDataError)) else f"{type(e).__name__}: {e}"})
            log.error("%s (labels.csv line %d): %s: the log is left out", row["log"],
                      row["line"], e)
            continue
        converted.append({"log": row["log"], "flight": flight, "sha256": key["sha256"],
                          "line": row["line"]})
        gives.append(given)
    keep = {c["flight"] for c in converted}
    for stale in processed.iterdir():
        if stale.name not in keep:
            shutil.rmtree(stale) if stale.is_dir() else stale.unlink()
    signals = _corpus_signals(gives, [c["log"] for c in converted])
    flights = pd.DataFrame(converted, columns=["log", "flight", "sha256", "line"])
    left = pd.DataFrame(left_out, columns=LEFT_OUT_COLUMNS)
    flights.to_csv(out / "flights.csv", index=False)
    pd.DataFrame([{"signal": s, "kind": SIGNALS[s].kind, "given": why is None,
                   "why_not": why or ""} for s, why in signals.items()]
                 ).to_csv(out / "signals.csv", index=False)
    left.to_csv(out / "left_out.csv", index=False)
    return LogCorpus(processed, flights, signals, left)


def read_signals(out: str | Path) -> dict[str, str | None]:
    """The signals of the corpus converted into ``out`` (its ``signals.csv``): signal ->
    why the corpus lacks it, None where it has it."""
    table = pd.read_csv(Path(out) / "signals.csv", keep_default_na=False)
    return {r.signal: None if r.given else r.why_not for r in table.itertuples()}


def _corpus_signals(gives: list[dict[str, str | None]], logs: list[str]
                    ) -> dict[str, str | None]:
    """Per catalogue signal: None where every log gives it, else why not (the first
    log's reason, and how many logs lack it)."""
    out = {}
    for name in SIGNALS:
        lacking = [(log_, g[name]) for log_, g in zip(logs, gives, strict=True)
                   if g.get(name) is not None]
        if not gives:
            out[name] = "no log was converted"
        elif lacking:
            first, why = lacking[0]
            out[name] = (f"{why} ({len(lacking)} of {len(gives)} logs, e.g. {first})"
                         if len(gives) > 1 else why)
        else:
            out[name] = None
    return out


def _convert_once(path: Path, row: dict, key: dict, processed: Path
                  ) -> tuple[str, dict[str, str | None]]:
    """The flight folder of one log, reused where ``key`` matches the one it was written
    with; returns its name and, per catalogue signal, why it is not given (None: given)."""
    for done in processed.glob(f"log_*_{row['line']}_*"):
        meta = done / ".source.json"
        if meta.is_file():
            kept = json.loads(meta.read_text())
            if kept["key"] == key:
                return done.name, kept["given"]
    records = read_log(path)
    name, folder = _write_flight(records, row, processed)
    given = {s: _why_not(records, s) for s in SIGNALS}
    (folder / ".source.json").write_text(json.dumps({"key": key, "given": given}, indent=1))
    return name, given


def _why_not(records: LogRecords, name: str) -> str | None:
    sig = SIGNALS[name]
    if sig.minus is None:
        return None if name in records.records else records.not_given.get(
            name, "the log holds no message giving it")
    # a difference needs both of its columns' signals
    terms = [s for s, other in SIGNALS.items() if other.minus is None
             and other.topic == sig.topic and other.column in (sig.column, sig.minus)]
    missing = [s for s in terms if s not in records.records]
    return None if not missing else f"needs {', '.join(missing)}"


def _write_flight(records: LogRecords, row: dict, processed: Path) -> tuple[str, Path]:
    origin = records.origin_s
    start = records.utc_start_s
    group = row["group"]
    if not group:
        if start is None:
            raise _LeftOut("group", "empty, and the log gives no date: give a group")
        group = datetime.fromtimestamp(start, UTC).strftime("%Y-%m-%d")
    clock = ("00-00-00" if start is None else
             datetime.fromtimestamp(start, UTC).strftime("%H-%M-%S"))
    name = f"log_{group}-{clock}_{row['line']}_{_label(row['fault'], row['emergency_trajectory'])}"
    folder = processed / name
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir()
    last = max(float(t[-1]) for t, _ in records.records.values())
    for topic, columns in _topics().items():
        present = {c: s for c, s in columns.items() if s in records.records}
        if present:
            _write_topic(folder / f"{name}-{topic}.csv", present, records.records)
    _write_rows(folder / f"{name}-log-origin.csv", ["field.data"], np.array([origin]),
                np.zeros((1, 1)))
    if row["fault"]:
        onset = origin + row["onset_s"]
        first = min(float(t[0]) for t, _ in records.records.values())
        if not first <= onset <= last:
            raise _LeftOut("onset_s", f"{row['onset_s']} s is outside the log "
                                      f"({first - origin:.2f} to {last - origin:.2f} s on "
                                      "its clock)")
        times = np.arange(onset, last + 1e-9, 1.0 / GROUND_TRUTH_HZ)
        for topic in ALFA_FAULTS.get(row["fault"], [row["fault"]]):
            _write_rows(folder / f"{name}-failure_status-{topic}.csv", ["field.data"], times,
                        np.ones((times.size, 1)))
    return name, folder


def _topics() -> dict[str, dict[str, str]]:
    """Catalogue topic -> {column: the signal it holds} (a difference's columns are its
    terms')."""
    out: dict[str, dict[str, str]] = {}
    for name, sig in SIGNALS.items():
        if sig.minus is None:
            out.setdefault(sig.topic, {})[sig.column] = name
    return out


def _write_topic(path: Path, columns: dict[str, str], records: dict) -> None:
    series = [records[s] for s in columns.values()]
    start = max(float(t[0]) for t, _ in series)
    times = np.unique(np.concatenate([t for t, _ in series]))
    times = times[times >= start]
    values = np.column_stack([v[np.searchsorted(t, times, side="right") - 1]
                              for t, v in series])
    _write_rows(path, list(columns), times, values)


def _write_rows(path: Path, columns: list[str], times: np.ndarray, values: np.ndarray) -> None:
    frame = pd.DataFrame(values, columns=columns)
    frame.insert(0, "%time", np.round(times * 1e9).astype(np.int64))
    frame.to_csv(path, index=False)
