"""A corpus of logs in the workflow (``--config corpus=<folder>``): the folder converted
when the workflow starts (:func:`alfa_bench.logs.corpus.convert_corpus`), the runs it
cannot run named, and the ALFA-only parts of the config set aside.

A run that reads a signal the corpus lacks is *not applicable*: taken out of the
config's ``methods`` before any job is planned, so that it shrinks no ranked run's
common ground, and kept in ``config["not_applicable"]`` (run -> its missing signals and
why), which the tables and the page list. The subset ``icra22`` is the 22 ALFA flights
of the ICRA paper, so a corpus has none; ``emr`` is kept where ``labels.csv`` marks a
flight with an emergency trajectory.
"""

from __future__ import annotations

import logging
from pathlib import Path

__all__ = ["CONVERTED", "corpus_config", "not_applicable"]

log = logging.getLogger(__name__)

#: where a corpus is converted: its processed/ is the workflow's flights
CONVERTED = Path("results/corpus")


def not_applicable(methods: dict, signals: dict[str, str | None]) -> dict[str, str]:
    """Run -> ``signal (why); ...`` for each run of ``methods`` that reads a signal the
    corpus lacks (``signals``: signal -> why not, None where the corpus has it)."""
    from alfa_bench.methods import make_detector

    out = {}
    for run, spec in methods.items():
        needs = make_detector(spec["detector"], spec.get("params")).signals()
        missing = [s for s in dict.fromkeys(needs) if signals.get(s) is not None]
        if missing:
            out[run] = "; ".join(f"{s} ({signals[s]})" for s in missing)
    return out


def corpus_config(config: dict, signals: dict[str, str | None], emr: bool) -> None:
    """``config`` made the corpus's: its not-applicable runs out of ``methods`` into
    ``not_applicable`` and out of every part that names runs, the injected sensor faults
    on the signals it has, and the subsets it has (``emr`` only where a flight of it is
    ``emr``)."""
    config["not_applicable"] = not_applicable(config["methods"], signals)
    for run, why in config["not_applicable"].items():
        log.warning("run %s is not applicable to the corpus: it reads %s", run, why)
        del config["methods"][run]
    # the parts of the config that name runs name only those that run
    runs = set(config["methods"])
    refit = config["stability"]["refit"]
    refit["runs"] = [r for r in refit["runs"] if r in runs]
    study = config.get("public_study")
    if study:
        study["steps"] = [s for s in study.get("steps", []) if s["run"] in runs]
    config["features_learners"] = [
        row for row in ({k: v for k, v in row.items() if k == "learner" or v in runs}
                        for row in config.get("features_learners", []))
        if len(row) > 1]
    # a sensor fault is injected into a signal the corpus has
    injection = config["injection"]
    injection["sensors"] = [s for s in injection["sensors"] if signals.get(s, "") is None]
    dropped = ["icra22", *([] if emr else ["emr"])]
    config["subsets"] = [s for s in config["subsets"] if s not in dropped]
    if config["primary_subset"] not in config["subsets"]:
        config["primary_subset"] = "all" if "all" in config["subsets"] else config["subsets"][0]
