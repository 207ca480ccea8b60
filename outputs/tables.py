"""Summary and per-fault-class tables, as CSV, Markdown and LaTeX.

Every score is counted with the detection deadline first (a first alarm later than
onset + ``deadline_s`` is a miss) and by Keipour et al.'s rule beside it (columns
ending ``_paper``), each rate with its Wilson 95 % interval.

Runs fall in three blocks (:func:`block`), listed in this order and never ranked
together: ``honest`` methods, which read sensors and setpoints only; methods that
read a signal the fault emulation writes (``reads actuators``, marked); and
``reference`` rows (what lateness or the emulation alone gives). Only honest methods
get a rank (by deadline accuracy, then recall, then mean detection time), and each
run is compared with the best honest one on the same flights by the exact McNemar
test (:func:`~.scoring.mcnemar_exact`).

``summary``: one row per (method, subset) with the scoring of
:func:`~.scoring.summarize`. ``comparison``: all methods side by side per subset,
with the false alarms on fault-free flights, how each was calibrated, on how many
flights it armed (judged at all: a method that never arms has no false alarms), and
the paired test. ``by_fault``: the layout of Keipour et al.'s Table I per method and
subset: fault class, flights, flight time, detections, mean and max detection time,
accuracy, and a total row.

Every table compares like with like: runs are scored on the *common ground*, the
labelled flights every ranked (honest) run scored (:func:`common_ground`). A flight
refused at load (for every run), or one that a ranked run failed on (a fold it could
not calibrate), is left out for all of them; ``results/tables/left_out.csv`` lists
those flights with every run that failed on them and each one's error, the
``excluded`` column of the summary and comparison counts them per subset, and
``failed_flights`` counts a run's own failures, which flag it. A reference or
actuator-reading run that failed on a flight leaves it on the common ground: its row
is scored on the flights of it that it scored (``flights``). A run that scored no
flight of a subset has a row all the same, with ``flights`` 0 and no scores.
``results/tables/failures.csv`` (:func:`failures_table`) holds every error.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from alfa_bench.analysis.blocks import BLOCK_MARKS, BLOCKS, FAULT_ORDER, block
from alfa_bench.analysis.isolation import names_class
from alfa_bench.analysis.reference import ICRA2019_BY_FAULT, ICRA2019_NAME, ICRA2019_SUMMARY
from alfa_bench.analysis.scoring import mcnemar_exact, score_records
from alfa_bench.analysis.stability import pool_summaries, stability_table
from alfa_bench.data import FAILURE_COLUMNS, in_subset, subset_flights
from alfa_bench.render import Section, fmt, latex_tables, markdown

__all__ = ["LEFT_OUT_COLUMNS", "SIGNIFICANCE", "SILENT", "by_fault_latex",
           "by_fault_markdown", "by_fault_table", "comparison_latex", "comparison_markdown",
           "common_ground", "comparison_notes", "comparison_table", "configurations",
           "failures_table", "ground_note", "left_out_markdown", "no_fault_note",
           "not_applicable_markdown",
           "not_applicable_table",
           "refit_markdown", "stability_markdown", "summary_latex", "summary_markdown",
           "summary_table", "unscored_notes"]

#: the reference run that arms and never alarms (methods/silent.py): the line to beat
SILENT = "silent"

#: the level below which the exact McNemar test tells two runs apart
SIGNIFICANCE = 0.05


def failures_table(load: pd.DataFrame, per_method: list[pd.DataFrame]) -> pd.DataFrame:
    """Every flight given up: at load (for every method) and per method, in that order."""
    frames = [f for f in [load, *per_method] if len(f)]
    if not frames:
        return pd.DataFrame(columns=[*FAILURE_COLUMNS, "subsets"])
    return pd.concat(frames, ignore_index=True).reindex(columns=[*FAILURE_COLUMNS, "subsets"])


#: the columns of ``left_out.csv``: a flight off the common ground, the subsets it is
#: in, the stages it failed at, the runs that failed on it ("every run" at load) and
#: each one's error (``run: error``, joined by " | ")
LEFT_OUT_COLUMNS = ["flight", "subsets", "stage", "runs", "error"]


def _failures(failures: pd.DataFrame | None) -> pd.DataFrame:
    columns = [*FAILURE_COLUMNS, "subsets"]
    if failures is None or not len(failures):
        return pd.DataFrame(columns=columns)
    f = failures.reindex(columns=columns)
    return f.astype(object).where(f.notna(), "").astype({"subsets": str, "method": str})


def common_ground(records: list[dict], manifest: pd.DataFrame,
                  failures: pd.DataFrame | None = None) -> tuple[list[dict], pd.DataFrame]:
    """The records of the flights every ranked run (block ``honest``:
    :func:`~alfa_bench.analysis.blocks.block`) scored, and the flights left out of that
    common ground (:data:`LEFT_OUT_COLUMNS`): those refused at load, then those a
    ranked run failed on, each with every run that failed on it and each one's error.

    Only the ranked runs decide it: a reference or actuator-reading run that failed on
    a flight leaves it on the common ground, and keeps its records of the rest. A run
    that scored no flight at all does not shrink it either (its comparison row says it
    scored none; :func:`unscored_notes` names it). Every labelled flight a run has no
    record of must be one of its ``failures``: else :class:`ValueError`."""
    f = _failures(failures)
    by_method: dict[str, set[str]] = {}
    blocks: dict[str, str] = {}
    for r in records:
        by_method.setdefault(r["method"], set()).add(r["flight"])
        # as every table blocks a run: by its first record
        blocks.setdefault(r["method"], block(r))
    labelled = manifest.loc[manifest["ground_truth"], "flight"].tolist()
    own = {m: set(g["flight"]) for m, g in f[f["method"] != ""].groupby("method")}
    for method, scored in by_method.items():
        missing = [x for x in labelled if x not in scored and x not in own.get(method, ())]
        if missing:
            raise ValueError(f"method {method}: no detection for {len(missing)} flight(s), "
                             f"e.g. {missing[0]}, and no failure reported")
    common = set(labelled).intersection(
        *(scored for method, scored in by_method.items() if blocks[method] == "honest"))
    rows = [{"flight": r["flight"], "subsets": r["subsets"], "stage": "load",
             "runs": "every run", "error": r["error"]}
            for r in f[f["stage"] == "load"].to_dict(orient="records")]
    subsets = manifest.set_index("flight")["subsets"]
    for flight in (x for x in labelled if x not in common):
        mine = f[(f["flight"] == flight) & (f["method"] != "")].sort_values(
            "method", kind="stable")
        rows.append({"flight": flight, "subsets": subsets[flight],
                     "stage": ";".join(dict.fromkeys(mine["stage"])),
                     "runs": ";".join(dict.fromkeys(mine["method"])),
                     "error": " | ".join(dict.fromkeys(
                         f"{m}: {e}" for m, e in zip(mine["method"], mine["error"],
                                                     strict=True)))})
    return ([r for r in records if r["flight"] in common],
            pd.DataFrame(rows, columns=LEFT_OUT_COLUMNS))


def _on_ground(records: list[dict], manifest: pd.DataFrame, subsets,
               failures: pd.DataFrame | None) -> dict[str, dict[str, tuple[list[dict], int, int]]]:
    """subset -> method -> (its records on the common ground (:func:`common_ground`) of
    the subset's flights, the flights of the subset it failed on itself, the subset's
    flights off the common ground: refused at load or failed by a ranked run,
    ``excluded`` from every run alike). A run with no record on the subset's common
    ground has no entry; a subset with no flight scored has none."""
    kept, left_out = common_ground(records, manifest, failures)
    f = _failures(failures)
    own = f[f["method"] != ""]
    by_method: dict[str, dict[str, dict]] = {}
    for r in kept:
        by_method.setdefault(r["method"], {})[r["flight"]] = r
    out = {}
    for subset in subsets:
        flights = subset_flights(manifest, subset)
        failed = own[own["flight"].isin(flights)].groupby("method")["flight"].nunique()
        excluded = len(in_subset(left_out, subset))
        out[subset] = {}
        for method, recs in by_method.items():
            scored = [recs[x] for x in flights if x in recs]
            if scored:
                out[subset][method] = (scored, int(failed.get(method, 0)), excluded)
    return out


def _scores(recs: list[dict], deadline_s: float) -> tuple[list[str], dict]:
    """Outcomes under the deadline, and the summary: deadline first, then the paper's
    rule (keys ending ``_paper``)."""
    outcomes, s = score_records(recs, deadline_s)
    _, paper = score_records(recs)
    return outcomes, {**s, **{f"{k}_paper": v for k, v in paper.items() if k != "flights"}}


def summary_table(records: list[dict], manifest: pd.DataFrame, subsets, deadline_s: float,
                  failures: pd.DataFrame | None = None) -> pd.DataFrame:
    rows = []
    for subset, runs in _on_ground(records, manifest, subsets, failures).items():
        for method, (recs, failed, excluded) in runs.items():
            _, s = _scores(recs, deadline_s)
            rows.append({"method": method, "subset": subset, "block": block(recs[0]),
                         "deadline_s": deadline_s, **s, "excluded": excluded,
                         "failed_flights": failed})
    return pd.DataFrame(rows)


def _calibration(rec: dict) -> str:
    """What a run learned from, and how the scored group was kept out of it."""
    cal = rec.get("calibration")
    if not cal:
        return "none"
    data = "supervised (labelled flights)" if cal.get("supervised") else "fault-free only"
    n = configurations(rec)
    chosen = (f"; best of {n} configurations by an inner leave-one-{cal['group_by']}-out"
              if n > 1 else "")
    return f"{data}, leave-one-{cal['group_by']}-out{chosen}"


def configurations(rec: dict) -> int:
    """How many configurations the run scored to choose the one that scored ``rec``: the
    candidates of a nested selection (:mod:`alfa_bench.methods.nested_selection`),
    else one."""
    fitted = (rec.get("calibration") or {}).get("fitted") or {}
    return int(fitted.get("candidates", 1)) if isinstance(fitted, dict) else 1


def _isolation(recs: list[dict], outcomes: list[str]) -> tuple[int, int]:
    """Of the in-time detections, how many alarmed first on a channel that names the
    flight's fault class, and how many there are (:func:`~.isolation.names_class`)."""
    hits = [r for r, o in zip(recs, outcomes, strict=True) if o == "TP"]
    return sum(names_class(r) for r in hits), len(hits)


def comparison_table(records: list[dict], manifest: pd.DataFrame, subsets, deadline_s: float,
                     failures: pd.DataFrame | None = None, stable: float = 0.9,
                     interval: float = 0.9) -> pd.DataFrame:
    """Per subset and method, in block order (honest ones ranked): the scores under the
    deadline and by the paper's rule, false alarms on fault-free flights, the
    calibration protocol, the flights excluded, and the exact McNemar test against the
    best honest method on the flights both scored.

    Ranks compare like with like: every run is scored on the common ground
    (:func:`common_ground`), and a run that failed on flights the others scored is
    ranked there all the same, flagged by ``failed_flights``. An honest run that never
    armed is not ranked: ``not_ranked`` says so and it follows the ranked ones. A run
    that failed on every flight of a subset it has flights of comes last, with
    ``flights`` 0, ``not_ranked`` "not scored" and no block or scores.

    Under resampled calibration pools (:mod:`alfa_bench.analysis.stability`): the
    stable detections (survival at least ``stable``), the central ``interval`` of the
    in-time detections over the pools, and ``rank_range``, the ranks a ranked run
    takes over the pools (the other ranked runs re-scored under the same pools)."""
    kept, left_out = common_ground(records, manifest, failures)
    ground = _on_ground(records, manifest, subsets, failures)
    pooled = {(row["subset"], row["method"]): row for row in stability_table(
        kept, manifest, subsets, deadline_s, stable, interval).to_dict("records")}
    own = _failures(failures)
    own = own[own["method"] != ""]
    rows = []
    for subset in subsets:
        runs = []
        for method, (recs, failed, excluded) in ground[subset].items():
            outcomes, s = _scores(recs, deadline_s)
            named, hits = _isolation(recs, outcomes)
            free = [r for r in recs if r["fault_class"] == "none"]
            correct = {r["flight"]: o in ("TP", "TN")
                       for r, o in zip(recs, outcomes, strict=True)}
            runs.append((correct, {
                "subset": subset, "method": method, "block": block(recs[0]),
                "family": recs[0].get("family", "other"),
                "detector": recs[0]["detector"], "calibration": _calibration(recs[0]),
                "configurations": max(configurations(r) for r in recs),
                "deadline_s": deadline_s, **s,
                "fault_free_flights": len(free),
                "fault_free_false_alarms": sum(r["first_alarm_s"] is not None for r in free),
                "armed_flights": sum(any(v is not None for v in r["pair_armed_s"].values())
                                     for r in recs),
                "isolation": named / hits if hits else math.nan,
                "excluded": excluded,
                "failed_flights": failed,
                **{k: pooled[(subset, method)][k]
                   for k in ("stable_detections", "detections_low", "detections_high")},
            }, recs))
        honest = sorted((r[:2] for r in runs if r[1]["block"] == "honest"),
                        key=lambda r: _rank_key(r[1]))
        recs_of = {row["method"]: recs for _, row, recs in runs}
        runs = [r[:2] for r in runs]
        for _, row in runs:
            row["not_ranked"] = ("never armed" if row["block"] == "honest"
                                 and row["armed_flights"] == 0 else "")
        ranked = [r for r in honest if not r[1]["not_ranked"]]
        for i, (_, row) in enumerate(ranked, 1):
            row["rank"] = i
        _rank_ranges([row for _, row in ranked], recs_of, deadline_s)
        ordered = ranked + [r for r in honest if r[1]["not_ranked"]] + [
            r for b in BLOCKS[1:] for r in runs if r[1]["block"] == b]
        best_correct, best = ranked[0] if ranked else ({}, None)
        silence = [row for _, row in runs if row["detector"] == SILENT]
        for correct, row in ordered:
            row["best_honest"] = best["method"] if best else ""
            # no better than a run that never alarms: its accuracy is not above silence's
            row["beats_silence"] = (_num(row["accuracy"]) > _num(silence[0]["accuracy"])
                                    if silence and row["detector"] != SILENT else None)
            both = [f for f in correct if f in best_correct]
            test = (mcnemar_exact([correct[f] for f in both], [best_correct[f] for f in both])
                    if best and row is not best else
                    {"only_a": None, "only_b": None, "p_value": math.nan})
            row["vs_best_only_this"], row["vs_best_only_best"] = test["only_a"], test["only_b"]
            row["vs_best_p"] = test["p_value"]
            rows.append(row)
        failed = own[own["flight"].isin(subset_flights(manifest, subset))]
        for method, mine in failed.groupby("method", sort=False):
            if method not in ground[subset]:
                rows.append({"subset": subset, "method": method, "block": "",
                             "deadline_s": deadline_s, "flights": 0,
                             "excluded": len(in_subset(left_out, subset)),
                             "failed_flights": mine["flight"].nunique(),
                             "not_ranked": "not scored"})
    # the scored rows' columns in their order, also where a subset's first row is unscored
    columns = dict.fromkeys(k for r in sorted(rows, key=lambda r: not r["flights"]) for k in r)
    table = pd.DataFrame(rows).reindex(columns=list(columns))
    if table.empty or table["flights"].all():
        return table
    # the counts stay whole numbers beside the empty cells of a run not scored
    counts = pd.DataFrame([r for r in rows if r["flights"]]).select_dtypes("integer")
    return table.astype(dict.fromkeys(counts.columns, "Int64"))


def _rank_ranges(ranked: list[dict], recs_of: dict[str, list[dict]], deadline_s: float) -> None:
    """Each ranked row's ``rank_range``: its lowest and highest rank when every ranked
    run is re-scored under each calibration pool (``"3"``, ``"2-5"``); its rank where
    no run has pools."""
    pools = max((len(r["stability"]["first_alarm_s"]) for row in ranked
                 for r in recs_of[row["method"]][:1] if r.get("stability")), default=0)
    for row in ranked:
        row["rank_range"] = str(row["rank"])
    if not pools:
        return
    keys = [[_rank_key(s) for s in pool_summaries(recs_of[row["method"]], deadline_s, pools)]
            for row in ranked]
    seen = [[] for _ in ranked]
    for b in range(pools):
        # ties keep the reported order, as the reported ranking does
        for place, i in enumerate(sorted(range(len(ranked)), key=lambda i: keys[i][b]), 1):
            seen[i].append(place)
    for row, places in zip(ranked, seen, strict=True):
        low, high = min(places), max(places)
        row["rank_range"] = str(low) if low == high else f"{low}-{high}"


def _rank_key(scores: dict) -> tuple[float, float, float]:
    """What honest runs are ranked by: accuracy, then recall (higher first), then mean
    detection time (lower first)."""
    return (-_num(scores["accuracy"]), -_num(scores["recall"]),
            _num(scores["mean_detection_s"], math.inf))


def _num(v, nan=-math.inf) -> float:
    return nan if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)


def _total(values: dict[str, float], flights: list[str]) -> float:
    """The sum of ``values`` over ``flights``, NaN as 0, as pandas sums a column."""
    return float(np.nansum(np.array([values[f] for f in flights], dtype=float)))


def by_fault_table(records: list[dict], manifest: pd.DataFrame, subsets, deadline_s: float,
                   failures: pd.DataFrame | None = None) -> pd.DataFrame:
    # by dictionary: a frame's .loc per row and class took a third of the job
    times = {c: dict(zip(manifest["flight"], manifest[c].to_numpy(float), strict=True))
             for c in ("flight_s", "pre_fault_s")}
    rows = []
    for subset, runs in _on_ground(records, manifest, subsets, failures).items():
        for method, (recs, _, _) in runs.items():
            groups = {c: [r for r in recs if r["fault_class"] == c] for c in FAULT_ORDER}
            groups["total"] = recs
            for fault_class, group in groups.items():
                if not group:
                    continue
                outcomes, s = _scores(group, deadline_s)
                named, hits = _isolation(group, outcomes)
                flights = [r["flight"] for r in group]
                rows.append({
                    "method": method, "subset": subset, "block": block(group[0]),
                    "fault_class": fault_class, "deadline_s": deadline_s,
                    "flights": len(group),
                    "flight_time_s": _total(times["flight_s"], flights),
                    "pre_fault_s": _total(times["pre_fault_s"], flights),
                    "detected": s["tp"], "detected_paper": s["tp_paper"],
                    # in time, but first on a channel of another axis than the fault's
                    "detected_other_class": hits - named,
                    "mean_detection_s": s["mean_detection_s"],
                    "max_detection_s": s["max_detection_s"],
                    "accuracy": s["accuracy"], "accuracy_paper": s["accuracy_paper"],
                })
    return pd.DataFrame(rows)


def _rate(r, key: str) -> str:
    """A rate with its Wilson 95 % interval: ``88.2 [65.7, 96.7]``."""
    if f"{key}_low" not in r or fmt(r[key]) == "-":
        return fmt(r.get(key), True, 1)
    return (f"{fmt(r[key], True, 1)} [{fmt(r[f'{key}_low'], True, 1)}, "
            f"{fmt(r[f'{key}_high'], True, 1)}]")


_BLOCK_TITLES = {"honest": "honest methods (sensors and setpoints only), ranked",
                 "reads actuators": "MARKED: reads what the fault emulation writes "
                                    "(servo outputs, throttle); not ranked",
                 "reference": "reference rows: what lateness, the emulation alone or a "
                              "calibration that saw the scored date gives; not ranked"}


def _blocked(rows: list[tuple[str, list[str]]], width: int) -> list[list[str]]:
    """Rows ``(block, cells)`` in block order, each block under a title row."""
    out = []
    for b in BLOCKS:
        mine = [cells for blk, cells in rows if blk == b]
        if mine:
            out.append([f"*{_BLOCK_TITLES[b]}*", *[""] * (width - 1)])
            out += mine
    return out


def _deadline(table: pd.DataFrame) -> str:
    return fmt(float(table["deadline_s"].iloc[0]), digits=1)


def _summary_sections(summary: pd.DataFrame) -> list[Section]:
    out = []
    for subset, table in summary.groupby("subset", sort=False):
        d = _deadline(table)
        header = ["method", "flights", "excluded", f"TP ≤{d} s", "FP", "FN", "TN",
                  f"precision % ≤{d} s [95 % CI]", f"recall % ≤{d} s [95 % CI]",
                  f"accuracy % ≤{d} s [95 % CI]", "mean det. s", "max det. s",
                  "paper's rule: TP", "FP", "FN", "TN", "accuracy %", "mean det. s"]

        def cells(name, r):
            return [name, fmt(r.get("flights")), fmt(r.get("excluded")), fmt(r.get("tp")),
                    fmt(r.get("fp")), fmt(r.get("fn")), fmt(r.get("tn")),
                    _rate(r, "precision"), _rate(r, "recall"), _rate(r, "accuracy"),
                    _stable(r), r["rank_range"] if isinstance(r.get("rank_range"), str) else "-",
                    fmt(r.get("mean_detection_s")), fmt(r.get("max_detection_s")),
                    fmt(r["tp_paper"]), fmt(r["fp_paper"]), fmt(r["fn_paper"]),
                    fmt(r["tn_paper"]), _rate(r, "accuracy_paper"),
                    fmt(r["mean_detection_s_paper"])]

        rows = _blocked([(r["block"], cells(r["method"], r))
                         for r in table.to_dict(orient="records")], len(header))
        if subset == "icra22":
            paper = {f"{k}_paper": v for k, v in ICRA2019_SUMMARY.items()}
            rows.append(cells(ICRA2019_NAME, {"flights": ICRA2019_SUMMARY["flights"], **paper}))
        out.append((f"Subset `{subset}`", header, rows))
    return out


def _by_fault_sections(by_fault: pd.DataFrame) -> list[Section]:
    out = []
    for (method, subset), table in by_fault.groupby(["method", "subset"], sort=False):
        paper = subset == "icra22"
        d = _deadline(table)
        header = ["fault", "flights", "flight time s", "pre-fault s", f"detected ≤{d} s",
                  "of them first on another axis", "mean det. s", "max det. s",
                  f"accuracy % ≤{d} s", "detected (paper's rule)", "accuracy % (paper's rule)"]
        if paper:
            header += ["paper: flights", "paper: flight time s", "paper: mean det. s",
                       "paper: max det. s", "paper: accuracy %"]
        rows = []
        for r in table.to_dict(orient="records"):
            row = [r["fault_class"], str(r["flights"]), fmt(r["flight_time_s"], digits=1),
                   fmt(r["pre_fault_s"], digits=1), str(r["detected"]),
                   str(r["detected_other_class"]), fmt(r["mean_detection_s"]),
                   fmt(r["max_detection_s"]),
                   fmt(r["accuracy"], True), str(r["detected_paper"]),
                   fmt(r["accuracy_paper"], True)]
            if paper:
                ref = ICRA2019_BY_FAULT.get(r["fault_class"], (None,) * 5)
                row += [fmt(ref[0]), fmt(ref[1]), fmt(ref[2]), fmt(ref[3]),
                        fmt(ref[4], True)]
            rows.append(row)
        mark = BLOCK_MARKS[table["block"].iloc[0]]
        out.append((f"`{method}` on `{subset}`{mark}", header, rows))
    return out


#: what each subset holds, as the comparison titles it
SUBSET_NOTES = {
    "no_emr": "no emergency trajectory",
    "all": "includes the emergency-trajectory flights, whose commands switch at onset",
    "icra22": "the flights of Keipour et al., ICRA 2019",
    "emr": "emergency trajectory only: the commands switch at onset",
}


def _stable(r) -> str:
    """In-time detections, stable ones and their interval over the calibration pools:
    ``7: 3 stable [4, 8]``; the count alone where its thresholds cannot be set again
    for resampled calibration flights without a refit."""
    if fmt(r.get("tp")) == "-":
        return "-"
    if fmt(r.get("stable_detections")) == "-":
        return f"{int(r['tp'])} (not resampled)"
    return (f"{int(r['tp'])}: {int(r['stable_detections'])} stable "
            f"[{fmt(r['detections_low'], digits=0)}, {fmt(r['detections_high'], digits=0)}]")


def _scored(comparison: pd.DataFrame) -> pd.DataFrame:
    """The rows of runs that scored a flight: the others are listed apart
    (:func:`unscored_notes`)."""
    return comparison[comparison["flights"] > 0] if len(comparison) else comparison


def _comparison_sections(comparison: pd.DataFrame, primary: str | None = None
                         ) -> list[Section]:
    out = []
    for subset, table in _scored(comparison).groupby("subset", sort=False):
        d = _deadline(table)
        header = ["rank", "method", "detector", "calibration", f"precision % ≤{d} s [95 % CI]",
                  f"recall % ≤{d} s [95 % CI]", f"accuracy % ≤{d} s [95 % CI]",
                  f"detections ≤{d} s: stable [range when the calibration flights are "
                  "resampled]",
                  "rank range, calibration flights resampled",
                  "mean det. s", "max det. s", "accuracy % (paper's rule)",
                  "mean det. s (paper's rule)", "false alarms, fault-free flights",
                  "in-time detections first on the fault's axis %",
                  "vs best honest: only this / only best correct, McNemar p",
                  "flights armed", "flights excluded"]

        def cells(r):
            p = r.get("vs_best_p")
            paired = ("best" if r.get("rank") == 1 else "-" if fmt(p) == "-" else
                      f"{int(r['vs_best_only_this'])} / {int(r['vs_best_only_best'])}, "
                      f"p = {p:.3f}" + ("" if p < SIGNIFICANCE else " (cannot tell apart)"))
            rank = r.get("rank")
            why = r.get("not_ranked")
            failed = int(r.get("failed_flights") or 0)
            # a ranked run's failure took the flight off the common ground; another's not
            flag = "" if not failed else (
                f" (FLAGGED: failed on {failed} flight{'s' * (failed > 1)}; "
                + ("ranked on the common ground)" if r.get("block") == "honest" else
                   f"scored on {int(r['flights'])} flights of the common ground)"))
            return [why if isinstance(why, str) and why else
                    "-" if fmt(rank) == "-" else str(int(rank)),
                    r["method"] + (" (no better than silence)"
                                   if r.get("beats_silence") is False else "")
                    + flag,
                    r["detector"], r["calibration"],
                    _rate(r, "precision"), _rate(r, "recall"), _rate(r, "accuracy"),
                    _stable(r), r["rank_range"] if isinstance(r.get("rank_range"), str) else "-",
                    fmt(r.get("mean_detection_s")), fmt(r.get("max_detection_s")),
                    fmt(r["accuracy_paper"], True), fmt(r["mean_detection_s_paper"]),
                    f"{r['fault_free_false_alarms']} of {r['fault_free_flights']}",
                    fmt(r.get("isolation"), True, 0), paired,
                    fmt(r.get("armed_flights")), fmt(r.get("excluded"))]

        records = table.to_dict(orient="records")
        rows = _blocked([(r["block"], cells(r)) for r in records], len(header))
        if subset == "icra22":
            paper = ICRA2019_SUMMARY
            free = ICRA2019_BY_FAULT["none"][0]
            rows.append(cells({"method": ICRA2019_NAME, "detector": "rls_arx_zscore",
                               "calibration": "(as published; no deadline)",
                               "accuracy_paper": paper["accuracy"],
                               "mean_detection_s_paper": paper["mean_detection_s"],
                               "fault_free_flights": free,
                               "fault_free_false_alarms": free - paper["tn"]}))
        head = "Headline: subset" if subset == primary else "Subset"
        note = f"; {SUBSET_NOTES[subset]}" if subset in SUBSET_NOTES else ""
        out.append((f"{head} `{subset}` ({ground_note(table)}{note}; deadline {d} s)",
                    header, rows))
    return out


def ground_note(table: pd.DataFrame) -> str:
    """A subset's size and its common ground, from its rows of the comparison or
    summary: ``26 flights`` or ``26 flights, 22 on the common ground, 4 left out``.
    The common ground is the most flights a row scored: every ranked run's, and every
    run's that failed on none of it."""
    scored = int(table["flights"].max())
    left = int(table["excluded"].iloc[0]) if "excluded" in table else 0
    return (f"{scored + left} flights" if not left else
            f"{scored + left} flights, {scored} on the common ground, {left} left out")


def left_out_markdown(left_out: pd.DataFrame, subsets) -> str:
    """The flights of ``subsets`` off the common ground (:func:`common_ground`), the
    subsets they are in, and why; empty when no flight is left out."""
    lines = []
    for r in left_out.to_dict(orient="records"):
        mine = [s for s in subsets if s in str(r["subsets"] or "").split(";")]
        if not mine:
            continue
        who = ("refused at load, for every run" if r["runs"] == "every run" else
               f"failed by {', '.join(f'`{m}`' for m in str(r['runs']).split(';'))} "
               f"({r['stage']}), so left out for every run")
        lines.append(f"- `{r['flight']}` (of {', '.join(f'`{s}`' for s in mine)}): {who}: "
                     f"{r['error']}")
    if not lines:
        return ""
    return ("\n### Flights left out of the common ground\n\n"
            "Every run is scored and ranked on the flights every run scored; these were "
            "not (every error: [`failures.csv`](failures.csv), per flight: "
            "[`left_out.csv`](left_out.csv)).\n\n" + "\n".join(lines) + "\n")


def comparison_notes(comparison: pd.DataFrame) -> str:
    """Per subset, one line: which runs the data cannot tell apart from the best honest
    method (exact McNemar, p >= 0.05)."""
    lines = []
    for subset, table in _scored(comparison).groupby("subset", sort=False):
        best = table.loc[table["rank"] == 1, "method"] if "rank" in table else []
        if not len(best):
            lines.append(f"- `{subset}`: no honest method.")
            continue
        same = table.loc[(table["vs_best_p"] >= SIGNIFICANCE) & (table["method"] !=
                         best.iloc[0]), "method"]
        names = ", ".join(f"`{m}`" for m in same) or "none"
        lines.append(f"- `{subset}`: the best honest method is `{best.iloc[0]}`; the data "
                     f"cannot tell it apart (McNemar p ≥ {SIGNIFICANCE}) from: {names}.")
    return "\n".join(lines) + "\n"


def summary_markdown(summary: pd.DataFrame) -> str:
    """Per subset, a table of methods, with the paper's row under ``icra22``."""
    return markdown(_summary_sections(summary))


def summary_latex(summary: pd.DataFrame) -> str:
    """:func:`summary_markdown` as LaTeX (booktabs)."""
    return latex_tables(_summary_sections(summary), "summary")


def by_fault_markdown(by_fault: pd.DataFrame) -> str:
    """Per method and subset, Table I's layout; the paper's values beside ``icra22``."""
    return markdown(_by_fault_sections(by_fault))


def by_fault_latex(by_fault: pd.DataFrame) -> str:
    """:func:`by_fault_markdown` as LaTeX (booktabs)."""
    return latex_tables(_by_fault_sections(by_fault), "by-fault")


def unscored_notes(comparison: pd.DataFrame, failures: pd.DataFrame, manifest: pd.DataFrame,
                   subsets) -> str:
    """Per subset, the runs with no row because every flight of the subset was excluded
    for them (a fold they could not calibrate, flights they could not read); empty when
    every run was scored."""
    lines = []
    own = failures[failures["method"].fillna("") != ""] if len(failures) else failures
    for subset in subsets:
        flights = set(subset_flights(manifest, subset))
        scored = set(comparison.loc[(comparison["subset"] == subset)
                                    & (comparison["flights"] > 0), "method"]) \
            if len(comparison) else set()
        for method, rows in own.groupby("method", sort=False) if len(own) else []:
            rows = rows[rows["flight"].isin(flights)]
            if method in scored or not len(rows):
                continue
            stages = ", ".join(dict.fromkeys(rows["stage"]))
            lines.append(f"- `{method}` on `{subset}`: all {len(rows)} flights excluded "
                         f"({stages}); `results/tables/failures.csv` says why and what to "
                         "change.")
    return "\n### Runs not scored\n\n" + "\n".join(lines) + "\n" if lines else ""


def not_applicable_markdown(not_applicable: dict[str, str]) -> str:
    """The runs a corpus of logs cannot run (``config["not_applicable"]``:
    run -> the signals it reads that the corpus lacks, and why), in a section; empty
    when there are none."""
    if not not_applicable:
        return ""
    lines = [f"- `{run}`: reads {why}" for run, why in not_applicable.items()]
    return ("\n### Runs not applicable to this corpus\n\nThey read a signal the corpus's "
            "logs do not give (`results/corpus/signals.csv`), so they were not run; the "
            "ranked runs' common ground is the same without them.\n\n"
            + "\n".join(lines) + "\n")


def no_fault_note(comparison: pd.DataFrame, primary: str) -> str:
    """A line where no flight of the ``primary`` subset that the runs scored has a fault
    (a corpus of fault-free logs): recall cannot be computed; empty otherwise."""
    rows = comparison[comparison["subset"] == primary]
    if not len(rows) or (rows["tp"] + rows["fn"]).max() > 0:
        return ""
    return (f"No flight of `{primary}` that the runs scored has a fault: recall cannot be "
            "computed (`-`), and the ranks order false alarms alone.\n\n")


def not_applicable_table(not_applicable: dict[str, str]) -> pd.DataFrame:
    """``not_applicable`` as rows: ``method``, ``missing`` (the signals and why)."""
    return pd.DataFrame([{"method": run, "missing": why}
                         for run, why in not_applicable.items()],
                        columns=["method", "missing"])


def comparison_markdown(comparison: pd.DataFrame, unscored: str = "", primary: str | None = None,
                        audit: str = "", left_out: str = "") -> str:
    """``audit`` (what the leakage audit finds on the ``primary`` subset), then one table
    per subset, in blocks, the ``primary`` one titled the headline; the ICRA 2019 paper's
    row under ``icra22``; which differences the data cannot tell apart; then
    ``left_out`` (:func:`left_out_markdown`) and ``unscored`` (:func:`unscored_notes`)."""
    return (audit + markdown(_comparison_sections(comparison, primary))
            + "\n### Which differences the data can tell\n\n" + comparison_notes(comparison)
            + left_out + unscored)


def comparison_latex(comparison: pd.DataFrame) -> str:
    """:func:`comparison_markdown` as LaTeX (booktabs)."""
    return latex_tables(_comparison_sections(comparison), "comparison")


def stability_markdown(stability: pd.DataFrame, folds: pd.DataFrame, settings: dict) -> str:
    """The stability table per subset (:func:`~alfa_bench.analysis.stability.
    stability_table`), then each fold's calibration data (:func:`~alfa_bench.analysis.
    stability.calibration_table`); ``settings`` is the config's ``stability``."""
    level = fmt(100 * settings["interval"], digits=0)
    sections = []
    for subset, table in stability.groupby("subset", sort=False):
        d = _deadline(table)
        header = ["method", f"detections ≤{d} s", f"stable (survival ≥ {settings['stable']:g})",
                  f"over the pools: mean [{level} % interval]", "fault-free alarms",
                  f"over the pools: mean [{level} % interval]", "pools"]
        rows = [[r["method"], str(r["detections"]), fmt(r["stable_detections"], digits=0),
                 "-" if not r["pools"] else
                 f"{fmt(r['detections_mean'], digits=1)} [{fmt(r['detections_low'], digits=0)}"
                 f", {fmt(r['detections_high'], digits=0)}]",
                 f"{r['fault_free_alarms']} of {r['fault_free_flights']}",
                 "-" if not r["pools"] else
                 f"{fmt(r['fault_free_alarms_mean'], digits=1)} "
                 f"[{fmt(r['fault_free_alarms_low'], digits=0)}, "
                 f"{fmt(r['fault_free_alarms_high'], digits=0)}]",
                 str(r["pools"]) if r["pools"] else "none: not calibrated, or its thresholds "
                 "come with a fitted model"]
                for r in table.to_dict(orient="records")]
        sections.append((f"Subset `{subset}` (deadline {d} s)", header, rows))
    sections.append(("Calibration data per fold", ["fold (left out)", "calibration flights",
                                                   "fault-free hours",
                                                   "smallest per-flight false-alarm level "
                                                   "they can check"],
                     [[r["fold"], str(r["flights"]), fmt(r["fault_free_hours"]),
                       fmt(r["smallest_level"], digits=3)]
                      for r in folds.to_dict(orient="records")]))
    return markdown(sections)


def refit_markdown(table: pd.DataFrame) -> str:
    """:func:`~alfa_bench.analysis.stability.refit_table` per subset: the in-time
    detections over the same pools, thresholds alone against the model fitted again."""
    sections = []
    for subset, rows in table.groupby("subset", sort=False):
        d = _deadline(rows)
        header = ["method", "pools", f"detections ≤{d} s, thresholds alone: mean [min, max]",
                  "SD", "model fitted again: mean [min, max]", "SD",
                  "(flight, pool) outcomes the two agree on %"]
        sections.append((f"Subset `{subset}` (deadline {d} s)", header, [
            [r["method"], str(r["pools"]),
             f"{r['thresholds_mean']:.1f} [{r['thresholds_min']:.0f}, "
             f"{r['thresholds_max']:.0f}]", f"{r['thresholds_sd']:.2f}",
             f"{r['refit_mean']:.1f} [{r['refit_min']:.0f}, {r['refit_max']:.0f}]",
             f"{r['refit_sd']:.2f}", fmt(r["outcomes_agree"], True, 1)]
            for r in rows.to_dict(orient="records")]))
    return markdown(sections)
