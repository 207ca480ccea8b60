"""Logging set-up for workflow scripts: everything to the rule's log file."""

import logging
import sys
from pathlib import Path

import pandas as pd

__all__ = ["closing_lines", "failed_flights_line", "log_to", "page_line"]


def log_to(path: str) -> None:
    """Send INFO and above of every logger to ``path``, capture warnings, and log an
    uncaught exception there too (it still reaches stderr and fails the job)."""
    logging.basicConfig(filename=path, filemode="w", level=logging.INFO, force=True,
                        format="%(levelname)s %(name)s: %(message)s")
    logging.captureWarnings(True)

    def excepthook(kind, value, tb):
        logging.getLogger("alfa_bench").critical("stopped: %s", value, exc_info=(kind, value, tb))
        sys.__excepthook__(kind, value, tb)

    sys.excepthook = excepthook


def failed_flights_line(results: str | Path = "results") -> str | None:
    """One line on the flights the run failed on, for the end of Snakemake's log: how
    many were refused at load and how many some run failed on, and where to read why;
    None when there are none, or no table says yet."""
    results = Path(results)
    left_out, failures = results / "tables/left_out.csv", results / "tables/failures.csv"
    if not left_out.is_file():
        return None
    rows = pd.read_csv(left_out, dtype=str, keep_default_na=False)
    if not len(rows):
        return None
    load = rows["runs"] == "every run"
    runs = {m for r in rows.loc[~load, "runs"] for m in r.split(";") if m}
    errors = len(pd.read_csv(failures)) if failures.is_file() else 0
    return (f"alfa-bench: {len(rows)} flight(s) left out of the common ground every run is "
            f"ranked on: {int(load.sum())} refused at load, {int((~load).sum())} failed by "
            f"{len(runs)} run(s); {errors} error(s) in {failures}, the flights in {left_out}")


def page_line(primary: str, results: str | Path = "results") -> str | None:
    """One line naming the page to open, ``results/index.html``, with how many runs the
    comparison ranks on the headline subset ``primary`` and how many it leaves unranked;
    None when the run wrote no page."""
    results = Path(results)
    page, comparison = results / "index.html", results / "tables/comparison.csv"
    if not page.is_file() or not comparison.is_file():
        return None
    rows = pd.read_csv(comparison, usecols=["subset", "rank"])
    rows = rows[rows["subset"] == primary]
    ranked = int(rows["rank"].notna().sum())
    return (f"alfa-bench: open {page}: {ranked} run(s) ranked on `{primary}`, "
            f"{len(rows) - ranked} not ranked (each with why, on the page)")


def closing_lines(primary: str, results: str | Path = "results") -> list[str]:
    """The lines a successful run ends on: the flights it failed on, if any, then the
    page to open (:func:`failed_flights_line`, :func:`page_line`)."""
    return [line for line in (failed_flights_line(results), page_line(primary, results))
            if line]
