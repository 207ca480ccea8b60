"""An ALFA flight written as the MAVLink messages the map reads, at its logged times.

Each message type of :data:`.mavlink.MESSAGES` is sent at every row time of the topics
its signals come from, from when all of those topics have begun until the first of them
ends (so that no signal is carried beyond its topic's span), carrying each signal's
value held at that time (its topic's last row at or before it): a monitor that holds
each signal by zero-order hold (:func:`alfa_bench.data.hold`) sees on the grid the
values and freshness the data layer samples from the flight. Messages whose fields
carry no time of their own (``NAV_CONTROLLER_OUTPUT``, ``WIND``, ``VFR_HUD``) follow a
``SYSTEM_TIME`` of their time, as an autopilot's stream dates them.

Times: a message's own time fields are the flight clock (``time_boot_ms``,
``time_usec`` from boot); a ``.tlog`` record's timestamp is the flight clock plus a
whole number of seconds, ``epoch_s`` (by default the flight's date and time from its
name), so that a monitor reading the log's clock has the flight's grid.
"""

from __future__ import annotations

import heapq
import os
import struct
import time
from collections.abc import Iterator
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from alfa_bench.data import SIGNALS, Flight, series

from . import mavlink

__all__ = ["flight_epoch_s", "messages", "packets", "send", "write_tlog"]


def flight_epoch_s(flight: Flight) -> int:
    """The flight's date and time from its name (``carbonZ_2018-07-18-15-53-31_...``) as
    whole UNIX seconds, UTC; 0 for a name without them."""
    try:
        when = datetime.strptime(flight.id.split("_")[1], "%Y-%m-%d-%H-%M-%S")
    except (IndexError, ValueError):
        return 0
    return int(when.replace(tzinfo=UTC).timestamp())


def messages(flight: Flight, signals=None) -> Iterator[tuple[float, str, dict]]:
    """``(t, message type, signal values)`` in time order for ``flight``: every message
    type that gives one of ``signals`` (default: every mapped signal the flight has a
    topic for), with those of its signals the flight has (its other fields are 0)."""
    wanted = set(mavlink.fields_for(signals) if signals is not None else
                 [n for ns in mavlink.MESSAGES.values() for n in ns])
    streams = []
    for message, names in mavlink.MESSAGES.items():
        names = [n for n in names if n in wanted and SIGNALS[n].topic in flight.topics]
        if not names:
            continue
        topics = {SIGNALS[n].topic for n in names}
        start = max(float(flight.topic(tp).t[0]) for tp in topics)
        stop = min(float(flight.topic(tp).t[-1]) for tp in topics)
        times = np.unique(np.concatenate([flight.topic(tp).t for tp in topics]))
        times = times[(times >= start) & (times <= stop)]
        held = {}
        for n in names:
            t, v = series(flight, n)
            held[n] = v[np.searchsorted(t, times, side="right") - 1]
        streams.append(_stream(message, times, held))
    yield from heapq.merge(*streams, key=lambda m: (m[0], m[1]))


def _stream(message: str, times: np.ndarray, held: dict) -> Iterator[tuple[float, str, dict]]:
    for i, t in enumerate(times):
        yield float(t), message, {n: float(v[i]) for n, v in held.items()}


def _build(mav, t: float, message: str, values: dict):
    """The pymavlink message of type ``message`` at ``t`` (its time fields the flight
    clock) whose fields give ``values``; a field the map does not set is 0."""
    from pymavlink.dialects.v20 import ardupilotmega

    fields = mavlink.encode(message, values)
    cls = getattr(ardupilotmega, f"MAVLink_{message.lower()}_message")
    clock = {"time_boot_ms": int(round(t * 1e3)), "time_usec": int(round(t * 1e6))}
    args = [clock[n] if n in clock else
            int(round(fields.get(n, 0))) if kind.startswith(("int", "uint")) else
            float(fields.get(n, 0))
            for n, kind in zip(cls.fieldnames, cls.fieldtypes, strict=True)]
    return getattr(mav, f"{message.lower()}_encode")(*args)


def _encoder():
    from pymavlink.dialects.v20 import ardupilotmega

    return ardupilotmega.MAVLink(None, srcSystem=1, srcComponent=1)


def packets(flight: Flight, signals=None) -> Iterator[tuple[float, bytes]]:
    """``(t, MAVLink 2 packet)`` in time order: :func:`messages` packed, each message
    without a time of its own after a ``SYSTEM_TIME`` of its time."""
    mav = _encoder()
    epoch = flight_epoch_s(flight)
    for t, message, values in messages(flight, signals):
        if mavlink.TIMED.get(message, "") is None:
            yield t, mav.system_time_encode(int((epoch + t) * 1e6),
                                            int(round(t * 1e3))).pack(mav)
        yield t, _build(mav, t, message, values).pack(mav)


def write_tlog(flight: Flight, path: str | os.PathLike, signals=None,
               epoch_s: int | None = None) -> Path:
    """The flight's :func:`packets` as a ``.tlog`` (each packet after its 64-bit
    big-endian timestamp in microseconds: the flight clock plus ``epoch_s``)."""
    epoch = flight_epoch_s(flight) if epoch_s is None else epoch_s
    path = Path(path)
    with path.open("wb") as f:
        for t, packet in packets(flight, signals):
            f.write(struct.pack(">Q", round((epoch + t) * 1e6)) + packet)
    return path


def send(flight: Flight, connection, signals=None, speed: float = 1.0) -> int:
    """The flight's :func:`packets` written to ``connection`` (anything with ``write``:
    a pymavlink connection, ``mavutil.mavlink_connection("udpout:host:port")``) at
    their logged times sped up by ``speed`` (``inf``: as fast as it takes them);
    returns the packets sent."""
    start, first, sent = time.monotonic(), None, 0
    for t, packet in packets(flight, signals):
        first = t if first is None else first
        if np.isfinite(speed):
            wait = (t - first) / speed - (time.monotonic() - start)
            if wait > 0:
                time.sleep(wait)
        connection.write(packet)
        sent += 1
    return sent
