"""The evaluation core: folds (:mod:`.held_out`), detection records (:mod:`.detections`),
scoring (:mod:`.scoring`) and the Python route (:mod:`.evaluation`), and the analyses
the tables are made of (sweep, deadline, detectability, isolation, leakage, ceiling,
per flight). Tables, figures, recordings and provenance are written by
:mod:`alfa_bench.outputs`; what only the workflow uses is :mod:`alfa_bench.workflow`."""

import importlib

# each name's module, imported when the name is first used: a job imports only the
# modules it needs (every script imports this package, for its log)
_MODULES = {
    "Corpus": ".evaluation",
    "Result": ".evaluation",
    "compare": ".evaluation",
    "evaluate": ".evaluation",
    "load_corpus": ".evaluation",
    "folds": ".held_out",
    "detect_all": ".detections",
    "detection_record": ".detections",
    "read_failures": ".detections",
    "read_records": ".detections",
    "write_record": ".detections",
    "per_flight_markdown": ".per_flight",
    "per_flight_table": ".per_flight",
    "OUTCOMES": ".scoring",
    "flight_outcome": ".scoring",
    "score_records": ".scoring",
    "summarize": ".scoring",
    "by_fault_latex": "alfa_bench.outputs.tables",
    "by_fault_markdown": "alfa_bench.outputs.tables",
    "by_fault_table": "alfa_bench.outputs.tables",
    "comparison_latex": "alfa_bench.outputs.tables",
    "comparison_markdown": "alfa_bench.outputs.tables",
    "comparison_table": "alfa_bench.outputs.tables",
    "failures_table": "alfa_bench.outputs.tables",
    "summary_latex": "alfa_bench.outputs.tables",
    "summary_markdown": "alfa_bench.outputs.tables",
    "summary_table": "alfa_bench.outputs.tables",
}

__all__ = sorted(_MODULES)


def __getattr__(name: str):
    if name not in _MODULES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_MODULES[name], __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return list(__all__)
