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

import importlib

# each name's module, imported when the name is first used: a workflow job that imports
# one module of the package pays for no other
_MODULES = {
    "Corpus": "alfa_bench.analysis.evaluation",
    "Result": "alfa_bench.analysis.evaluation",
    "compare": "alfa_bench.analysis.evaluation",
    "evaluate": "alfa_bench.analysis.evaluation",
    "load_config": "alfa_bench.analysis.evaluation",
    "load_corpus": "alfa_bench.analysis.evaluation",
    "CalibrationError": "alfa_bench.methods",
    "Detector": "alfa_bench.methods",
    "MaximaThresholds": "alfa_bench.methods",
    "NotFittedError": "alfa_bench.methods",
    "make_detector": "alfa_bench.methods",
}

__all__ = sorted(_MODULES)


def __getattr__(name: str):
    if name not in _MODULES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_MODULES[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return list(__all__)
