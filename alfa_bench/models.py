"""A configured run fitted once on the flights it is given, and saved to a model file.

::

    import alfa_bench as ab

    corpus = ab.load_corpus()
    ab.save_run("coincidence", corpus, "coincidence.abm")   # fitted on every flight
    detector, about = ab.load_model("coincidence.abm")        # runs no code from the file

The file (:mod:`alfa_bench.methods.model_files`) holds the fitted detector, the run's
name and config spec, the SHA-256 of every flight it was fitted on, the signals it reads
and whether any of them is one ALFA's fault emulation writes.
"""

from __future__ import annotations

import os
from pathlib import Path

from threadpoolctl import threadpool_limits

from alfa_bench.evaluation import Corpus
from alfa_bench.methods import Detector, make_detector, training_segments
from alfa_bench.methods.model_files import load_model, save_model

__all__ = ["fit_run", "load_model", "save_run"]


def fit_run(run: str, corpus: Corpus, flights: list[str] | None = None) -> Detector:
    """The detector of the config run ``run`` fitted on ``flights`` of ``corpus`` (by
    name; default: every flight with ground truth), as a workflow fold fits it: labelled
    flights for a supervised run, else their fault-free data less the config's margin."""
    methods = corpus.config["methods"]
    if run not in methods:
        raise KeyError(f"no run {run!r} in the config; its runs: {', '.join(methods)}")
    spec = methods[run]
    detector = make_detector(spec["detector"], spec.get("params"))
    names = list(corpus.flights) if flights is None else list(flights)
    unknown = sorted(set(names) - set(corpus.manifest["flight"]))
    if unknown:
        raise KeyError(f"flights not in the corpus: {unknown}")
    if detector.calibrated:
        segments = training_segments(detector, [corpus.flight(n) for n in names],
                                     float(corpus.config["calibration"]["margin_s"]))
        # one BLAS thread, as every workflow job: a fit's last digits depend on it
        with threadpool_limits(1, user_api="blas"):
            detector.fit(segments)
    else:
        detector.fit([])
    return detector


def save_run(run: str, corpus: Corpus, path: str | os.PathLike,
             flights: list[str] | None = None) -> Path:
    """:func:`fit_run`, written to the model file ``path``."""
    names = list(corpus.flights) if flights is None else list(flights)
    detector = fit_run(run, corpus, names)
    sha = corpus.manifest.set_index("flight")["sha256"]
    return save_model(detector, path, run=run, config=corpus.config["methods"][run],
                      data={n: str(sha[n]) for n in names})
