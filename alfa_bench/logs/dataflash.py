"""ArduPilot DataFlash logs (``.bin``), read by pymavlink's ``DFReader``.

The clock is the autopilot's boot (each message's ``TimeUS``), the log's own. A
message type logged for several sensors (``IMU``, ``ARSP``, ``BARO``, ``GPS`` with an
instance field ``I``) is read for the first one. ArduPlane's body axes are
forward-right-down and its frame north-east-down; ALFA's (MAVROS's) forward-left-up and
east-north-up, hence the signs, as in the MAVLink map. The servo channels follow the
MAVLink map's (``RCOU.C1`` is ``SERVO_OUTPUT_RAW.servo1_raw``): outputs and throttle are
``actuator`` signals, which the leak rules keep apart on every corpus.

Where a signal has two entries the first whose message the log holds is read. The
log's start in UTC comes from its first ``GPS`` fix (GPS week and milliseconds less
the 18 leap seconds of 2017 on), where it has one.
"""

from __future__ import annotations

import math

import numpy as np

from .records import Entry, LogRecords, check_map, collect, linear, pick

__all__ = ["MAP", "NOT_GIVEN", "read"]

_FRD = "FRD/NED to FLU/ENU"


def _from_course(trig):
    return lambda speed, course: np.asarray(speed, float) * trig(np.radians(course))


MAP = [
    linear("roll", "ATT", "Roll", "deg"),
    linear("pitch", "ATT", "Pitch", "deg"),
    linear("yaw", "ATT", "Yaw", "deg"),
    linear("roll_cmd", "CTUN", "NavRoll", "deg"),
    linear("pitch_cmd", "CTUN", "NavPitch", "deg"),
    linear("yaw_cmd", "NTUN", "NavBrg", "deg"),
    linear("altitude_error", "NTUN", "AltErr", "m"),
    linear("airspeed_error", "NTUN", "ArspdErr", "m/s", 100.0, "to cm/s, as ALFA logs it"),
    linear("roll_rate", "IMU", "GyrX", "rad/s"),
    linear("pitch_rate", "IMU", "GyrY", "rad/s", -1.0, _FRD),
    linear("yaw_rate", "IMU", "GyrZ", "rad/s", -1.0, _FRD),
    linear("accel_x", "IMU", "AccX", "m/s^2"),
    linear("accel_y", "IMU", "AccY", "m/s^2", -1.0, _FRD),
    linear("airspeed", "ARSP", "Airspeed", "m/s"),
    linear("rel_alt", "BARO", "Alt", "m", why="the barometer's height above its "
                                              "calibration on the ground"),
    Entry("vel_north", "GPS", ("Spd", "GCrs"), "m/s, deg", "Spd × cos(GCrs)",
          _from_course(np.cos)),
    Entry("vel_east", "GPS", ("Spd", "GCrs"), "m/s, deg", "Spd × sin(GCrs)",
          _from_course(np.sin)),
    linear("vel_up", "GPS", "VZ", "m/s", -1.0, "down to up"),
    # the EKF's estimate: NKF* from EKF2, XKF* from EKF3 (ArduPilot 4.0 on)
    linear("nav_vel_north", "NKF1", "VN", "m/s"),
    linear("nav_vel_east", "NKF1", "VE", "m/s"),
    linear("nav_vel_down", "NKF1", "VD", "m/s"),
    linear("nav_vel_north", "XKF1", "VN", "m/s"),
    linear("nav_vel_east", "XKF1", "VE", "m/s"),
    linear("nav_vel_down", "XKF1", "VD", "m/s"),
    linear("wind_north", "NKF2", "VWN", "m/s"),
    linear("wind_east", "NKF2", "VWE", "m/s"),
    linear("wind_north", "XKF2", "VWN", "m/s"),
    linear("wind_east", "XKF2", "VWE", "m/s"),
    linear("servo_elevator", "RCOU", "C1", "us"),
    linear("servo_throttle", "RCOU", "C2", "us"),
    linear("servo_rudder", "RCOU", "C3", "us"),
    linear("servo_aileron_left", "RCOU", "C4", "us"),
    linear("servo_aileron_right", "RCOU", "C5", "us"),
    linear("throttle", "CTUN", "ThrOut", "%", 0.01, "to 0-1"),
]

NOT_GIVEN = {"airspeed_cmd": "DataFlash logs the airspeed error (NTUN), not the demand"}

check_map(MAP, NOT_GIVEN)

#: message types with an instance field: the first instance is read
_INSTANCED = {"IMU", "ARSP", "BARO", "GPS"}
#: GPS time (1980-01-06) as UNIX s, and the leap seconds since (from 2017-01-01)
_GPS_EPOCH_S, _LEAP_S = 315964800, 18


def read(path: str) -> LogRecords:
    """Every mapped signal of the DataFlash log at ``path``."""
    from pymavlink import DFReader

    log = DFReader.DFReader_binary(str(path), zero_time_base=True)
    wanted = sorted({e.message for e in MAP} | {"GPS"})
    tables: dict[str, dict[str, list]] = {}
    first_t, utc = None, None
    try:
        while (msg := log.recv_match(type=wanted)) is not None:
            kind = msg.get_type()
            if kind in _INSTANCED and getattr(msg, "I", 0) != 0:
                continue
            t = msg.TimeUS * 1e-6
            first_t = t if first_t is None else first_t
            if kind == "GPS" and utc is None and getattr(msg, "GWk", 0) > 0:
                utc = (_GPS_EPOCH_S + msg.GWk * 604800 + msg.GMS * 1e-3 - _LEAP_S
                       - (t - first_t))
            table = tables.setdefault(kind, {"t": []})
            table["t"].append(t)
            for name in msg.get_fieldnames():
                table.setdefault(name, []).append(getattr(msg, name))
    finally:
        log.close()

    def columns(message):
        table = tables.get(message)
        if table is None:
            return None
        # a field every message of the type logs (its format is the log's own)
        return {k: np.asarray(v, dtype=float) for k, v in table.items()
                if len(v) == len(table["t"]) and not isinstance(v[0], (str, bytes))}

    rows = {name: (list(t), list(v)) for name, (t, v) in pick(MAP, columns).items()}
    return collect(str(path), "dataflash", "the autopilot's boot (TimeUS, s)", rows,
                   NOT_GIVEN, None if utc is None or not math.isfinite(utc) else utc, MAP)
