r"""Physical features of the aircraft's state, from sensors and setpoints only.

Each feature is causal and fitted on nothing: a step against the flight's own recent
past (a window's mean minus the mean of the :data:`BASELINE_S` before it), so it needs
no model of the aircraft and no flight's bias reaches another. Gains are
least-squares slopes over a window,
:math:`\hat k = \sum \dot\phi\,(-e) / (\sum e^2 + n\,e_0^2)`, of a body rate on the
attitude error it should correct, with :math:`e_0` = 1 deg keeping a window without
error from dividing by zero. The specific energy is :math:`h + V^2/2g`, with
:math:`V` the air-relative speed from the local velocity less the wind estimate (the
pitot is dead from 2018-09-11 on).

:data:`FEATURES` names each with the fault class it is a candidate signature of. The
detectability ceiling (:mod:`alfa_bench.analysis.ceiling`) scores each alone; the
coincidence detector (:mod:`.coincidence`) scores them together.
"""

from __future__ import annotations

import numpy as np

from alfa_bench.data import Flight, Sampled, sample

from .windows import step_means, window_steps

__all__ = ["BASELINE_S", "FEATURES", "FEATURE_SIGNAL", "HISTORY_S", "RATE_HZ", "SIGNALS_READ",
           "WARMUP_S", "features", "features_of"]

G = 9.80665
#: the features' grid rate, Hz: the IMU's
RATE_HZ = 10.0
#: the baseline window every step is taken against, s
BASELINE_S = 20.0
#: no feature is read before this, s: its baseline must be full
WARMUP_S = BASELINE_S + 1.0
#: the attitude error that regularises a gain, rad
_E0 = np.deg2rad(1.0)

#: feature -> (the fault class it is a candidate signature of, what it measures)
FEATURES = {
    "accel_x_drop": ("engine", "1 s mean body-x specific force, drop below its baseline"),
    "energy_rate_drop": ("engine", "2 s mean specific energy rate d/dt(h + V²/2g), V the "
                                   "air-relative speed, drop below its baseline"),
    "climb_rate_drop": ("engine", "2 s mean climb rate, drop below its baseline"),
    "pitch_shortfall": ("engine", "1 s mean commanded minus measured pitch, rise above its "
                                  "baseline"),
    "pitch_rate_gain_drop": ("elevator", "2 s pitch-rate gain per pitch error, drop below "
                                         "its baseline"),
    "accel_y_shift": ("rudder", "1 s mean lateral specific force, step either way"),
    "yaw_coupling": ("rudder", "1 s mean yaw rate less the coordinated turn's g tan(roll)/V, "
                               "step either way"),
    "roll_rate_gain_drop": ("aileron", "2 s roll-rate gain per roll error, drop below its "
                                       "baseline"),
    "roll_asymmetry": ("aileron", "5 s roll-rate gains for errors to the left and to the "
                                  "right, their difference"),
    "roll_error_growth": ("aileron", "1 s mean absolute roll error, rise above its baseline"),
}

#: the catalogue signals the features read
SIGNALS_READ = ("roll", "roll_error", "pitch_error", "accel_x", "accel_y", "roll_rate",
                "pitch_rate", "yaw_rate", "rel_alt", "vel_east", "vel_north", "vel_up",
                "wind_east", "wind_north")


def _step(values: np.ndarray, have: np.ndarray, window_s: float) -> np.ndarray:
    """Mean of the fresh finite ``values`` over the last ``window_s`` minus their mean
    over the :data:`BASELINE_S` before."""
    have = have & np.isfinite(values)
    return step_means(values[:, None], have, window_steps(window_s, RATE_HZ),
                      window_steps(BASELINE_S, RATE_HZ))[:, 0]


def _sums(values: np.ndarray, n: int) -> np.ndarray:
    """Sum over the last ``n`` steps (fewer at the start)."""
    c = np.concatenate([[0.0], np.cumsum(values)])
    k = np.arange(1, values.size + 1)
    return c[k] - c[np.maximum(k - n, 0)]


def _gain(rate: np.ndarray, error: np.ndarray, have: np.ndarray, n: int) -> np.ndarray:
    """The window's least-squares gain of ``rate`` on ``-error`` (module docstring), over
    the steps ``have`` marks where both are finite: one NaN would spoil every later sum."""
    have = have & np.isfinite(rate) & np.isfinite(error)
    num = _sums(np.where(have, -rate * error, 0.0), n)
    den = _sums(np.where(have, error ** 2 + _E0 ** 2, 0.0), n)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / den, np.nan)


def _gain_drop(rate, error, have, window_s):
    n, nb = window_steps(window_s, RATE_HZ), window_steps(BASELINE_S, RATE_HZ)
    recent, long = _gain(rate, error, have, n), _gain(rate, error, have, nb)
    base = np.full(rate.size, np.nan)
    base[n:] = long[:-n]                                   # the baseline before the window
    return base - recent


def features(flight: Flight) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The grid times and every feature of :data:`FEATURES` on ``flight``
    (:func:`features_of` its :data:`SIGNALS_READ` sampled at :data:`RATE_HZ`). Raises
    :class:`~alfa_bench.data.AlfaDataError` when the flight lacks a topic they read."""
    s = sample(flight, SIGNALS_READ, RATE_HZ)
    return s.t, features_of(s)


def features_of(s: Sampled, first_step: int = 0) -> dict[str, np.ndarray]:
    """Every feature of :data:`FEATURES` on the grid of ``s`` (which holds
    :data:`SIGNALS_READ`, at :data:`RATE_HZ`): NaN where a window holds no fresh value,
    and in the first :data:`WARMUP_S` of grid steps (``s`` starting at step
    ``first_step`` of its flight, for a stream's recent past). Each value depends on the
    samples up to its own step only."""
    x = dict(zip(s.names, s.x.T, strict=True))
    fresh = dict(zip(s.names, s.fresh.T, strict=True))
    roll_error, pitch_error = np.deg2rad(x["roll_error"]), np.deg2rad(x["pitch_error"])
    air = np.sqrt((x["vel_east"] - x["wind_east"]) ** 2
                  + (x["vel_north"] - x["wind_north"]) ** 2 + x["vel_up"] ** 2)
    energy = x["rel_alt"] + air ** 2 / (2 * G)             # specific energy, m
    lag = window_steps(1.0, RATE_HZ)
    energy_rate = np.full(s.t.size, np.nan)
    energy_rate[lag:] = (energy[lag:] - energy[:-lag]) / (lag / RATE_HZ)
    turn = x["yaw_rate"] - G * np.tan(np.deg2rad(x["roll"])) / np.maximum(air, 5.0)
    roll_imu, n5 = fresh["roll_rate"], window_steps(5.0, RATE_HZ)
    left, right = roll_imu & (roll_error < 0), roll_imu & (roll_error > 0)
    out = {
        "accel_x_drop": -_step(x["accel_x"], fresh["accel_x"], 1.0),
        "energy_rate_drop": -_step(energy_rate, fresh["vel_up"], 2.0),
        "climb_rate_drop": -_step(x["vel_up"], fresh["vel_up"], 2.0),
        "pitch_shortfall": -_step(x["pitch_error"], fresh["pitch_error"], 1.0),
        # the IMU's body y axis points left (ROS), so a nose-up rate is negative
        "pitch_rate_gain_drop": _gain_drop(x["pitch_rate"], -pitch_error, fresh["pitch_rate"],
                                           2.0),
        "accel_y_shift": np.abs(_step(x["accel_y"], fresh["accel_y"], 1.0)),
        "yaw_coupling": np.abs(_step(turn, fresh["yaw_rate"], 1.0)),
        "roll_rate_gain_drop": _gain_drop(x["roll_rate"], roll_error, roll_imu, 2.0),
        "roll_asymmetry": np.abs(_gain(x["roll_rate"], roll_error, left, n5)
                                 - _gain(x["roll_rate"], roll_error, right, n5)),
        "roll_error_growth": _step(np.abs(x["roll_error"]), fresh["roll_error"], 1.0),
    }
    warm = max(0, window_steps(WARMUP_S, RATE_HZ) - first_step)
    for v in out.values():
        v[:warm] = np.nan
    return out


#: per feature, the measured signal it scores: what a detection on it isolates
FEATURE_SIGNAL = {"accel_x_drop": "accel_x", "energy_rate_drop": "rel_alt",
                  "climb_rate_drop": "vel_up", "pitch_shortfall": "pitch_error",
                  "pitch_rate_gain_drop": "pitch_rate", "accel_y_shift": "accel_y",
                  "yaw_coupling": "yaw_rate", "roll_rate_gain_drop": "roll_rate",
                  "roll_asymmetry": "roll_rate", "roll_error_growth": "roll_error"}
#: the stream's recent past that every feature's windows fit in, s
HISTORY_S = BASELINE_S + 4.0
