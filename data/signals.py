"""Named flight signals and their causal sampling on a fixed-rate grid.

Detectors ask for signals by name (``roll_cmd``, ``roll_error``, ...) and a rate;
:func:`sample` returns them on the grid :math:`t_k = k / f_s` of the flight clock.

Sampling is a causal zero-order hold: the value at :math:`t_k` is that of the
latest row with record time :math:`\\le t_k`. Nothing after :math:`t_k` is used,
so no interpolation; the grid covers only the span where every requested topic
has started and none has ended. No value is held longer than ``max_hold_s``
(default :data:`MAX_HOLD_S`): a gap in a topic's rows, or a topic so slow that its
rows are further apart, is an :class:`AlfaDataError` naming the rows, since a
detector fed a stale value would score data that does not exist. (In the ALFA
flights the longest step between rows of a used topic is 0.54 s, in ``rc-out``.)

ALFA topics are sample-and-hold streams (``nav_info`` roll and pitch rows come at
~19.5 Hz, but the measured value changes at ~2.5 Hz). :func:`sample` therefore
also returns, per signal, whether each grid value is *fresh*: it comes from a row
whose measured field changed since the previous grid point.

Every signal has a *kind*, by where it sits relative to ALFA's fault emulation:

``sensor``
    a measurement of the aircraft's state (attitude, body rates, airspeed);
``setpoint``
    the autopilot's command, upstream of the emulation (commanded attitude and
    airspeed, and the attitude errors against them);
``actuator``
    written by the emulation itself: every servo output of ``rc-out`` and the
    throttle of ``vfr_hud``. At onset the failed actuator's output goes flat (the
    throttle to zero), so a method reading these reads the label, not the fault.

:func:`reads_actuators` tells, from a method's signal names alone, whether it reads
such a signal; nobody sets it by hand. :func:`not_measured` finds signals that are
constant over a whole flight (measured airspeed is 0 from 2018-09-11 on).

Bad values and gaps that parse (also in docs/bad-data.md):

- a value outside what its instrument can produce (:attr:`Signal.bounds`: a gyro's
  full scale, an attitude angle's range, a servo pulse's; physics, never fitted on
  flights) fails the flight at load, naming flight, file, column, line and value
  (:func:`check_physical`);
- a topic that :func:`sample` is asked for must cover the flight: start within
  :data:`COVERAGE_S` of its first row and end within it of its last (in ALFA every
  topic does within 1.1 s); one that starts late or stops early would silently
  shorten the span scored, so it is an :class:`AlfaDataError` naming the topic.

A flight is read one way by every run: :func:`check_signals` refuses, at load, a
flight on which any catalogue signal could not be read (a missing topic, a bad cell,
a gap, a topic that does not cover the flight, a value out of bounds), whether or not
a configured run reads it. Left to the runs, such a flight would be scored by some
and not by others, and no two runs would be compared on the same flights. Every
ALFA flight passes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import AlfaDataError, UnknownSignalError
from .flight import Flight

__all__ = ["COVERAGE_S", "KINDS", "MAX_HOLD_S", "SIGNALS", "Sampled", "Signal", "check_physical",
           "check_signals", "first_grid_step", "hold", "not_measured", "reads_actuators", "sample",
           "series"]

#: The longest a row's value may be held on the sampling grid, s.
MAX_HOLD_S = 1.0

#: How much later than the flight's first row a topic that is read may start, and how
#: much earlier than its last row it may end, s.
COVERAGE_S = 5.0

#: Signal kinds, by where they sit relative to the fault emulation (module docstring).
KINDS = ("sensor", "setpoint", "actuator")


@dataclass(frozen=True)
class Signal:
    """A column of a topic, optionally minus another column of the same rows.

    Freshness follows ``column`` (the measured quantity); ``kind`` is one of
    :data:`KINDS`.
    """

    topic: str
    column: str
    kind: str
    minus: str | None = None
    unit: str = ""
    #: the values the instrument can produce at all (``column``'s), from its physics or
    #: a datasheet-like limit, never fitted on flights; None where no limit applies
    bounds: tuple[float, float] | None = None

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"signal kind must be one of {KINDS}, got {self.kind!r}")


#: an attitude angle, deg: roll within a turn, pitch within a quarter turn, heading
#: within one turn either way of its origin
_ANGLE_BOUNDS = {"roll": (-180.0, 180.0), "pitch": (-90.0, 90.0), "yaw": (-360.0, 360.0)}
#: a MEMS gyro's widest full scale, ±2000 deg/s, in rad/s
_RATE_BOUNDS = (-34.91, 34.91)
#: a MEMS accelerometer's widest full scale, ±16 g, in m/s^2
_ACCEL_BOUNDS = (-156.9, 156.9)
#: a speed over ground or of the wind, m/s: past any small aircraft's, or gale's
_SPEED_BOUNDS = (-150.0, 150.0)
#: an RC servo pulse, µs (the standard 1000-2000 µs, extended)
_PWM_BOUNDS = (500.0, 2500.0)


def _attitude(axis: str) -> dict[str, Signal]:
    topic = f"mavros-nav_info-{axis}"
    bounds = _ANGLE_BOUNDS[axis]
    return {
        f"{axis}_cmd": Signal(topic, "field.commanded", "setpoint", unit="deg", bounds=bounds),
        axis: Signal(topic, "field.measured", "sensor", unit="deg", bounds=bounds),
        # measured minus commanded: a setpoint's deviation, fresh with the measurement
        f"{axis}_error": Signal(topic, "field.measured", "setpoint", minus="field.commanded",
                                unit="deg"),
    }


#: The catalogue of named signals.
SIGNALS: dict[str, Signal] = {
    **_attitude("roll"),
    **_attitude("pitch"),
    **_attitude("yaw"),
    # a small aircraft's pitot reads 0 to a few tens of m/s; 100 m/s is past any Carbon Z
    "airspeed_cmd": Signal("mavros-nav_info-airspeed", "field.commanded", "setpoint",
                           unit="m/s", bounds=(0.0, 100.0)),
    "airspeed": Signal("mavros-nav_info-airspeed", "field.measured", "sensor", unit="m/s",
                       bounds=(0.0, 100.0)),
    # the autopilot's own altitude error (target minus measured): the energy its
    # throttle is asked to make up
    "altitude_error": Signal("mavros-nav_info-errors", "field.alt_error", "setpoint", unit="m",
                             bounds=(-5000.0, 5000.0)),
    # the autopilot's airspeed error (target minus its airspeed estimate, which is
    # synthetic where the pitot is dead, so it is live on every flight), in cm/s as logged
    "airspeed_error": Signal("mavros-nav_info-errors", "field.aspd_error", "setpoint",
                             unit="cm/s", bounds=(-10000.0, 10000.0)),
    # body rates from the raw IMU, the freshest sensor in ALFA (~10 Hz, every row new)
    "roll_rate": Signal("mavros-imu-data_raw", "field.angular_velocity.x", "sensor",
                        unit="rad/s", bounds=_RATE_BOUNDS),
    "pitch_rate": Signal("mavros-imu-data_raw", "field.angular_velocity.y", "sensor",
                         unit="rad/s", bounds=_RATE_BOUNDS),
    "yaw_rate": Signal("mavros-imu-data_raw", "field.angular_velocity.z", "sensor",
                       unit="rad/s", bounds=_RATE_BOUNDS),
    # specific force in body axes from the same IMU rows: thrust minus drag along x,
    # sideslip along y (gravity included: x reads g sin(pitch) in steady flight)
    "accel_x": Signal("mavros-imu-data_raw", "field.linear_acceleration.x", "sensor",
                      unit="m/s^2", bounds=_ACCEL_BOUNDS),
    "accel_y": Signal("mavros-imu-data_raw", "field.linear_acceleration.y", "sensor",
                      unit="m/s^2", bounds=_ACCEL_BOUNDS),
    # the aircraft's energy (~4 Hz): height above home and velocity in mavros's local
    # ENU frame (x east, y north, z up), and the autopilot's wind estimate (~2 Hz, the
    # same frame); with the wind, the air-relative speed is live where the pitot is dead
    "rel_alt": Signal("mavros-global_position-rel_alt", "field.data", "sensor", unit="m",
                      bounds=(-1000.0, 10000.0)),
    "vel_east": Signal("mavros-local_position-velocity", "field.twist.linear.x", "sensor",
                       unit="m/s", bounds=_SPEED_BOUNDS),
    "vel_north": Signal("mavros-local_position-velocity", "field.twist.linear.y", "sensor",
                        unit="m/s", bounds=_SPEED_BOUNDS),
    "vel_up": Signal("mavros-local_position-velocity", "field.twist.linear.z", "sensor",
                     unit="m/s", bounds=_SPEED_BOUNDS),
    # the autopilot's own velocity estimate (nav_info, NED as its frame_id says, rows
    # ~19 Hz)
    "nav_vel_north": Signal("mavros-nav_info-velocity", "field.meas_x", "sensor", unit="m/s",
                            bounds=_SPEED_BOUNDS),
    "nav_vel_east": Signal("mavros-nav_info-velocity", "field.meas_y", "sensor", unit="m/s",
                           bounds=_SPEED_BOUNDS),
    "nav_vel_down": Signal("mavros-nav_info-velocity", "field.meas_z", "sensor", unit="m/s",
                           bounds=_SPEED_BOUNDS),
    "wind_east": Signal("mavros-wind_estimation", "field.twist.linear.x", "sensor",
                        unit="m/s", bounds=_SPEED_BOUNDS),
    "wind_north": Signal("mavros-wind_estimation", "field.twist.linear.y", "sensor",
                         unit="m/s", bounds=_SPEED_BOUNDS),
    # servo outputs (~3 Hz). ALFA does not name the channels; the mapping follows the
    # data: channels4 and 5 track roll rate (ailerons, r ~ 0.6-0.9), channels1 pitch rate
    # (elevator), channels2 drops to idle at every engine failure (throttle), channels3
    # is the one left (rudder); channels0, 6 and 7 never move.
    "servo_elevator": Signal("mavros-rc-out", "field.channels1", "actuator", unit="us",
                             bounds=_PWM_BOUNDS),
    "servo_throttle": Signal("mavros-rc-out", "field.channels2", "actuator", unit="us",
                             bounds=_PWM_BOUNDS),
    "servo_rudder": Signal("mavros-rc-out", "field.channels3", "actuator", unit="us",
                           bounds=_PWM_BOUNDS),
    "servo_aileron_left": Signal("mavros-rc-out", "field.channels4", "actuator", unit="us",
                                 bounds=_PWM_BOUNDS),
    "servo_aileron_right": Signal("mavros-rc-out", "field.channels5", "actuator", unit="us",
                                  bounds=_PWM_BOUNDS),
    "throttle": Signal("mavros-vfr_hud", "field.throttle", "actuator", unit="1",
                       bounds=(0.0, 1.0)),
}


@dataclass(frozen=True)
class Sampled:
    """Signals on a fixed grid.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Grid times on the flight clock, s.
    x : ndarray, shape (n, m)
        Held values of the m signals, in the order requested.
    fresh : ndarray of bool, shape (n, m)
        True where the value comes from a new measurement.
    names : tuple of str
    flight : str
        The flight sampled: what calibration checks to keep a scored flight out of a fit.
    """

    t: np.ndarray
    x: np.ndarray
    fresh: np.ndarray
    names: tuple[str, ...]
    flight: str = ""

    def before(self, t_s: float) -> Sampled:
        """The grid steps strictly before ``t_s``."""
        n = int(np.searchsorted(self.t, t_s, side="left"))
        return Sampled(t=self.t[:n], x=self.x[:n], fresh=self.fresh[:n], names=self.names,
                       flight=self.flight)

    def since(self, k: int) -> Sampled:
        """The grid steps from step ``k`` on."""
        return Sampled(t=self.t[k:], x=self.x[k:], fresh=self.fresh[k:], names=self.names,
                       flight=self.flight)

    def columns(self, names) -> Sampled:
        """The signals ``names`` (each one of :attr:`names`), in that order."""
        idx = [self.names.index(n) for n in names]
        return Sampled(t=self.t, x=self.x[:, idx], fresh=self.fresh[:, idx], names=tuple(names),
                       flight=self.flight)


def series(flight: Flight, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Signal ``name`` of ``flight`` at its topic's record times: ``(t, value)``."""
    if name not in SIGNALS:
        raise UnknownSignalError(f"unknown signal {name!r}; known: {sorted(SIGNALS)}")
    sig = SIGNALS[name]
    tp = flight.topic(sig.topic)
    value = tp.values(sig.column)
    return tp.t, value - tp.values(sig.minus) if sig.minus else value


def reads_actuators(names) -> bool:
    """Whether the signals ``names`` include one the fault emulation writes."""
    return any(SIGNALS[n].kind == "actuator" for n in names)


def not_measured(flight: Flight, names=None) -> tuple[str, ...]:
    """The sensors among ``names`` (default: every catalogue signal whose topic and
    column the flight has) that are constant over the whole flight: not measured on it. A
    constant setpoint is a command that did not change, and a constant actuator an
    output not used; neither is missing data."""
    if names is None:
        names = [n for n, sig in SIGNALS.items() if sig.topic in flight.topics
                 and flight.topics[sig.topic].has(sig.column)]
    dead = []
    for name in (n for n in names if SIGNALS[n].kind == "sensor"):
        value = series(flight, name)[1]
        if value.size and np.all(value == value[0]):
            dead.append(name)
    return tuple(dead)


def check_signals(flight: Flight, names=None) -> None:
    """Raise :class:`AlfaDataError` where any of the signals ``names`` of ``flight``
    (default: the whole catalogue; a corpus of logs, the signals it has) could not be
    read the way :func:`sample` reads it: a missing topic, a topic that does not
    cover the flight, a gap of more than :data:`MAX_HOLD_S` between rows, a cell that
    is not a finite number, a value outside the signal's bounds (:func:`check_physical`).
    Called at load, so that a flight is refused for every run or read by all alike."""
    names = list(SIGNALS) if names is None else list(names)
    for tp in dict.fromkeys(flight.topic(SIGNALS[n].topic) for n in names):
        _check_coverage(flight, tp)
        _check_gaps(flight, tp)
    for name in names:
        series(flight, name)
    check_physical(flight, names)


def check_physical(flight: Flight, names=None) -> None:
    """Raise :class:`AlfaDataError` at the first value of a signal's column (of
    ``names``, default the catalogue) outside its :attr:`Signal.bounds` (module
    docstring); a topic the flight lacks is passed over (:func:`check_signals` refuses
    it)."""
    for name in SIGNALS if names is None else names:
        sig = SIGNALS[name]
        if sig.bounds is None or sig.topic not in flight.topics:
            continue
        tp = flight.topics[sig.topic]
        value = tp.values(sig.column)
        lo, hi = sig.bounds
        out = (value < lo) | (value > hi)
        if out.any():
            i = int(np.argmax(out))
            raise AlfaDataError(
                f"{value[i]:.6g} {sig.unit} is outside what {name} can read ({lo:g} to "
                f"{hi:g} {sig.unit}): not a physical value", flight=flight.id, file=tp.file,
                column=sig.column, line=int(tp.lines[i]))


def _check_coverage(flight: Flight, tp) -> None:
    late = float(tp.t[0])
    early = flight.duration_s - float(tp.t[-1])
    if late > COVERAGE_S or early > COVERAGE_S:
        what = (f"starts {late:.1f} s after the flight's first row" if late > COVERAGE_S
                else f"ends {early:.1f} s before the flight's last row")
        raise AlfaDataError(f"topic {what} (limit {COVERAGE_S:g} s): scored, it would "
                            "shorten the span judged", flight=flight.id, file=tp.file,
                            column="%time", line=int(tp.lines[0 if late > COVERAGE_S else -1]))


def _check_gaps(flight: Flight, tp, max_hold_s: float = MAX_HOLD_S) -> None:
    """Refuse a topic with more than ``max_hold_s`` between two rows: on a grid a value
    would be held that long."""
    step = np.diff(tp.t)
    if step.size and step.max() > max_hold_s:
        i = int(np.argmax(step > max_hold_s))
        median = float(np.median(step))
        raise AlfaDataError(
            f"no row for {step[i]:.2f} s (from {tp.t[i]:.2f} s to {tp.t[i + 1]:.2f} s on the "
            f"flight clock; the topic's median period is {median:.2f} s): a value would be "
            f"held longer than {max_hold_s} s", flight=flight.id, file=tp.file,
            column="%time", line=int(tp.lines[i + 1]))


def sample(flight: Flight, names: tuple[str, ...] | list[str], rate_hz: float,
           max_hold_s: float = MAX_HOLD_S) -> Sampled:
    """Sample the named signals of ``flight`` at ``rate_hz`` (causal hold)."""
    names = tuple(names)
    unknown = [n for n in names if n not in SIGNALS]
    if unknown:
        raise UnknownSignalError(f"unknown signal(s) {unknown}; known: {sorted(SIGNALS)}")
    topics = [flight.topic(SIGNALS[n].topic) for n in names]
    for tp in dict.fromkeys(topics):
        _check_coverage(flight, tp)
    start = max(float(tp.t[0]) for tp in topics)
    stop = min(float(tp.t[-1]) for tp in topics)
    k = np.arange(first_grid_step(start, rate_hz), np.floor(stop * rate_hz) + 1)
    t = k / rate_hz
    if t.size == 0:
        raise AlfaDataError(f"signals {list(names)} never overlap in time", flight=flight.id)

    for tp in dict.fromkeys(topics):
        _check_gaps(flight, tp, max_hold_s)
    x = np.empty((t.size, len(names)))
    fresh = np.empty((t.size, len(names)), dtype=bool)
    for j, (name, tp) in enumerate(zip(names, topics, strict=True)):
        measured = tp.values(SIGNALS[name].column)
        row, source = hold(tp.t, np.r_[True, measured[1:] != measured[:-1]], t)
        x[:, j] = series(flight, name)[1][row]
        fresh[:, j] = np.r_[True, source[1:] != source[:-1]]
    return Sampled(t=t, x=x, fresh=fresh, names=names, flight=flight.id)


def first_grid_step(start_s: float, rate_hz: float) -> int:
    r"""The first grid step :math:`k` with :math:`k / f \ge` ``start_s``: ``ceil`` of the
    product alone can fall one step short in floating point (1.7000000000000002 s at
    10 Hz gives 17, and 1.7 s holds no record yet)."""
    k = math.ceil(start_s * rate_hz)
    return k + 1 if k / rate_hz < start_s else k


def hold(t_records: np.ndarray, changed: np.ndarray,
         t_grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The zero-order hold of one signal's records onto grid times, as :func:`sample`
    resamples ALFA and a live monitor its link: per grid time, the index of the last
    record at or before it (its value is held) and the index of the last record at or
    before it whose value had ``changed`` from the record before (a grid step whose
    source differs from the step before's holds a fresh value). The records are in
    time order; every grid time is at or after the first."""
    row = np.searchsorted(t_records, t_grid, side="right") - 1
    last_change = np.maximum.accumulate(np.where(changed, np.arange(changed.size), 0))
    return row, last_change[row]
