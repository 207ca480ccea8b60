"""The numbers the manuscript quotes, and its Markdown twin rendered from them.

The LaTeX manuscript (``paper/paper.tex``) and its Markdown twin
(``paper/paper.template.md``) quote results only by key: ``\\result{key}`` and
``{{num:key}}``, defined here from the workflow's tables. Tables and figures are
included from the files the workflow writes (``\\input``/``{{file:path}}``). An
unknown key or a missing file is an error, so the text cannot quote a number the
run did not produce.

Keys (``<m>`` a method run, ``<s>`` a subset, ``<sig>`` a catalogue signal, ``<c>`` a
fault class): ``deadline`` (s), ``flights:<s>`` (the subset's flights on the common
ground, the flights every ranked run scored), ``ground:<s>`` (the subset's size and, where a
flight was left out, its common ground: "26 flights, 22 on the common ground, 4 left
out"), ``leftout`` (the flights left out and why, or "none"), ``faultfree:<s>``,
``faultflights:<s>``;
scored with the deadline: ``precision:<m>:<s>``, ``recall:<m>:<s>``,
``accuracy:<m>:<s>`` (in %), ``detected:<m>:<s>`` (faults detected in time),
``meandet:<m>:<s>``, ``maxdet:<m>:<s>`` (s); by the paper's rule:
``accuracypaper:<m>:<s>``, ``recallpaper:<m>:<s>`` (%); ``falsealarms:<m>:<s>`` ("k of
n" fault-free flights), ``best:<s>`` and ``bestaccuracy:<s>`` (the best honest method),
``bestdetected:<s>`` and ``bestfalsealarms:<s>`` (its faults detected in time and its
fault-free flights alarmed), ``primary`` (the headline subset's name),
``tied:<s>`` (the runs the exact McNemar test cannot tell apart from it),
``recallnofa:<m>:<s>`` (the best recall of the threshold sweep with no false alarm on
any flight, %), ``leak:<sig>:<c>`` ("k of n" flights on which the signal goes flat at
onset), ``leakchance:<sig>:<c>`` (its larger chance rate, %), ``step:<sig>:<c>:<e>``
("k of n" flights on which it steps at onset, ``<e>`` ``emr`` or ``noemr``: with or
without an emergency trajectory), ``classdetected:<m>:<s>:<c>``
("k of n" faults of class ``c`` detected in time; "n/a" where the subset has none);
from the per-flight table (:mod:`.per_flight`, all labelled flights), in units of the
threshold: ``marginmax:<m>:<c>`` and ``marginmin:<m>:<c>`` (the largest and smallest
in-time margin over the faults of class ``c``), ``marginbefore:<m>`` (the largest
margin before onset, or on a fault-free flight, over all flights); from the injected
sensor faults: ``sensorfaults`` (injected flights scored), ``sensordetected:<m>`` and
``sensorchance:<m>`` (detection and chance rates over the whole grid, %),
``bestsensor`` (the run whose detection rate beats its chance rate by most),
``sensorisolated:<m>`` (sensor named correctly, % of the injected faults) and
``actuatorisolated:<m>`` (actuator class named correctly, % of ALFA's fault flights),
``configurations:<m>`` (the configurations the run scored to choose each fold's: the
candidates of a nested selection, else 1); from the detectability ceiling
(:mod:`.ceiling`): ``ceilingfeature:<s>:<c>``, ``ceilingauc:<s>:<c>`` and
``ceilingreach:<s>:<c>`` (the best single feature of class ``c``, its AUC, and "k of n"
faults above every fault-free maximum); under resampled calibration pools
(:mod:`alfa_bench.analysis.stability`): ``stable:<m>:<s>`` (in-time detections that
survive at least the configured share of the pools; "n/a" without pools),
``detectedpools:<m>:<s>`` (the interval of the in-time detections over the pools,
"lo-hi"), ``rankrange:<m>:<s>`` (its ranks over the pools), ``beststable:<s>`` (the
best honest run's stable detections), ``calflights`` and ``calhours`` (the fewest and
most calibration flights of a fold, and their fault-free hours, "lo-hi"),
``callevel`` (the largest, over the folds, of the smallest per-flight false-alarm
level a fold's flights can check), ``pools`` and ``stableshare`` (the pools each fold
draws, and the share of them a stable detection survives, %; the config's
``stability``); ``paper:precision``,
``paper:recall``, ``paper:accuracy``, ``paper:meandet``, ``paper:maxdet`` (Keipour et
al. 2019, quoted).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd

from alfa_bench.analysis.blocks import FAULT_ORDER
from alfa_bench.analysis.public_study import STUDY_SUMMARY, study_counts
from alfa_bench.analysis.reference import ICRA2019_SUMMARY
from alfa_bench.data import SIGNALS
from alfa_bench.render import latex_escape

from .tables import SIGNIFICANCE, ground_note

__all__ = ["latex_macros", "latex_keys", "paper_numbers", "render_markdown", "sensor_numbers"]

_PLACEHOLDER = re.compile(r"\{\{(num|file):([^}]+)\}\}")
_LATEX_KEY = re.compile(r"\\result\{([^}]+)\}")
_LATEX_COMMENT = re.compile(r"(?<!\\)%.*")
_HTML_COMMENT = re.compile(r"<!--.*?-->", re.DOTALL)


def _pct(v: float) -> str:
    return "n/a" if math.isnan(v) else f"{100 * v:.2f}"


def _sec(v: float) -> str:
    return "n/a" if math.isnan(v) else f"{v:.2f}"


#: the keys of one run on one subset, "n/a" for a configured run with no score there
_PER_RUN = ("precision", "recall", "accuracy", "accuracypaper", "recallpaper", "detected",
            "meandet", "maxdet", "falsealarms", "recallnofa", "stable", "detectedpools",
            "rankrange")


def paper_numbers(comparison: pd.DataFrame, sweep: pd.DataFrame, leakage: pd.DataFrame,
                  by_fault: pd.DataFrame | None = None,
                  per_flight: pd.DataFrame | None = None,
                  methods=(), subsets=(), sensors: dict | None = None,
                  primary: str | None = None,
                  ceiling: pd.DataFrame | None = None,
                  calibration: pd.DataFrame | None = None,
                  stability: dict | None = None,
                  study: pd.DataFrame | None = None,
                  left_out: pd.DataFrame | None = None) -> dict[str, str]:
    """Every quotable number, as text, by key (see the module docstring). A configured
    run (``methods``) with no score on a subset (``subsets``), because every flight of
    it was excluded, quotes "n/a". ``sensors`` holds the ``detectability``,
    ``isolation_sensors`` and ``isolation_actuators`` tables; ``primary`` is the
    headline subset; ``ceiling`` the detectability ceiling's table; ``study`` the public
    study's reproduction against its published table
    (:func:`~alfa_bench.analysis.public_study.against_study`); ``left_out`` the flights
    off the common ground (``left_out.csv``)."""
    # a run that scored no flight of a subset has a row without scores: it quotes "n/a"
    scored = comparison[comparison["flights"] > 0]
    comparison = scored.astype({c: int for c in ("flights", "tp", "fn", "fault_free_flights",
                                                 "fault_free_false_alarms") if c in scored})
    out = {f"{k}:{m}:{s}": "n/a" for k in _PER_RUN for m in methods for s in subsets}
    # every subset's own numbers first, so that a flight set with no flight of a subset
    # (or every one of them left out) still renders
    out |= {f"{k}:{s}": "n/a" for s in subsets
            for k in ("flights", "faultfree", "faultflights", "ground", "bestaccuracy",
                      "bestdetected", "bestfalsealarms", "beststable")}
    out |= {f"{k}:{s}": "none" for s in subsets for k in ("best", "tied")}
    out |= {f"paper:{k}": (_pct if k in ("precision", "recall", "accuracy") else _sec)(
        ICRA2019_SUMMARY[key])
        for k, key in (("precision", "precision"), ("recall", "recall"),
                       ("accuracy", "accuracy"), ("meandet", "mean_detection_s"),
                       ("maxdet", "max_detection_s"))}
    for r in comparison.to_dict(orient="records"):
        m, s = r["method"], r["subset"]
        out["deadline"] = f"{r['deadline_s']:g}"
        for key in ("precision", "recall", "accuracy"):
            out[f"{key}:{m}:{s}"] = _pct(r[key])
        out[f"accuracypaper:{m}:{s}"] = _pct(r["accuracy_paper"])
        out[f"recallpaper:{m}:{s}"] = _pct(r["recall_paper"])
        out[f"detected:{m}:{s}"] = f"{r['tp']} of {r['tp'] + r['fn']}"
        out[f"meandet:{m}:{s}"] = _sec(r["mean_detection_s"])
        out[f"maxdet:{m}:{s}"] = _sec(r["max_detection_s"])
        out[f"falsealarms:{m}:{s}"] = (f"{r['fault_free_false_alarms']} of "
                                       f"{r['fault_free_flights']}")
        pooled = not pd.isna(r.get("stable_detections", math.nan))
        out[f"stable:{m}:{s}"] = str(int(r["stable_detections"])) if pooled else "n/a"
        out[f"detectedpools:{m}:{s}"] = (
            f"{int(r['detections_low'])}-{int(r['detections_high'])}" if pooled else "n/a")
        rank = r.get("rank_range")
        out[f"rankrange:{m}:{s}"] = rank if isinstance(rank, str) else "n/a"
    out["primary"] = primary or "none"
    out["leftout"] = _left_out_words(left_out)
    for s, table in comparison.groupby("subset", sort=False):
        # the common ground: a reference run that failed on a flight scored fewer
        whole = table.loc[table["flights"].idxmax()]
        out[f"flights:{s}"] = str(whole["flights"])
        out[f"faultfree:{s}"] = str(whole["fault_free_flights"])
        # every fault flight is a TP or a FN (an alarm before onset counts as both FP and FN)
        out[f"faultflights:{s}"] = str(whole["tp"] + whole["fn"])
        out[f"ground:{s}"] = ground_note(table)
        best = table[table["rank"] == 1]
        out[f"best:{s}"] = best["method"].iloc[0] if len(best) else "none"
        out[f"bestaccuracy:{s}"] = _pct(best["accuracy"].iloc[0]) if len(best) else "n/a"
        out[f"bestdetected:{s}"] = (out[f"detected:{best['method'].iloc[0]}:{s}"]
                                    if len(best) else "n/a")
        out[f"bestfalsealarms:{s}"] = (out[f"falsealarms:{best['method'].iloc[0]}:{s}"]
                                       if len(best) else "n/a")
        out[f"beststable:{s}"] = (out[f"stable:{best['method'].iloc[0]}:{s}"]
                                  if len(best) else "n/a")
        tied = table[(table["vs_best_p"] >= SIGNIFICANCE) & (table["block"] == "honest")]
        out[f"tied:{s}"] = ", ".join(tied["method"]) or "none"
    for (m, s), table in sweep.groupby(["method", "subset"], sort=False):
        clean = table[table["fp"] == 0]
        out[f"recallnofa:{m}:{s}"] = _pct(clean["recall"].max()) if len(clean) else "n/a"
    out |= _leak_numbers(leakage)
    runs = [*dict.fromkeys([*methods, *comparison["method"]])]
    out |= {f"configurations:{m}": "n/a" for m in runs}
    if "configurations" in comparison:
        for m, n in comparison.groupby("method")["configurations"].max().items():
            out[f"configurations:{m}"] = str(int(n))
    out |= _calibration_numbers(calibration)
    out |= _study_numbers(study)
    out |= {"pools": str(stability["pools"]) if stability else "n/a",
            "stableshare": f"{100 * stability['stable']:g}" if stability else "n/a"}
    out |= _ceiling_numbers(ceiling, [*dict.fromkeys([*subsets, *comparison["subset"]])])
    # every run, subset and class first, so that a flight set without some still renders
    out |= {f"classdetected:{m}:{s}:{c}": "n/a" for m in runs
            for s in [*dict.fromkeys([*subsets, *comparison["subset"]])]
            for c in FAULT_ORDER if c != "none"}
    for r in ([] if by_fault is None else by_fault.to_dict(orient="records")):
        if r["fault_class"] not in ("none", "total"):
            out[f"classdetected:{r['method']}:{r['subset']}:{r['fault_class']}"] = (
                f"{r['detected']} of {r['flights']}")
    out |= {f"{k}:{m}:{c}": "n/a" for k in ("marginmax", "marginmin") for m in runs
            for c in FAULT_ORDER if c != "none"}
    out |= {f"marginbefore:{m}": "n/a" for m in runs}
    if per_flight is not None and not per_flight.empty:
        for (m, c), rows in per_flight.groupby(["method", "fault_class"]):
            margin = rows["margin_in_time"].dropna()
            if c != "none" and len(margin):
                out[f"marginmax:{m}:{c}"] = f"{margin.max():.2f}"
                out[f"marginmin:{m}:{c}"] = f"{margin.min():.2f}"
        for m, rows in per_flight.groupby("method"):
            if rows["margin_before"].notna().any():
                out[f"marginbefore:{m}"] = f"{rows['margin_before'].max():.2f}"
    return out | sensor_numbers(sensors or {}, runs)


def _calibration_numbers(calibration: pd.DataFrame | None) -> dict[str, str]:
    """The folds' calibration data (``calflights``, ``calhours``, ``callevel``)."""
    if calibration is None or calibration.empty:
        return {"calflights": "n/a", "calhours": "n/a", "callevel": "n/a"}
    flights, hours = calibration["flights"], calibration["fault_free_hours"]
    return {"calflights": f"{flights.min()}-{flights.max()}",
            "calhours": f"{hours.min():.2f}-{hours.max():.2f}",
            "callevel": f"{calibration['smallest_level'].max():.3f}"}


def _study_numbers(study: pd.DataFrame | None) -> dict[str, str]:
    """The reproduction against the public study's table: flights with its outcome
    (``studysame``), and TP / FP / FN / TN by its rule, ours (``studyours``), the
    study's on the same flights (``studytheirs``) and on all of its own
    (``studyall``, over ``studyflights``)."""
    out = {"studyall": _counts(STUDY_SUMMARY), "studyflights": str(STUDY_SUMMARY["flights"])}
    if study is None or study.empty:
        return out | dict.fromkeys(("studysame", "studyours", "studytheirs"), "n/a")
    return out | {"studysame": f"{int(study['same'].sum())} of {len(study)}",
                  "studyours": _counts(study_counts(study["outcome"])),
                  "studytheirs": _counts(study_counts(study["study_outcome"]))}


def _counts(c: dict) -> str:
    return " / ".join(str(c[k]) for k in ("tp", "fp", "fn", "tn"))


def _ceiling_numbers(ceiling: pd.DataFrame | None, subsets) -> dict[str, str]:
    """The best single feature per subset and class, "n/a" where the table has none."""
    classes = [c for c in FAULT_ORDER if c != "none"]
    out = {f"{k}:{s}:{c}": "n/a" for k in ("ceilingfeature", "ceilingauc", "ceilingreach")
           for s in subsets for c in classes}
    if ceiling is None or ceiling.empty:
        return out
    best = ceiling[ceiling["best"].astype(str).str.lower() == "true"]
    for r in best.drop_duplicates(["subset", "fault_class"]).to_dict(orient="records"):
        key = f"{r['subset']}:{r['fault_class']}"
        out[f"ceilingfeature:{key}"] = str(r["feature"])
        out[f"ceilingauc:{key}"] = f"{r['auc']:.2f}"
        out[f"ceilingreach:{key}"] = f"{r['above_free_max']} of {r['fault_flights']}"
    return out


def _leak_numbers(leakage: pd.DataFrame) -> dict[str, str]:
    """``leak``/``leakchance`` (the flat test over a class's flights) and ``step``
    (the step test on the class's flights with and without an emergency trajectory),
    for every signal and class: "n/a" where the flights have none."""
    classes = [c for c in FAULT_ORDER if c != "none"]
    out = {f"{k}:{sig}:{c}": "n/a" for k in ("leak", "leakchance") for sig in SIGNALS
           for c in classes}
    out |= {f"step:{sig}:{c}:{e}": "n/a" for sig in SIGNALS for c in classes
            for e in ("emr", "noemr")}
    for (sig, c), g in leakage.groupby(["signal", "fault_class"], sort=False):
        out[f"leak:{sig}:{c}"] = f"{int(g['flat_at_onset'].sum())} of {int(g['flights'].sum())}"
        out[f"leakchance:{sig}:{c}"] = _pct(float(np.nanmax(
            [*g["flat_chance_before"], *g["flat_chance_fault_free"], 0.0])))
        for r in g.to_dict(orient="records"):
            e = "emr" if r["emergency_trajectory"] else "noemr"
            out[f"step:{sig}:{c}:{e}"] = f"{r['step_at_onset']} of {r['step_flights']}"
    return out


def sensor_numbers(tables: dict, runs) -> dict[str, str]:
    """The injected sensor faults' keys (module docstring) from the ``detectability``,
    ``isolation_sensors`` and ``isolation_actuators`` tables; "n/a" for a run or a
    table without rows."""
    out = {f"{k}:{m}": "n/a" for k in ("sensordetected", "sensorchance", "sensorisolated",
                                       "actuatorisolated") for m in runs}
    out |= {"sensorfaults": "0", "bestsensor": "none"}
    grid = tables.get("detectability")
    if grid is not None and len(grid):
        sums = grid.assign(chance=grid["chance_rate"] * grid["flights"]).groupby(
            "method", sort=False)[["detected", "flights", "chance"]].sum()
        rate, chance = sums["detected"] / sums["flights"], sums["chance"] / sums["flights"]
        for m in sums.index:
            out[f"sensordetected:{m}"], out[f"sensorchance:{m}"] = _pct(rate[m]), _pct(chance[m])
        out["bestsensor"] = str((rate - chance).idxmax())
    for key, name in (("sensorisolated", "isolation_sensors"),
                      ("actuatorisolated", "isolation_actuators")):
        table = tables.get(name)
        if table is None or not len(table):
            continue
        correct = table["correct"].astype(str).str.lower() == "true"
        for m, ok in correct.groupby(table["method"], sort=False):
            out[f"{key}:{m}"] = _pct(float(ok.mean()))
        if name == "isolation_sensors":
            out["sensorfaults"] = str(table["flight"].nunique())
    return out


def _left_out_words(left_out: pd.DataFrame | None) -> str:
    """The flights off the common ground and why, in words; "none" without any."""
    if left_out is None or not len(left_out):
        return "none"
    return "; ".join(
        f"{r['flight']} ("
        + ("refused at load" if r["runs"] == "every run" else
           f"failed by {str(r['runs']).replace(';', ', ')} at {r['stage']}")
        + ")" for r in left_out.to_dict(orient="records")
    ) + " (why: results/tables/failures.csv)"


def latex_macros(numbers: dict[str, str]) -> str:
    """``\\result{key}`` for LaTeX; an undefined key stops the build."""
    lines = [r"\newcommand{\result}[1]{\ifcsname abresult@#1\endcsname"
             r"\csname abresult@#1\endcsname\else\errmessage{no result named #1}\fi}"]
    lines += [rf"\expandafter\def\csname abresult@{k}\endcsname{{{latex_escape(v)}}}"
              for k, v in sorted(numbers.items())]
    return "\n".join(lines) + "\n"


def latex_keys(tex: str) -> set[str]:
    """The keys a LaTeX source quotes with ``\\result`` (outside comments)."""
    return set(_LATEX_KEY.findall(_LATEX_COMMENT.sub("", tex)))


def render_markdown(template: str, numbers: dict[str, str], root: Path) -> str:
    """Drop HTML comments, fill ``{{num:key}}`` from ``numbers`` and ``{{file:path}}``
    with the file at ``root / path``; raise ``KeyError`` or ``FileNotFoundError``
    naming what is missing."""
    def fill(match: re.Match) -> str:
        kind, arg = match.group(1), match.group(2).strip()
        if kind == "num":
            if arg not in numbers:
                raise KeyError(f"the manuscript quotes {arg!r}, which no result defines")
            return numbers[arg]
        path = root / arg
        if not path.is_file():
            raise FileNotFoundError(f"the manuscript includes {arg}, which was not written")
        return path.read_text().strip()

    return _PLACEHOLDER.sub(fill, _HTML_COMMENT.sub("", template)).lstrip()
