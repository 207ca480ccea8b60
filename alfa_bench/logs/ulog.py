"""PX4 ULogs (``.ulg``), read by ``pyulog`` (the ``logs`` extra).

The clock is the autopilot's boot (each message's ``timestamp``, µs), the log's own.
Each topic's first instance (``multi_id`` 0) is read. PX4's body axes are
forward-right-down and its frame north-east-down; ALFA's (MAVROS's) forward-left-up and
east-north-up, hence the signs, as in the MAVLink map. Attitude comes as a quaternion
(``q[0]`` the scalar), turned into ZYX Euler angles as ArduPilot reports them. Where a
signal has two entries the first whose topic the log holds is read (PX4 renamed
topics across releases). The throttle (``actuator_controls_0``) is an ``actuator``
signal; PX4's servo outputs follow the airframe's mixer, so no output is named as one
of ALFA's servos.

The log's start in UTC comes from ``vehicle_gps_position.time_utc_usec`` where a fix
gave one. ``tecs_status`` (the fixed-wing energy controller) gives the altitude and
airspeed errors and the commanded airspeed; a multicopter's log has none.
"""

from __future__ import annotations

import numpy as np

from .records import RAD_TO_DEG, Entry, LogRecords, check_map, collect, linear, pick

__all__ = ["MAP", "NOT_GIVEN", "read"]

_FRD = "FRD/NED to FLU/ENU"
_Q = ("q[0]", "q[1]", "q[2]", "q[3]")


def _roll(w, x, y, z):
    return RAD_TO_DEG * np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))


def _pitch(w, x, y, z):
    return RAD_TO_DEG * np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))


def _yaw(w, x, y, z):
    return RAD_TO_DEG * np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def _difference(gain):
    return lambda a, b: gain * (np.asarray(a, float) - np.asarray(b, float))


MAP = [
    Entry("roll", "vehicle_attitude", _Q, "1", "quaternion to ZYX roll, deg", _roll),
    Entry("pitch", "vehicle_attitude", _Q, "1", "quaternion to ZYX pitch, deg", _pitch),
    Entry("yaw", "vehicle_attitude", _Q, "1", "quaternion to ZYX yaw, deg", _yaw),
    linear("roll_cmd", "vehicle_attitude_setpoint", "roll_body", "rad", RAD_TO_DEG, "to deg"),
    linear("pitch_cmd", "vehicle_attitude_setpoint", "pitch_body", "rad", RAD_TO_DEG,
           "to deg"),
    linear("yaw_cmd", "vehicle_attitude_setpoint", "yaw_body", "rad", RAD_TO_DEG, "to deg"),
    linear("roll_rate", "vehicle_angular_velocity", "xyz[0]", "rad/s"),
    linear("pitch_rate", "vehicle_angular_velocity", "xyz[1]", "rad/s", -1.0, _FRD),
    linear("yaw_rate", "vehicle_angular_velocity", "xyz[2]", "rad/s", -1.0, _FRD),
    linear("roll_rate", "sensor_combined", "gyro_rad[0]", "rad/s"),
    linear("pitch_rate", "sensor_combined", "gyro_rad[1]", "rad/s", -1.0, _FRD),
    linear("yaw_rate", "sensor_combined", "gyro_rad[2]", "rad/s", -1.0, _FRD),
    linear("accel_x", "sensor_combined", "accelerometer_m_s2[0]", "m/s^2"),
    linear("accel_y", "sensor_combined", "accelerometer_m_s2[1]", "m/s^2", -1.0, _FRD),
    linear("airspeed", "airspeed_validated", "indicated_airspeed_m_s", "m/s"),
    linear("airspeed_cmd", "tecs_status", "true_airspeed_sp", "m/s"),
    linear("airspeed_cmd", "tecs_status", "airspeed_sp", "m/s"),
    Entry("altitude_error", "tecs_status", ("altitude_sp", "altitude_filtered"), "m",
          "altitude_sp − altitude_filtered", _difference(1.0)),
    Entry("airspeed_error", "tecs_status", ("true_airspeed_sp", "true_airspeed_filtered"),
          "m/s", "(true_airspeed_sp − true_airspeed_filtered) × 100, to cm/s",
          _difference(100.0)),
    Entry("airspeed_error", "tecs_status", ("airspeed_sp", "airspeed_filtered"), "m/s",
          "(airspeed_sp − airspeed_filtered) × 100, to cm/s", _difference(100.0)),
    linear("rel_alt", "vehicle_local_position", "z", "m", -1.0,
           "down to up: height above the local origin"),
    linear("vel_north", "vehicle_local_position", "vx", "m/s"),
    linear("vel_east", "vehicle_local_position", "vy", "m/s"),
    linear("vel_up", "vehicle_local_position", "vz", "m/s", -1.0, "down to up"),
    # PX4 has one navigation estimate: the autopilot's velocity is the same EKF's
    linear("nav_vel_north", "vehicle_local_position", "vx", "m/s"),
    linear("nav_vel_east", "vehicle_local_position", "vy", "m/s"),
    linear("nav_vel_down", "vehicle_local_position", "vz", "m/s"),
    linear("wind_north", "wind", "windspeed_north", "m/s"),
    linear("wind_east", "wind", "windspeed_east", "m/s"),
    linear("wind_north", "wind_estimate", "windspeed_north", "m/s"),
    linear("wind_east", "wind_estimate", "windspeed_east", "m/s"),
    linear("throttle", "actuator_controls_0", "control[3]", "1"),
]

_SERVOS = "PX4's outputs follow the airframe's mixer: no output is one of ALFA's servos"
NOT_GIVEN = {s: _SERVOS for s in ("servo_elevator", "servo_throttle", "servo_rudder",
                                  "servo_aileron_left", "servo_aileron_right")}

check_map(MAP, NOT_GIVEN)


def read(path: str) -> LogRecords:
    """Every mapped signal of the ULog at ``path``."""
    from pyulog import ULog

    topics = sorted({e.message for e in MAP} | {"vehicle_gps_position"})
    ulog = ULog(str(path), topics)
    data = {d.name: d.data for d in ulog.data_list if d.multi_id == 0}

    def columns(message):
        table = data.get(message)
        if table is None or not len(table["timestamp"]):
            return None
        return {**table, "t": table["timestamp"] * 1e-6}

    rows = {name: (list(t), list(v)) for name, (t, v) in pick(MAP, columns).items()}
    return collect(str(path), "ulog", "the autopilot's boot (timestamp, s)", rows,
                   NOT_GIVEN, _utc_start(data, rows), MAP)


def _utc_start(data: dict, rows: dict) -> float | None:
    gps = data.get("vehicle_gps_position")
    if gps is None or "time_utc_usec" not in gps or not rows:
        return None
    fixed = np.flatnonzero(gps["time_utc_usec"] > 0)
    if not fixed.size:
        return None
    i = fixed[0]
    first = min(t[0] for t, _ in rows.values() if t)
    return float(gps["time_utc_usec"][i] * 1e-6 - (gps["timestamp"][i] * 1e-6 - first))
