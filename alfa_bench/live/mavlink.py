"""Which MAVLink message field gives which catalogue signal, in which unit.

ALFA's aircraft flew ArduPlane with MAVROS; its topics come from these messages. Each
:class:`Field` maps one message field to one signal of
:data:`alfa_bench.data.SIGNALS` by a linear conversion, ``signal = gain * field``; the
replay (:mod:`.replay`) writes a flight's rows through the inverse, the monitor
(:mod:`.monitor`) reads a link through it. MAVLink's body axes are forward-right-down
and its local frame north-east-down; MAVROS's (ALFA's) are forward-left-up and
east-north-up, hence the signs. The differences ``roll_error``, ``pitch_error`` and
``yaw_error`` are measured less commanded, fresh when the measurement is
(:data:`DIFFERENCES`), as the data layer reads them.

``docs/live.md`` tabulates the map; its honest column is the signal's kind: a monitor
refuses a model that reads an ``actuator`` signal (written by ALFA's fault emulation,
``SERVO_OUTPUT_RAW`` and ``VFR_HUD.throttle``) unless told otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["DIFFERENCES", "FIELDS", "MESSAGES", "TIMED", "WIND", "Field", "decode", "encode",
           "fields_for", "messages_for"]


@dataclass(frozen=True)
class Field:
    """``signal = gain * message.field``; ``unit`` is the field's."""

    signal: str
    message: str
    field: str
    unit: str
    gain: float = 1.0


_RAD = 180.0 / math.pi

#: every field read linearly, by signal (the wind: :data:`WIND`)
FIELDS = {f.signal: f for f in [
    Field("accel_x", "HIGHRES_IMU", "xacc", "m/s^2"),
    Field("accel_y", "HIGHRES_IMU", "yacc", "m/s^2", -1.0),
    Field("roll_rate", "HIGHRES_IMU", "xgyro", "rad/s"),
    Field("pitch_rate", "HIGHRES_IMU", "ygyro", "rad/s", -1.0),
    Field("yaw_rate", "HIGHRES_IMU", "zgyro", "rad/s", -1.0),
    Field("roll", "ATTITUDE", "roll", "rad", _RAD),
    Field("pitch", "ATTITUDE", "pitch", "rad", _RAD),
    Field("yaw", "ATTITUDE", "yaw", "rad", _RAD),
    Field("roll_cmd", "NAV_CONTROLLER_OUTPUT", "nav_roll", "deg"),
    Field("pitch_cmd", "NAV_CONTROLLER_OUTPUT", "nav_pitch", "deg"),
    Field("yaw_cmd", "NAV_CONTROLLER_OUTPUT", "nav_bearing", "deg"),
    Field("altitude_error", "NAV_CONTROLLER_OUTPUT", "alt_error", "m"),
    # MAVLink says m/s, but ArduPlane sends cm/s (airspeed_error * 100, its PR 7933),
    # which ALFA logs
    Field("airspeed_error", "NAV_CONTROLLER_OUTPUT", "aspd_error", "cm/s"),
    Field("airspeed", "VFR_HUD", "airspeed", "m/s"),
    Field("rel_alt", "GLOBAL_POSITION_INT", "relative_alt", "mm", 1e-3),
    Field("nav_vel_north", "GLOBAL_POSITION_INT", "vx", "cm/s", 1e-2),
    Field("nav_vel_east", "GLOBAL_POSITION_INT", "vy", "cm/s", 1e-2),
    Field("nav_vel_down", "GLOBAL_POSITION_INT", "vz", "cm/s", 1e-2),
    Field("vel_north", "LOCAL_POSITION_NED", "vx", "m/s"),
    Field("vel_east", "LOCAL_POSITION_NED", "vy", "m/s"),
    Field("vel_up", "LOCAL_POSITION_NED", "vz", "m/s", -1.0),
    Field("servo_elevator", "SERVO_OUTPUT_RAW", "servo1_raw", "us"),
    Field("servo_throttle", "SERVO_OUTPUT_RAW", "servo2_raw", "us"),
    Field("servo_rudder", "SERVO_OUTPUT_RAW", "servo3_raw", "us"),
    Field("servo_aileron_left", "SERVO_OUTPUT_RAW", "servo4_raw", "us"),
    Field("servo_aileron_right", "SERVO_OUTPUT_RAW", "servo5_raw", "us"),
    Field("throttle", "VFR_HUD", "throttle", "%", 1e-2),
]}

#: measured less commanded: difference -> (measured, commanded); fresh with the measured
DIFFERENCES = {"roll_error": ("roll", "roll_cmd"), "pitch_error": ("pitch", "pitch_cmd"),
               "yaw_error": ("yaw", "yaw_cmd")}

#: the messages read, and the field that carries their own time (None: the link's clock)
TIMED = {"HIGHRES_IMU": "time_usec", "ATTITUDE": "time_boot_ms",
         "GLOBAL_POSITION_INT": "time_boot_ms", "LOCAL_POSITION_NED": "time_boot_ms",
         "SERVO_OUTPUT_RAW": "time_usec", "SYSTEM_TIME": "time_boot_ms",
         "NAV_CONTROLLER_OUTPUT": None, "WIND": None, "VFR_HUD": None}

#: ArduPilot's ``WIND`` gives the direction the wind comes from (deg) and its speed: the
#: wind's north and east components are ``-speed * (cos, sin)(direction)``
WIND = ("wind_north", "wind_east")

#: message -> the signals it gives
MESSAGES: dict[str, list[str]] = {"WIND": list(WIND)}
for _f in FIELDS.values():
    MESSAGES.setdefault(_f.message, []).append(_f.signal)


def decode(message: str, get) -> dict[str, float]:
    """The signals message type ``message`` gives, from its fields (``get(name)``)."""
    if message == "WIND":
        a = math.radians(get("direction"))
        return {"wind_north": -get("speed") * math.cos(a),
                "wind_east": -get("speed") * math.sin(a)}
    return {s: FIELDS[s].gain * get(FIELDS[s].field) for s in MESSAGES.get(message, ())}


def encode(message: str, values: dict[str, float]) -> dict[str, float]:
    """:func:`decode` inverted: the fields of ``message`` that give ``values``."""
    if message == "WIND":
        north, east = values["wind_north"], values["wind_east"]
        return {"direction": math.degrees(math.atan2(-east, -north)) % 360.0,
                "speed": math.hypot(north, east), "speed_z": 0.0}
    return {FIELDS[s].field: v / FIELDS[s].gain for s, v in values.items()}


def messages_for(signals) -> list[str]:
    """The message types that give ``signals`` (:func:`fields_for` them)."""
    measured = set(fields_for(signals))
    return [m for m, names in MESSAGES.items() if measured.intersection(names)]


def fields_for(signals) -> list[str]:
    """The measured signals that ``signals`` need from a link (a difference needs its
    two terms), in order, each once. Raises KeyError naming a signal no field gives."""
    out = []
    for name in signals:
        for term in DIFFERENCES.get(name, (name,)):
            if term not in FIELDS and term not in WIND:
                raise KeyError(f"signal {term!r} has no MAVLink field in the map")
            if term not in out:
                out.append(term)
    return out
