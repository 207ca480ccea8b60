r"""The detectability ceiling: how well single physical features separate each fault
class from fault-free flight, whatever detector reads them.

For each candidate feature :math:`f(t)` (:data:`FEATURES`: causal, from sensors and
setpoints only, nothing fitted on flights) and each fault class, two sets of
per-flight maxima are compared:

- the *fault* maxima: :math:`\max f` over :math:`[\tau, \tau + D]` on each flight of
  the class, :math:`\tau` its onset and :math:`D` the scoring deadline;
- the *fault-free* maxima: :math:`\max f` over each fault-free segment after the
  warm-up (:data:`WARMUP_S`): whole fault-free flights, and the other flights up to
  :math:`\tau - m` (the calibration margin).

A detector that alarms when :math:`f` passes a threshold and must stay quiet on
fault-free flights needs its threshold above the fault-free maxima, so how far the
two sets overlap bounds what the feature can give. The table reports

.. math::

    \mathrm{AUC} = P(M_\mathrm{fault} > M_\mathrm{free})
                   + \tfrac12\,P(M_\mathrm{fault} = M_\mathrm{free}),

its 95 % bootstrap interval (each set resampled by flight, :data:`BOOTSTRAP` times,
a fixed seed), and ``above_free_max``: how many fault flights pass the largest
fault-free maximum, the detections within :math:`D` that the feature alone could
make with no false alarm on these flights. The fault-free maxima span whole
segments while a fault's span is :math:`D`: that is the comparison a detector faces.
A class whose features all stay near AUC 0.5 has no signature in these signals; the
table shows it rather than asserts it. It bounds single *model-free* features: a
detector that models the manoeuvre (a residual against the commands, a combination of
features) can pass it, and the tables say whether one does.

Every feature is a step against the flight's own recent past (a window's mean minus
the mean of the :data:`BASELINE_S` before it), so it needs no model of the aircraft
and no flight's bias reaches another. Gains are least-squares slopes over a window,
:math:`\hat k = \sum \dot\phi\,(-e) / (\sum e^2 + n\,e_0^2)`, of a body rate on the
attitude error it should correct, with :math:`e_0` = 1 deg keeping a window without
error from dividing by zero.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from alfa_bench.data import AlfaDataError, Flight, sample
from alfa_bench.methods.residual_bank import step_means, window_steps

from .render import fmt, markdown

__all__ = ["BASELINE_S", "BOOTSTRAP", "FEATURES", "RATE_HZ", "SIGNALS_READ", "WARMUP_S",
           "auc_interval", "ceiling_markdown", "ceiling_table", "features"]

log = logging.getLogger(__name__)

G = 9.80665
#: the features' grid rate, Hz: the IMU's
RATE_HZ = 10.0
#: the baseline window every step is taken against, s
BASELINE_S = 20.0
#: no feature is read before this, s: its baseline must be full
WARMUP_S = BASELINE_S + 1.0
#: bootstrap resamples of each interval
BOOTSTRAP = 2000
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
    """The window's least-squares gain of ``rate`` on ``-error`` (module docstring)."""
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
    """The grid times and every feature of :data:`FEATURES` on ``flight``, NaN where
    a window holds no fresh value. Raises :class:`~alfa_bench.data.AlfaDataError` when
    the flight lacks a topic they read."""
    s = sample(flight, SIGNALS_READ, RATE_HZ)
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
    for v in out.values():
        v[s.t < WARMUP_S] = np.nan
    return s.t, out


def _max(v: np.ndarray, keep: np.ndarray) -> float:
    v = v[keep & np.isfinite(v)]
    return float(v.max()) if v.size else np.nan


def auc_interval(fault: np.ndarray, free: np.ndarray, seed: int = 0,
                 n_boot: int = BOOTSTRAP) -> tuple[float, float, float]:
    """AUC of ``fault`` against ``free`` maxima (module docstring) and its 95 %
    percentile bootstrap interval."""
    def auc(a, b):
        d = a[:, None] - b[None, :]
        return float(np.mean((d > 0) + 0.5 * (d == 0)))

    rng = np.random.default_rng(seed)
    boots = [auc(rng.choice(fault, fault.size), rng.choice(free, free.size))
             for _ in range(n_boot)]
    lo, hi = np.quantile(boots, [0.025, 0.975])
    return auc(fault, free), float(lo), float(hi)


def ceiling_table(flights: dict[str, Flight], subsets: dict[str, list[str]], deadline_s: float,
                  margin_s: float) -> pd.DataFrame:
    """One row per subset, fault class and feature (module docstring); ``subsets``
    maps a subset's name to its flights, the headline first.

    Columns: ``subset``, ``fault_class``, ``feature``, ``signature_of`` (the class
    the feature is a candidate for), ``fault_flights``, ``free_segments``, ``auc``,
    ``auc_low``, ``auc_high``, ``above_free_max``, ``best`` (the feature of highest
    AUC for its class and subset) and ``measures``.
    """
    maxima = []
    for name, flight in flights.items():
        if flight.fault is None:
            continue
        try:
            t, feats = features(flight)
        except AlfaDataError as e:
            log.error("%s left out of the ceiling: %s", name, e)
            continue
        onset = flight.fault.onset_s
        free = t < (onset - margin_s) if onset is not None else np.ones(t.size, dtype=bool)
        after = ((t >= onset) & (t <= onset + deadline_s) if onset is not None
                 else np.zeros(t.size, dtype=bool))
        for feature, v in feats.items():
            maxima.append({"flight": name, "fault_class": flight.fault.fault_class,
                           "feature": feature, "free": _max(v, free), "fault": _max(v, after)})
    m = pd.DataFrame(maxima, columns=["flight", "fault_class", "feature", "free", "fault"])
    rows = []
    for subset, names in subsets.items():
        ms = m[m["flight"].isin(names)]
        for (cls, feature), g in ms[ms["fault_class"] != "none"].groupby(
                ["fault_class", "feature"], sort=True):
            fault = g["fault"].dropna().to_numpy()
            free = ms.loc[ms["feature"] == feature, "free"].dropna().to_numpy()
            if not fault.size or not free.size:
                continue
            auc, lo, hi = auc_interval(fault, free)
            rows.append({"subset": subset, "fault_class": cls, "feature": feature,
                         "signature_of": FEATURES[feature][0], "fault_flights": fault.size,
                         "free_segments": free.size, "auc": auc, "auc_low": lo,
                         "auc_high": hi, "above_free_max": int((fault > free.max()).sum()),
                         "measures": FEATURES[feature][1]})
    table = pd.DataFrame(rows, columns=[*_COLUMNS[:-2], "measures"])
    best = table.groupby(["subset", "fault_class"])["auc"].transform("max")
    table["best"] = table["auc"] == best
    return table[list(_COLUMNS)]


_COLUMNS = ("subset", "fault_class", "feature", "signature_of", "fault_flights",
            "free_segments", "auc", "auc_low", "auc_high", "above_free_max", "best", "measures")


def ceiling_markdown(table: pd.DataFrame, deadline_s: float) -> str:
    """Per subset, the best feature of each class (its AUC, interval and reach at no
    false alarm), then every feature."""
    sections = []
    for subset, g in table.groupby("subset", sort=False):
        best = g[g["best"]].drop_duplicates(["fault_class"])
        sections.append((
            f"{subset}: the best single feature per class, within {deadline_s:g} s of onset",
            ["fault", "feature", "AUC", "95 % interval", "above every fault-free max"],
            [[r["fault_class"], f"`{r['feature']}`", fmt(r["auc"]),
              f"{fmt(r['auc_low'])}-{fmt(r['auc_high'])}",
              f"{r['above_free_max']} of {r['fault_flights']}"]
             for r in best.to_dict(orient="records")]))
        sections.append((
            f"{subset}: every feature",
            ["fault", "feature", "signature of", "AUC", "95 % interval",
             "above every fault-free max", "fault-free segments"],
            [[r["fault_class"], f"`{r['feature']}`", r["signature_of"], fmt(r["auc"]),
              f"{fmt(r['auc_low'])}-{fmt(r['auc_high'])}",
              f"{r['above_free_max']} of {r['fault_flights']}", str(r["free_segments"])]
             for r in g.to_dict(orient="records")]))
    features_rows = [[f"`{k}`", v[0], v[1]] for k, v in FEATURES.items()]
    return markdown([("What each feature measures (sensors and setpoints only, nothing "
                      f"fitted; a step is against the {BASELINE_S:g} s before). The ceiling "
                      "of single model-free features: a detector that models the manoeuvre "
                      "can pass it",
                      ["feature", "signature of", "measures"], features_rows), *sections])
