"""What a reader gives: each catalogue signal a log holds as records on the log's clock.

A map entry (:class:`Entry`) gives one signal from one message's fields by a named
conversion; a format's map lists them, and names the catalogue signals it cannot give
(:data:`NOT_GIVEN` of each reader) with the reason, so that a run reading one is named
*not applicable* on that corpus rather than failed.

Times: the records' ``t`` is seconds on the log's clock (:attr:`LogRecords.clock`);
:attr:`LogRecords.origin_s` is the whole second at or before the first record, from
which a flight's clock counts, so that a replayed ALFA flight keeps its own clock.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from alfa_bench.data import SIGNALS, AlfaDataError

__all__ = ["Entry", "LogRecords", "check_map", "collect", "linear", "pick"]


@dataclass(frozen=True)
class Entry:
    """``signal`` from ``message``'s ``fields`` (in ``unit``) by ``convert`` (its
    arguments the fields' values, in order), described in words by ``how``."""

    signal: str
    message: str
    fields: tuple[str, ...]
    unit: str
    how: str
    convert: Callable[..., np.ndarray]


def linear(signal: str, message: str, name: str, unit: str, gain: float = 1.0,
           why: str = "") -> Entry:
    """``signal = gain * message.name``."""
    how = f"{unit}" if gain == 1.0 else f"{unit} × {gain:g}"
    return Entry(signal, message, (name,), unit, how + (f" ({why})" if why else ""),
                 lambda v, g=gain: g * np.asarray(v, dtype=float))


RAD_TO_DEG = 180.0 / math.pi


@dataclass
class LogRecords:
    """The catalogue signals of one log.

    Attributes
    ----------
    path : str
        The log, for messages.
    format : str
        ``tlog``, ``dataflash`` or ``ulog``.
    clock : str
        What the times count: the log's own timestamps, or the autopilot's boot.
    records : dict
        signal -> ``(t, value)``: float arrays, ``t`` increasing, on the log's clock.
    origin_s : float
        The whole second at or before the first record (the flight clock's zero).
    utc_start_s : float or None
        The log's start as UNIX seconds where the log says (a GPS fix, a tlog's
        timestamps), else None.
    not_given : dict
        catalogue signal -> why this log does not give it.
    """

    path: str
    format: str
    clock: str
    records: dict[str, tuple[np.ndarray, np.ndarray]]
    utc_start_s: float | None
    not_given: dict[str, str] = field(default_factory=dict)

    @property
    def origin_s(self) -> float:
        return float(math.floor(min(float(t[0]) for t, _ in self.records.values())))


def collect(path: str, fmt: str, clock: str, rows: dict[str, tuple[list, list]],
            not_given: dict[str, str], utc_start_s: float | None,
            entries: list[Entry]) -> LogRecords:
    """The :class:`LogRecords` of per-signal ``rows`` (lists of times and values, in the
    order read): a signal of the map (``entries``) without a record is not given, the
    log holding none of the messages that give it; each signal's records are put in
    time order, a repeated time keeps its last record, as the data layer does with
    ALFA's rows."""
    records, missing = {}, dict(not_given)
    sources: dict[str, list[str]] = {}
    for e in entries:
        sources.setdefault(e.signal, []).append(f"{e.message}.{'/'.join(e.fields)}")
    for name, sent in sources.items():
        if not rows.get(name, ((), ()))[0]:
            missing.setdefault(name, f"the log holds no {' nor '.join(dict.fromkeys(sent))}")
    for name, (t, v) in rows.items():
        if not t:
            continue
        t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
        order = np.argsort(t, kind="stable")
        t, v = t[order], v[order]
        keep = np.r_[t[1:] != t[:-1], True]
        records[name] = (t[keep], v[keep])
    if not records:
        raise AlfaDataError("the log holds no message its map reads", file=path)
    for name in SIGNALS:
        if name not in records and SIGNALS[name].minus is None:
            missing.setdefault(name, "the format's map has no field for it")
    return LogRecords(path, fmt, clock, records, utc_start_s, missing)


def check_map(entries: list[Entry], not_given: dict[str, str]) -> None:
    """A map names catalogue signals only, and none both as given and as not given (a
    signal named by several entries is read from the first whose message the log
    holds: :func:`pick`)."""
    named = [e.signal for e in entries]
    for name in [*named, *not_given]:
        if name not in SIGNALS:
            raise KeyError(f"map names {name!r}, not a catalogue signal")
    if both := set(named) & set(not_given):
        raise ValueError(f"map both gives and does not give {sorted(both)}")


def pick(entries: list[Entry], columns) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per signal, ``(t, value)`` from the first of its entries whose message and fields
    ``columns(message)`` has (None, or a mapping of field -> array with ``t``)."""
    out = {}
    for e in entries:
        if e.signal in out or (table := columns(e.message)) is None:
            continue
        if all(f in table for f in e.fields):
            out[e.signal] = (table["t"], e.convert(*(table[f] for f in e.fields)))
    return out
