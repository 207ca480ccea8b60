"""What a detect job spends its time and its fits on: the columns of the cost table
(``benchmarks/bench_workflow.py``), which the job writes beside its time
(:func:`~.detect_job.run`).

- ``fits_made``: the job's fold fits, and the fits it made for a store
  (:data:`~alfa_bench.methods.fits.MODEL_FITS`,
  :data:`~alfa_bench.methods.nested_selection.INNER_FITS`) because none held them;
- ``fits_kept``: fits a store gave again from the job's process;
- ``fits_read``: fits read from the folder of fits (``results/fits``);
- ``fitting_s``: seconds in the fold fits (their inner fits, feature rows and the
  folder's reads and writes included);
- ``scoring_s``: seconds running the fitted detectors over the flights (their forks
  and continued runs included);
- ``features_s``: seconds in the detectors' feature rows (``_features``: the
  classifiers', the outlier models'), within fitting and scoring;
- ``reading_s``: seconds loading the flights, and reading fits from the folder;
- ``writing_s``: seconds writing records, traces and figure panels, and fits to the
  folder.

The seconds overlap where the table says so; each is counted once where calls nest.
The timers wrap the functions for the job's process only (:func:`measured`), so the
project's modules carry no instrumentation; each adds two clock reads a call.
"""

from __future__ import annotations

import functools
import time
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["COLUMNS", "measured"]

#: the cost table's columns, in order (module docstring)
COLUMNS = ("fits_made", "fits_kept", "fits_read", "fitting_s", "scoring_s", "features_s",
           "reading_s", "writing_s")


def _timed(function, kind: str, totals: Counter, running: set[str]):
    """``function``, its seconds added to ``totals[kind]`` (and the calls to
    ``totals[kind + ":calls"]``) unless a call of the same kind is running already."""
    @functools.wraps(function)
    def timed(*args, **kwargs):
        if kind in running:
            return function(*args, **kwargs)
        running.add(kind)
        started = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            totals[kind] += time.perf_counter() - started
            totals[f"{kind}:calls"] += 1
            running.discard(kind)

    return timed


def _subclasses(cls: type) -> Iterator[type]:
    for sub in cls.__subclasses__():
        yield sub
        yield from _subclasses(sub)


@contextmanager
def measured(detector: type) -> Iterator[dict]:
    """Within it, the fits of ``detector`` (the run's class), the scoring, the feature
    rows of every detector class loaded, and the writing of the outputs are timed, and
    the stores' counts start from zero; the dict it gives holds the :data:`COLUMNS`
    once it ends (``reading_s`` the fits' reading only: the job adds its flights')."""
    from alfa_bench.analysis import detections
    from alfa_bench.methods import fits
    from alfa_bench.methods.base import Detector
    from alfa_bench.outputs import flight_figures, records

    totals, running = Counter(), set()
    wrapped = [(detector, "fit", "fitting_s"),
               *((detections, name, "scoring_s")
                 for name in ("run_detector", "forks", "continue_forks")),
               *((cls, "_features", "features_s") for cls in set(_subclasses(Detector))
                 if "_features" in vars(cls)),
               (records, "write_record", "writing_s"), (records, "write_trace", "writing_s"),
               (flight_figures.FlightPanel, "draw", "writing_s")]
    saved = [(owner, name, vars(owner).get(name)) for owner, name, _ in wrapped]
    for owner, name, kind in wrapped:
        setattr(owner, name, _timed(getattr(owner, name), kind, totals, running))
    fits.COUNTS.clear()
    costs: dict = {}
    try:
        yield costs
    finally:
        for owner, name, before in saved:
            if before is None:
                delattr(owner, name)          # inherited: the base's again
            else:
                setattr(owner, name, before)
        counts = fits.COUNTS
        costs.update({"fits_made": totals["fitting_s:calls"] + counts["made"],
                      "fits_kept": counts["kept"], "fits_read": counts["read"],
                      **{k: totals[k] for k in ("fitting_s", "scoring_s", "features_s")},
                      "reading_s": counts["reading_s"],
                      "writing_s": totals["writing_s"] + counts["writing_s"]})
