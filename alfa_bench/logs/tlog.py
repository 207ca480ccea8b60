"""MAVLink telemetry logs (``.tlog``): the monitor's map, read whole.

The map is the live monitor's (:mod:`alfa_bench.live.mavlink`, tabulated in
``docs/live.md``): one definition for both, so that a flight scored from its ``.tlog``
reads what the monitor reads on the link. The clock is the log's: each record's
64-bit timestamp (UNIX µs, when the ground station received the packet), as the
monitor reads a log. Every message type of the map is read from the system that sent
the first of them. ``airspeed_cmd`` has no MAVLink field: ArduPlane streams only the
error against it.
"""

from __future__ import annotations

import numpy as np

from alfa_bench.live import mavlink

from .records import Entry, LogRecords, check_map, collect, linear

__all__ = ["MAP", "NOT_GIVEN", "read"]

#: the monitor's map as entries (the wind's two signals from its direction and speed),
#: which name what gives each signal; the values are read by the map itself
#: (:func:`alfa_bench.live.mavlink.decode`)
MAP = [*(linear(f.signal, f.message, f.field, f.unit, f.gain) for f in mavlink.FIELDS.values()),
       Entry("wind_north", "WIND", ("direction", "speed"), "deg, m/s",
             "−speed × cos(direction)", lambda d, v: -np.asarray(v) * np.cos(np.radians(d))),
       Entry("wind_east", "WIND", ("direction", "speed"), "deg, m/s",
             "−speed × sin(direction)", lambda d, v: -np.asarray(v) * np.sin(np.radians(d)))]

NOT_GIVEN = {"airspeed_cmd": "no MAVLink message carries the commanded airspeed; "
                             "NAV_CONTROLLER_OUTPUT gives only the error against it"}

check_map(MAP, NOT_GIVEN)


def read(path: str) -> LogRecords:
    """Every mapped signal of the ``.tlog`` at ``path``."""
    from pymavlink import mavutil

    conn = mavutil.mavlink_connection(str(path), robust_parsing=True, dialect="ardupilotmega")
    rows = {s: ([], []) for names in mavlink.MESSAGES.values() for s in names}
    system, first = None, None
    try:
        while (msg := conn.recv_match(type=list(mavlink.MESSAGES))) is not None:
            system = msg.get_srcSystem() if system is None else system
            if msg.get_srcSystem() != system:
                continue
            t = float(msg._timestamp)
            first = t if first is None else first
            for name, value in mavlink.decode(msg.get_type(),
                                              lambda f, m=msg: getattr(m, f)).items():
                rows[name][0].append(t)
                rows[name][1].append(value)
    finally:
        conn.close()
    return collect(str(path), "tlog", "the log's timestamps (UNIX s)", rows, NOT_GIVEN, first,
                   MAP)
