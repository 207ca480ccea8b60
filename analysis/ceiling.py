r"""The detectability ceiling: how well single physical features separate each fault
class from fault-free flight, whatever detector reads them.

For each candidate feature :math:`f(t)` (:data:`~alfa_bench.methods.physics.FEATURES`:
causal, from sensors and setpoints only, nothing fitted on flights) and each fault
class, two sets of per-flight maxima are compared:

- the *fault* maxima: :math:`\max f` over :math:`[\tau, \tau + D]` on each flight of
  the class, :math:`\tau` its onset and :math:`D` the scoring deadline;
- the *fault-free* maxima: :math:`\max f` over each fault-free segment after the
  warm-up (:data:`~alfa_bench.methods.physics.WARMUP_S`): whole fault-free flights,
  and the other flights up to :math:`\tau - m` (the calibration margin).

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

The features are those of :mod:`alfa_bench.methods.physics`.
"""

from __future__ import annotations

import logging
from functools import lru_cache

import numpy as np
import pandas as pd

from alfa_bench.data import AlfaDataError, Flight
from alfa_bench.methods.physics import BASELINE_S, FEATURES, features
from alfa_bench.render import fmt, markdown

__all__ = ["BOOTSTRAP", "auc_interval", "ceiling_markdown", "ceiling_table"]

log = logging.getLogger(__name__)

#: bootstrap resamples of each interval
BOOTSTRAP = 2000


def _max(v: np.ndarray, keep: np.ndarray) -> float:
    v = v[keep & np.isfinite(v)]
    return float(v.max()) if v.size else np.nan


def auc_interval(fault: np.ndarray, free: np.ndarray, seed: int = 0,
                 n_boot: int = BOOTSTRAP) -> tuple[float, float, float]:
    """AUC of ``fault`` against ``free`` maxima (module docstring) and its 95 %
    percentile bootstrap interval.

    A resample draws each fault maximum :math:`a_i` some :math:`c_i` times and each
    fault-free one :math:`b_j` some :math:`c'_j` times, so its AUC is
    :math:`c^\top W c' / (2 n n')` with :math:`W_{ij} = 2[a_i > b_j] + [a_i = b_j]`:
    one product per resample, in integers that float64 holds exactly, so each AUC
    equals the mean over the resample's pairs to the bit."""
    n, m = fault.size, free.size
    fault_counts, free_counts = _resample_counts(n, m, seed, n_boot)
    wins = 2.0 * (fault[:, None] > free[None, :]) + (fault[:, None] == free[None, :])
    boots = ((fault_counts @ wins) * free_counts).sum(axis=1) * 0.5 / (n * m)
    lo, hi = np.quantile(boots, [0.025, 0.975])
    return float(wins.sum() * 0.5 / (n * m)), float(lo), float(hi)


@lru_cache(maxsize=8)
def _resample_counts(n: int, m: int, seed: int, n_boot: int) -> tuple[np.ndarray, np.ndarray]:
    """How often each of ``n`` fault and ``m`` fault-free maxima is drawn, per
    resample: the draws of ``rng.choice(fault, n)`` then ``rng.choice(free, m)``,
    resample after resample. They depend on the sizes and the seed alone, so the
    features of one class share them."""
    rng = np.random.default_rng(seed)
    draws = [(rng.integers(0, n, n), rng.integers(0, m, m)) for _ in range(n_boot)]
    counts = []
    for k, size in enumerate((n, m)):
        at = np.concatenate([d[k] for d in draws]) + np.repeat(np.arange(n_boot) * size, size)
        counts.append(np.bincount(at, minlength=n_boot * size).reshape(n_boot, size)
                      .astype(float))
    return counts[0], counts[1]


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
