"""The page a reader opens first: ``results/index.html``.

One light page, no external assets (the figure is inlined), that shows on arrival what
the run found: how many ranked runs the data cannot tell apart from the leader; the
ranked honest runs on the headline subset, with their detections in time beside the
stable ones and false alarms on fault-free flights; the threshold sweep figure; and
each of those runs' detections by fault class, with the detectability ceiling of a
class none of them detects. Below: the runs not ranked, each with why. It links to
the full tables and the per-flight outcomes, every link a file ``snakemake all``
writes.
"""

from __future__ import annotations

import base64
import html
from pathlib import Path

import pandas as pd

from alfa_bench.analysis.blocks import FAULT_ORDER
from alfa_bench.data import in_subset
from alfa_bench.render import fmt

from .tables import SIGNIFICANCE, SILENT, SUBSET_NOTES, ground_note

__all__ = ["index_html"]

#: laid out to show the headline, the per-class table and the figure, at its own size
#: (outputs/figures.py draws it for this column), in a 1400 x 900 window without a scroll
_STYLE = """
body { font: 14px/1.35 system-ui, sans-serif; margin: 14px 28px; color: #222;
       max-width: 1340px; }
h1 { font-size: 19px; margin: 0 0 2px; } h2 { font-size: 15px; margin: 10px 0 4px; }
p { margin: 2px 0 6px; } table { border-collapse: collapse; font-size: 13px; }
th, td { padding: 1px 8px; border-bottom: 1px solid #ddd; text-align: right; }
td { white-space: nowrap; }
th { background: #f3f3f3; } td:nth-child(2), th:nth-child(2) { text-align: left; }
.row { display: flex; gap: 16px; align-items: flex-start; }
.row > div:first-child { flex: 1 1 0; } .row > div:last-child { flex: none; width: min-content; }
.row img { max-width: none; }
img { max-width: 100%; border: 1px solid #eee; }
.lead { font-size: 15px; margin: 4px 0 6px; }
.links a { margin-right: 14px; } .note { color: #555; font-size: 12px; }
"""

#: the ranked runs the headline table shows, and those the per-class table shows, best
#: first (every run: comparison.html)
RANKED_ROWS = 10
CLASS_ROWS = 6


def _row(cells: list[str], tag: str = "td") -> str:
    return "<tr>" + "".join(f"<{tag}>{html.escape(c)}</{tag}>" for c in cells) + "</tr>"


def _cells(r: dict) -> list[str]:
    """A ranked run's row of the headline table."""
    stable = r.get("stable_detections")
    pooled = fmt(stable) != "-"
    return [str(int(r["rank"])), r["method"], r["family"],
            f"{int(r['tp'])} of {int(r['tp'] + r['fn'])}",
            str(int(stable)) if pooled else "not resampled",
            (f"{fmt(r['detections_low'], digits=0)}-{fmt(r['detections_high'], digits=0)}"
             if pooled else "-"),
            f"{int(r['fault_free_false_alarms'])} of {int(r['fault_free_flights'])}",
            fmt(r["precision"], True, 1), fmt(r["recall"], True, 1),
            fmt(r["accuracy"], True, 1), fmt(r["mean_detection_s"]),
            str(r.get("rank_range") or "-"), _told_apart(r)]


def _told_apart(r: dict) -> str:
    """Whether the exact McNemar test tells a ranked run apart from the leader."""
    p = r.get("vs_best_p")
    if r["rank"] == 1 or fmt(p) == "-":
        return "leader" if r["rank"] == 1 else "-"
    return f"{'yes' if p < SIGNIFICANCE else 'no'}, p {p:.2f}"


def _apart(table: pd.DataFrame) -> str:
    """The leader, and how many ranked runs the data cannot tell apart from it (exact
    McNemar), in plain words for the top of the page."""
    if not len(table):
        return "No run is ranked."
    lead = table.iloc[0]
    if not int(lead["tp"] + lead["fn"]):
        # a ranking of runs that had no fault to find says nothing of which finds faults
        return (f"<strong>No run can be told ahead:</strong> the {int(lead['flights'])} "
                "flight(s) every ranked run scored hold no fault, so recall cannot be "
                "computed and the ranks below order false alarms alone.")
    same = int(((table["rank"] > 1) & (table["vs_best_p"] >= SIGNIFICANCE)).sum())
    found = f"{int(lead['tp'])} of {int(lead['tp'] + lead['fn'])} faults in time"
    if not same:
        return (f"The leader, <code>{html.escape(lead['method'])}</code> ({found}), is "
                f"told apart from every other ranked run (exact McNemar, p &lt; "
                f"{SIGNIFICANCE}).")
    return (f"<strong>No clear winner:</strong> the data cannot tell the leader, "
            f"<code>{html.escape(lead['method'])}</code> ({found}), apart from {same} of "
            f"the other {len(table) - 1} ranked runs (exact McNemar, p ≥ {SIGNIFICANCE}).")


#: why a run of each block is not ranked, when its row gives no reason of its own
_WHY = {"reads actuators": "reads what the fault emulation writes (servo outputs, "
                           "throttle), so it sees the label",
        "reference": "a reference row: what lateness, the emulation alone or a "
                     "calibration that saw the scored date gives"}


def _unranked(subset: pd.DataFrame) -> str:
    """The runs of the headline subset without a rank, each with why, in a list."""
    rows = subset[subset["rank"].isna()]
    if not len(rows):
        return ""
    items = []
    for r in rows.to_dict(orient="records"):
        why = r.get("not_ranked")
        why = why if isinstance(why, str) and why else _WHY.get(r["block"], r["block"])
        items.append(f"<li><code>{html.escape(r['method'])}</code>: {html.escape(why)}</li>")
    return (f"<h2>Not ranked ({len(rows)} runs)</h2>\n<ul class=\"note\">"
            + "".join(items) + "</ul>")


def _beyond_reach(ceiling: pd.DataFrame, per_class: pd.DataFrame, shown, primary: str,
                  d: str) -> str:
    """For each fault class none of the ``shown`` runs detects in time, what the best
    single feature of the ceiling table reaches on it, in a note."""
    mine = per_class[per_class["method"].isin(shown)]
    missed = [c for c, g in mine.groupby("fault_class", sort=False)
              if c in FAULT_ORDER and c != "none" and g["flights"].gt(0).all()
              and not g["detected"].any()]
    best = ceiling[(ceiling["subset"] == primary) & ceiling["best"].astype(bool)
                   ].drop_duplicates("fault_class").set_index("fault_class")
    lines = []
    for c in missed:
        if c not in best.index:
            continue
        r = best.loc[c]
        lines.append(
            f"<code>{html.escape(c)}</code>: no single feature carries it within {d} s of "
            f"onset: the best, <code>{html.escape(r['feature'])}</code>, separates its "
            f"{int(r['fault_flights'])} flight{'s' * int(r['fault_flights'] > 1)} from "
            f"fault-free flight with AUC "
            f"{fmt(r['auc'])} (95 % {fmt(r['auc_low'])}-{fmt(r['auc_high'])}; 0.5 is "
            f"chance) and passes every fault-free maximum on {int(r['above_free_max'])} of "
            f"{int(r['fault_flights'])}")
    if not lines:
        return ""
    return ('<p class="note">Why no run above detects these in time ('
            '<a href="tables/ceiling.md">the detectability ceiling</a>): '
            + "; ".join(lines) + ".</p>")


def _left_out(left_out: pd.DataFrame, subset: str) -> str:
    """The flights of ``subset`` off the common ground, and why, in a line."""
    rows = in_subset(left_out, subset)
    if not len(rows):
        return ""
    why = "; ".join(
        f"<code>{html.escape(r['flight'])}</code> "
        + ("refused at load" if r["runs"] == "every run" else
           f"failed by {html.escape(str(r['runs']).replace(';', ', '))}")
        for r in rows.to_dict(orient="records"))
    return (f'<p class="note">The runs are ranked on the flights every ranked run scored; left '
            f'out: {why} (why: <a href="tables/failures.csv">failures.csv</a>).</p>')


def _not_applicable(not_applicable: dict[str, str]) -> str:
    """The runs a corpus of logs cannot run, each with the signals it lacks, in a list."""
    if not not_applicable:
        return ""
    items = "".join(f"<li><code>{html.escape(run)}</code>: reads {html.escape(why)}</li>"
                    for run, why in not_applicable.items())
    return (f"<h2>Not applicable to this corpus ({len(not_applicable)} runs)</h2>\n"
            "<p class=\"note\">They read a signal the logs do not give "
            "(<a href=\"corpus/signals.csv\">signals.csv</a>), so they were not run."
            f"</p><ul class=\"note\">{items}</ul>")


def index_html(comparison: pd.DataFrame, by_fault: pd.DataFrame, sweep_png: Path,
               primary: str, run: str, left_out: pd.DataFrame, ceiling: pd.DataFrame,
               not_applicable: dict[str, str] | None = None,
               data: str = "the ALFA flights") -> str:
    """The page (module docstring) from the run's ``comparison``, ``by_fault``,
    ``left_out`` and ``ceiling`` tables and its sweep figure; ``run`` names the run in
    the footer, ``data`` the flights ranked; ``not_applicable`` (run -> the signals
    it lacks) lists the runs a corpus of logs cannot run."""
    subset = comparison[comparison["subset"] == primary]
    table = subset[subset["rank"].notna()].sort_values("rank")
    d = fmt(float(comparison["deadline_s"].iloc[0]), digits=1)
    flights = ground_note(subset) if len(subset) else "0 flights"
    head = ["rank", "method", "family", f"faults detected ≤{d} s", "of them stable",
            "range, calibration resampled", "fault-free flights alarmed", "precision %",
            "recall %", "accuracy %", "mean det. s", "rank range, resampled",
            "told apart from the leader"]
    rows = [_row(head, "th")] + [_row(_cells(r)) for r in
                                 table.head(RANKED_ROWS).to_dict(orient="records")]
    more = len(table) - RANKED_ROWS
    shown = f" (the best {RANKED_ROWS}; {more} more in every run and subset)" if more > 0 else ""
    silent = subset[subset["detector"] == SILENT]
    quiet = (f" A run that arms and never alarms (<code>{SILENT}</code>) scores "
             f"{fmt(silent['accuracy'].iloc[0], True, 1)} % accuracy: "
             f"{int((~table['beats_silence'].astype(bool)).sum())} of {len(table)} ranked "
             "runs do no better, and are flagged in the tables." if len(silent) else "")
    best = table.drop_duplicates("family")
    family_rows = [_row(["family", "best run", "rank", f"detected ≤{d} s",
                         "fault-free alarmed"], "th")] + [
        _row([r["family"], r["method"], str(int(r["rank"])),
              f"{int(r['tp'])} of {int(r['tp'] + r['fn'])}",
              f"{int(r['fault_free_false_alarms'])} of {int(r['fault_free_flights'])}"])
        for r in best.to_dict(orient="records")]
    classes = [c for c in FAULT_ORDER if c != "none"]
    per_class = by_fault[(by_fault["subset"] == primary)
                         & by_fault["method"].isin(table["method"])]
    counts = {(r["method"], r["fault_class"]): f"{r['detected']} of {r['flights']}"
              for r in per_class.to_dict(orient="records")}
    present = [c for c in classes if any(k[1] == c for k in counts)]
    class_rows = [_row(["rank", "method", *present], "th")] + [
        _row([str(int(r["rank"])), r["method"], *(counts.get((r["method"], c), "-")
                                                  for c in present)])
        for r in table.head(CLASS_ROWS).to_dict(orient="records")]
    reach = _beyond_reach(ceiling, per_class, table.head(CLASS_ROWS)["method"], primary, d)
    figure = base64.b64encode(Path(sweep_png).read_bytes()).decode()
    note = f"; {html.escape(SUBSET_NOTES[primary])}" if primary in SUBSET_NOTES else ""
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>alfa-bench: results</title>
<style>{_STYLE}</style></head><body>
<h1>alfa-bench: online fault detectors on {html.escape(data)}</h1>
<p class="lead">{_apart(table)}</p>
<p>Headline: subset <code>{html.escape(primary)}</code> ({flights}{note}), a fault
detected when the first alarm comes at most {d} s after onset; {len(table)} honest runs
ranked, {int(subset["rank"].isna().sum())} not ranked (below, with why).</p>
{_left_out(left_out, primary)}
<p class="links"><a href="tables/comparison.html">every run and subset</a>
<a href="tables/stability.md">stability</a> <a href="tables/per_flight.md">per flight</a>
<a href="tables/ceiling.md">detectability ceiling</a>
<a href="../paper/build/paper.md">the paper</a> <span class="note">(the Snakemake
report: <code>snakemake --report results/report.html</code>)</span></p>
<h2>Ranked honest runs, deadline {d} s{shown}</h2>
<table>{''.join(rows)}</table>
<div class="row"><div>
<h2>Faults detected in time, by class (the best {CLASS_ROWS})</h2>
<table>{''.join(class_rows)}</table>
{reach}
<h2>The best run of each family</h2>
<table>{''.join(family_rows)}</table></div>
<div><h2>Threshold sweep</h2>
<a href="figures/sweep.png"><img alt="Threshold sweep of every method"
     src="data:image/png;base64,{figure}"></a>
<p class="note">Every channel threshold of a method scaled by one factor and the stored
scores re-scored, on <code>{html.escape(primary)}</code> with the deadline; dots mark
the configured thresholds.</p></div></div>
<h2>How the runs are ranked</h2>
<p>Only honest runs (sensors and setpoints only) are ranked: by accuracy within the
deadline (faults detected in time and fault-free flights left quiet, of all flights),
then recall, then mean detection time.{quiet} A detection is <em>stable</em> when it
survives when the calibration flights are resampled (most of the resamples; "not
resampled": thresholds that need a refit).</p>
{_unranked(subset)}
{_not_applicable(not_applicable or {})}
<p class="note">Run {html.escape(run)}: code, packages, config, data and checksums in
<code>results/provenance.json</code>.</p>
</body></html>
"""
