"""Summary and per-fault-class tables, as CSV, Markdown and LaTeX.

``summary``: one row per (method, subset) with the scoring of
:func:`~.scoring.summarize`. ``comparison``: all methods side by side per subset,
with the false alarms on fault-free flights, how each was calibrated, and on how many
flights it armed (judged at all: a method that never arms has no false alarms).
``by_fault``: the layout of Keipour et al.'s Table I per method and subset: fault
class, flights, flight time, mean and max detection time, accuracy, and a total row.

A flight that could not be read (for every method, or for one) is not scored; the
``excluded`` column of the summary and comparison counts such flights of the subset,
and ``results/tables/failures.csv`` (:func:`failures_table`) says why.
"""

from __future__ import annotations

import math

import pandas as pd

from alfa_bench.data import FAILURE_COLUMNS, subset_flights

from .reference import ICRA2019_BY_FAULT, ICRA2019_NAME, ICRA2019_SUMMARY
from .scoring import summarize

__all__ = ["FAULT_ORDER", "by_fault_latex", "by_fault_markdown", "by_fault_table",
           "comparison_latex", "comparison_markdown", "comparison_table", "failures_table",
           "latex_escape",
           "summary_latex", "summary_markdown", "summary_table"]

FAULT_ORDER = ("engine", "rudder", "elevator", "aileron", "rudder+aileron", "none")


def failures_table(load: pd.DataFrame, per_method: list[pd.DataFrame]) -> pd.DataFrame:
    """Every flight given up: at load (for every method) and per method, in that order."""
    frames = [f for f in [load, *per_method] if len(f)]
    if not frames:
        return pd.DataFrame(columns=[*FAILURE_COLUMNS, "subsets"])
    return pd.concat(frames, ignore_index=True).reindex(columns=[*FAILURE_COLUMNS, "subsets"])


def _excluded(failures: pd.DataFrame | None, subset: str, flights: list[str],
              method: str) -> list[str]:
    if failures is None or not len(failures):
        return []
    f = failures.fillna("")
    at_load = f[(f["stage"] == "load") & f["subsets"].astype(str).str.split(";").apply(
        lambda s: subset in s)]["flight"]
    member = set(flights)
    own = f[(f["method"] == method) & f["flight"].isin(member)]["flight"]
    return list(dict.fromkeys([*at_load, *own]))


def _records_for(records: list[dict], manifest: pd.DataFrame, subset: str,
                 failures: pd.DataFrame | None = None) -> dict[str, tuple[list[dict], list[str]]]:
    """method -> (records of the subset's flights, the subset's flights it excluded);
    a flight without a record must be one of ``failures``."""
    flights = subset_flights(manifest, subset)
    by_method: dict[str, dict[str, dict]] = {}
    for r in records:
        by_method.setdefault(r["method"], {})[r["flight"]] = r
    out = {}
    for method, recs in by_method.items():
        excluded = _excluded(failures, subset, flights, method)
        missing = [f for f in flights if f not in recs and f not in excluded]
        if missing:
            raise ValueError(f"method {method}: no detection for {len(missing)} flight(s) of "
                             f"subset {subset}, e.g. {missing[0]}, and no failure reported")
        out[method] = ([recs[f] for f in flights if f in recs], excluded)
    return out


def summary_table(records: list[dict], manifest: pd.DataFrame, subsets,
                  failures: pd.DataFrame | None = None) -> pd.DataFrame:
    rows = []
    for subset in subsets:
        for method, (recs, excluded) in _records_for(records, manifest, subset,
                                                     failures).items():
            s = summarize([r["outcome"] for r in recs], [r["detection_s"] for r in recs])
            rows.append({"method": method, "subset": subset, **s, "excluded": len(excluded)})
    return pd.DataFrame(rows)


def _calibration(rec: dict) -> str:
    cal = rec.get("calibration")
    return f"leave-one-{cal['group_by']}-out" if cal else "none"


def comparison_table(records: list[dict], manifest: pd.DataFrame, subsets,
                     failures: pd.DataFrame | None = None) -> pd.DataFrame:
    """Per subset and method: the scores, false alarms on fault-free flights, the
    calibration protocol, and the flights excluded."""
    rows = []
    for subset in subsets:
        for method, (recs, excluded) in _records_for(records, manifest, subset,
                                                     failures).items():
            s = summarize([r["outcome"] for r in recs], [r["detection_s"] for r in recs])
            free = [r for r in recs if r["fault_class"] == "none"]
            rows.append({
                "subset": subset, "method": method, "detector": recs[0]["detector"],
                "calibration": _calibration(recs[0]), "flights": s["flights"],
                "precision": s["precision"], "recall": s["recall"], "accuracy": s["accuracy"],
                "mean_detection_s": s["mean_detection_s"],
                "max_detection_s": s["max_detection_s"],
                "fault_free_flights": len(free),
                "fault_free_false_alarms": sum(r["outcome"] == "FP" for r in free),
                "armed_flights": sum(any(v is not None for v in r["pair_armed_s"].values())
                                     for r in recs),
                "excluded": len(excluded),
            })
    return pd.DataFrame(rows)


def by_fault_table(records: list[dict], manifest: pd.DataFrame, subsets,
                   failures: pd.DataFrame | None = None) -> pd.DataFrame:
    info = manifest.set_index("flight")
    rows = []
    for subset in subsets:
        for method, (recs, _) in _records_for(records, manifest, subset, failures).items():
            groups = {c: [r for r in recs if r["fault_class"] == c] for c in FAULT_ORDER}
            groups["total"] = recs
            for fault_class, group in groups.items():
                if not group:
                    continue
                s = summarize([r["outcome"] for r in group], [r["detection_s"] for r in group])
                flights = [r["flight"] for r in group]
                rows.append({
                    "method": method, "subset": subset, "fault_class": fault_class,
                    "flights": len(group),
                    "flight_time_s": float(info.loc[flights, "flight_s"].sum()),
                    "pre_fault_s": float(info.loc[flights, "pre_fault_s"].sum()),
                    "mean_detection_s": s["mean_detection_s"],
                    "max_detection_s": s["max_detection_s"],
                    "accuracy": s["accuracy"],
                })
    return pd.DataFrame(rows)


def _fmt(v, pct=False, digits=2) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if isinstance(v, float):
        return f"{100 * v:.{digits}f}" if pct else f"{v:.{digits}f}"
    return str(v)


Section = tuple[str, list[str], list[list[str]]]  # title (`code` marked), header, rows


def _markdown(sections: list[Section]) -> str:
    out = []
    for title, header, rows in sections:
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(r) + " |" for r in rows]
        out.append(f"### {title}\n\n" + "\n".join(lines) + "\n")
    return "\n".join(out)


_LATEX_ESCAPES = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$",
                  "#": r"\#", "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                  "^": r"\textasciicircum{}"}


def latex_escape(text: str) -> str:
    """Escape ``text`` for LaTeX; `code` becomes \\texttt{code}."""
    parts = text.split("`")
    esc = ["".join(_LATEX_ESCAPES.get(ch, ch) for ch in part) for part in parts]
    return "".join(rf"\texttt{{{e}}}" if i % 2 else e for i, e in enumerate(esc))


_SHRINK = r"\resizebox{\ifdim\width>\linewidth\linewidth\else\width\fi}{!}{%"


def _latex(sections: list[Section], label: str) -> str:
    """One booktabs table float per section, labelled ``tab:<label>-<1, 2, ...>``, shrunk
    to the line width where wider (needs the graphicx and booktabs packages)."""
    out = []
    for i, (title, header, rows) in enumerate(sections, 1):
        spec = "l" * 3 + "r" * (len(header) - 3) if len(header) > 3 else "l" * len(header)
        lines = [r"\begin{table}[htbp]", r"\centering", r"\scriptsize",
                 rf"\caption{{{latex_escape(title)}}}\label{{tab:{label}-{i}}}", _SHRINK,
                 rf"\begin{{tabular}}{{{spec}}}", r"\toprule",
                 " & ".join(latex_escape(h) for h in header) + r" \\", r"\midrule"]
        lines += [" & ".join(latex_escape(c) for c in r) + r" \\" for r in rows]
        lines += [r"\bottomrule", r"\end{tabular}}", r"\end{table}"]
        out.append("\n".join(lines) + "\n")
    return "\n".join(out)


def _summary_sections(summary: pd.DataFrame) -> list[Section]:
    header = ["method", "flights", "excluded", "TP", "FP", "FN", "TN", "precision %",
              "recall %", "accuracy %", "mean det. s", "max det. s"]

    def cells(name, s):
        return [name, str(s["flights"]), _fmt(s.get("excluded")), str(s["tp"]), str(s["fp"]),
                str(s["fn"]), str(s["tn"]), _fmt(s["precision"], True), _fmt(s["recall"], True),
                _fmt(s["accuracy"], True), _fmt(s["mean_detection_s"]),
                _fmt(s["max_detection_s"])]

    out = []
    for subset, table in summary.groupby("subset", sort=False):
        rows = [cells(r["method"], r) for r in table.to_dict(orient="records")]
        if subset == "icra22":
            rows.append(cells(ICRA2019_NAME, ICRA2019_SUMMARY))
        out.append((f"Subset `{subset}`", header, rows))
    return out


def _by_fault_sections(by_fault: pd.DataFrame) -> list[Section]:
    out = []
    for (method, subset), table in by_fault.groupby(["method", "subset"], sort=False):
        paper = subset == "icra22"
        header = ["fault", "flights", "flight time s", "pre-fault s", "mean det. s",
                  "max det. s", "accuracy %"]
        if paper:
            header += ["paper: flights", "paper: flight time s", "paper: mean det. s",
                       "paper: max det. s", "paper: accuracy %"]
        rows = []
        for r in table.to_dict(orient="records"):
            row = [r["fault_class"], str(r["flights"]), _fmt(r["flight_time_s"], digits=1),
                   _fmt(r["pre_fault_s"], digits=1), _fmt(r["mean_detection_s"]),
                   _fmt(r["max_detection_s"]), _fmt(r["accuracy"], True)]
            if paper:
                ref = ICRA2019_BY_FAULT.get(r["fault_class"], (None,) * 5)
                row += [_fmt(ref[0]), _fmt(ref[1]), _fmt(ref[2]), _fmt(ref[3]),
                        _fmt(ref[4], True)]
            rows.append(row)
        out.append((f"`{method}` on `{subset}`", header, rows))
    return out


def _comparison_sections(comparison: pd.DataFrame) -> list[Section]:
    header = ["method", "detector", "calibration", "precision %", "recall %", "accuracy %",
              "mean det. s", "max det. s", "false alarms, fault-free flights",
              "flights armed", "flights excluded"]

    def cells(r):
        return [r["method"], r["detector"], r["calibration"], _fmt(r["precision"], True),
                _fmt(r["recall"], True), _fmt(r["accuracy"], True),
                _fmt(r["mean_detection_s"]), _fmt(r["max_detection_s"]),
                f"{r['fault_free_false_alarms']} of {r['fault_free_flights']}",
                _fmt(r.get("armed_flights")), _fmt(r.get("excluded"))]

    out = []
    for subset, table in comparison.groupby("subset", sort=False):
        rows = [cells(r) for r in table.to_dict(orient="records")]
        if subset == "icra22":
            paper = ICRA2019_SUMMARY
            free = ICRA2019_BY_FAULT["none"][0]
            rows.append(cells({**paper, "method": ICRA2019_NAME, "detector": "rls_arx_zscore",
                               "calibration": "(as published)", "fault_free_flights": free,
                               "fault_free_false_alarms": free - paper["tn"],
                               "armed_flights": None, "excluded": None}))
        # the subset's size: the first method's scored and excluded flights
        first = table.iloc[0]
        flights = int(first["flights"]) + int(first.get("excluded", 0))
        out.append((f"Subset `{subset}` ({flights} flights)", header, rows))
    return out


def summary_markdown(summary: pd.DataFrame) -> str:
    """Per subset, a table of methods, with the paper's row under ``icra22``."""
    return _markdown(_summary_sections(summary))


def summary_latex(summary: pd.DataFrame) -> str:
    """:func:`summary_markdown` as LaTeX (booktabs)."""
    return _latex(_summary_sections(summary), "summary")


def by_fault_markdown(by_fault: pd.DataFrame) -> str:
    """Per method and subset, Table I's layout; the paper's values beside ``icra22``."""
    return _markdown(_by_fault_sections(by_fault))


def by_fault_latex(by_fault: pd.DataFrame) -> str:
    """:func:`by_fault_markdown` as LaTeX (booktabs)."""
    return _latex(_by_fault_sections(by_fault), "by-fault")


def comparison_markdown(comparison: pd.DataFrame) -> str:
    """One table per subset; the ICRA 2019 paper's row under ``icra22``."""
    return _markdown(_comparison_sections(comparison))


def comparison_latex(comparison: pd.DataFrame) -> str:
    """:func:`comparison_markdown` as LaTeX (booktabs)."""
    return _latex(_comparison_sections(comparison), "comparison")
