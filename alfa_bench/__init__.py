"""alfa-bench: online fault detectors for fixed-wing UAVs, compared on the ALFA flights.

From Python, a detector is scored as the workflow scores its runs::

    import alfa_bench as ab

    corpus = ab.load_corpus()                      # ALFA_DIR, the config, or the download
    result = ab.evaluate(MyDetector(), corpus)     # or the name of a config run
    ab.compare(result)                             # ranked beside results/ of the workflow

The rooms: :mod:`alfa_bench.data` (flights, signals, manifest), :mod:`alfa_bench.methods`
(the detector contract and the detectors), :mod:`alfa_bench.analysis` (folds,
detection records, scoring, :func:`evaluate`), :mod:`alfa_bench.outputs` (tables,
figures, recordings, provenance, the paper) and :mod:`alfa_bench.workflow` (what only
the Snakemake rules and scripts use).
"""

from alfa_bench.lazy import lazy_names

# each name's module, imported when the name is first used: a workflow job that imports
# one module of the package pays for no other
_MODULES = {
    **dict.fromkeys(["Corpus", "Result", "compare", "evaluate", "load_config", "load_corpus"],
                    "alfa_bench.analysis.evaluation"),
    **dict.fromkeys(["CalibrationError", "Detector", "MaximaThresholds", "NotFittedError",
                     "make_detector"], "alfa_bench.methods"),
}

__all__ = sorted(_MODULES)
__getattr__, __dir__ = lazy_names(__name__, _MODULES)
