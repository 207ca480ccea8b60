"""Features by learners: how much of a run's lead comes from its learner, and how much
from what it reads.

Each row of the config's ``features_learners`` names a learner and its runs: on raw
window features with the library's defaults (``windows``), the same at its fair best,
window and main parameter chosen by nested leave-one-date-out (``windows_best``), and
on a public study's 25 physical-residual features (``residuals``), and on the union of
the project's physical features, blocks and regularisation chosen by nested
leave-one-date-out (``physical_best``: ``bench_logistic``). A generic model is
unsupervised in every column but the fair best, which reads the training flights'
labels to choose; the logistic regression is supervised. Read down a column
for the learner, across a row for the features.

Every cell counts what :func:`~.per_flight.subset_counts` counts on the headline
subset's common ground (the flights every ranked run scored, as the comparison ranks
them: :func:`~alfa_bench.outputs.tables.common_ground`) with the deadline, and says
whether the run beats ``silent`` there (the comparison's ``beats_silence``); a
fair-best cell also names the configurations tried and the one chosen per scored date.
"""

from __future__ import annotations

from collections import Counter

import pandas as pd

from alfa_bench.data import subset_flights
from alfa_bench.render import markdown

from .per_flight import subset_counts

__all__ = ["COLUMNS", "FEATURE_COLUMNS", "chosen_configurations", "features_learners",
           "features_learners_markdown", "features_learners_sections"]

#: the config's keys of a row's runs, and their column headers
FEATURE_COLUMNS = {"windows": "raw windows, defaults",
                   "windows_best": "raw windows, at its fair best",
                   "residuals": "physical residuals",
                   "physical_best": "the project's physical features, at its fair best"}

#: the columns of :func:`features_learners`
COLUMNS = ["learner", "features", "run", "supervised", "configurations", "chosen",
           "faulty_flights", "detected", "early_alarms", "fault_free_flights",
           "fault_free_alarmed", "stable_detections", "beats_silence"]


def _setting(values: dict) -> str:
    """A nested selection's chosen values in words, the window first:
    ``window 5 s, n_neighbors 20``."""
    parts = [f"window {values['window_s']:g} s"] if "window_s" in values else []
    for name, value in values.items():
        if name == "window_s":
            continue
        if isinstance(value, dict):
            parts += [f"{k} {'all' if v is None else v}" for k, v in value.items()]
        elif isinstance(value, list | tuple):
            parts.append(f"{name} {'+'.join(map(str, value))}")
        else:
            parts.append(f"{name} {value}")
    return ", ".join(parts)


def chosen_configurations(records: list[dict]) -> str:
    """Per configuration a nested run chose, the scored dates it was chosen for, most
    often first: ``window 5 s, n_neighbors 5 (3 dates); window 5 s, n_neighbors 20 (2)``;
    empty where the records hold no choice."""
    by_fold = {}
    for r in records:
        cal = r.get("calibration") or {}
        fitted = cal.get("fitted") or {}
        if fitted.get("chosen") is not None:
            blind = str(fitted.get("chosen_by", "")).startswith("grid order")
            by_fold[cal.get("fold")] = _setting(fitted["chosen"]) + (
                " (grid order: none could be scored)" if blind else "")
    counts = Counter(by_fold.values()).most_common()
    return "; ".join(f"{c} ({n} date{'s' if n > 1 else ''})" if i == 0 else f"{c} ({n})"
                     for i, (c, n) in enumerate(counts))


def features_learners(per_flight: pd.DataFrame, comparison: pd.DataFrame,
                      manifest: pd.DataFrame, rows: list[dict], primary: str,
                      stable: float, chosen: dict[str, str],
                      left_out: pd.DataFrame) -> pd.DataFrame:
    """One row per learner and feature column of the config's ``rows`` whose run was
    scored: the run, whether it is supervised, the configurations it tried and those
    it chose (``chosen``, by run), its :func:`~.per_flight.subset_counts` on
    ``primary``'s flights on the common ground (those of ``left_out``, as
    ``left_out.csv``, are not) and whether it beats ``silent`` there."""
    members = set(subset_flights(manifest, primary)) - set(left_out["flight"])
    on_primary = comparison[(comparison["subset"] == primary)
                            & (comparison["flights"] > 0)].set_index("method")
    out = []
    for row in rows:
        for key, header in FEATURE_COLUMNS.items():
            run = row.get(key)
            if run is None or run not in on_primary.index:
                continue
            runs = per_flight[per_flight["method"] == run]
            if runs.empty:
                continue
            summary = on_primary.loc[run]
            beats = summary.get("beats_silence")
            out.append({"learner": row["learner"], "features": header, "run": run,
                        # the comparison's words for a run whose fit read labels
                        # (outputs.tables: "supervised (labelled flights)")
                        "supervised": str(summary["calibration"]).startswith("supervised"),
                        "configurations": int(summary["configurations"]),
                        "chosen": chosen.get(run, ""),
                        **subset_counts(runs, members, stable),
                        "beats_silence": None if pd.isna(beats) else bool(beats)})
    return pd.DataFrame(out, columns=COLUMNS)


def _cell(r: dict) -> str:
    beats = {True: "beats silence", False: "does not beat silence", None: "-"}[
        r["beats_silence"]]
    text = (f"`{r['run']}`: {r['detected']} of {r['faulty_flights']}, "
            f"{r['fault_free_alarmed']} of {r['fault_free_flights']} fault-free alarmed, "
            f"{r['early_alarms']} early; {beats}")
    if r["configurations"] > 1:
        text += f"; best of {r['configurations']}: {r['chosen']}"
    return text


def features_learners_sections(table: pd.DataFrame) -> list:
    """:func:`features_learners` as one table section, learners by features (``-``
    where a learner has no scored run of those features)."""
    learners = list(dict.fromkeys(table["learner"]))
    headers = [h for h in FEATURE_COLUMNS.values() if h in set(table["features"])]
    cells = {(r["learner"], r["features"]): _cell(r) for r in table.to_dict(orient="records")}
    rows = [[learner, *(cells.get((learner, h), "-") for h in headers)]
            for learner in learners]
    return [("Features by learners", ["learner", *headers], rows)]


def features_learners_markdown(table: pd.DataFrame, primary: str, deadline_s: float) -> str:
    """:func:`features_learners_sections` in Markdown, with what the cells count."""
    if table.empty:
        return "None of the features-by-learners runs was scored.\n"
    head = (f"Each learner on raw window features (with its library's defaults, and at "
            f"its fair best: window and main parameter chosen per scored date by nested "
            f"leave-one-date-out), on the public study's 25 residual features, and on "
            f"the project's physical features (the study's, the residual bank's steps and "
            f"the physical signatures; blocks and regularisation chosen the same way). On "
            f"`{primary}`, within {deadline_s:g} s of onset: faults detected in time, "
            "fault-free flights alarmed, faulty flights alarmed before onset, and whether "
            "the run's accuracy beats `silent`'s. The generic models learn from "
            "fault-free data alone, but at their fair best, which reads the training "
            "flights' labels to choose; the logistic regression is supervised. `-`: no "
            "such run scored.\n\n")
    return head + markdown(features_learners_sections(table))
