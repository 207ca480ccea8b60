"""alfa-bench: online fault detectors for fixed-wing UAVs, compared on the ALFA flights.

From Python, a detector is scored as the workflow scores its runs::

    import alfa_bench as ab

    corpus = ab.load_corpus()                      # ALFA_DIR, the config, or the download
    result = ab.evaluate(MyDetector(), corpus)     # or the name of a config run
    ab.compare(result, published="results")        # beside the runs of `snakemake all`

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
    "__version__": "alfa_bench.version",
    **dict.fromkeys(["Corpus", "Result", "compare", "evaluate", "load_corpus", "user_cache"],
                    "alfa_bench.evaluation"),
    **dict.fromkeys(["ConfigError", "load_config"], "alfa_bench.config"),
    **dict.fromkeys(["fit_run", "load_model", "save_run"], "alfa_bench.models"),
    **dict.fromkeys(["CalibrationError", "Detector", "MaximaThresholds", "NotFittedError",
                     "make_detector"], "alfa_bench.methods"),
}

__all__ = sorted(_MODULES)
__getattr__, __dir__ = lazy_names(__name__, _MODULES)
