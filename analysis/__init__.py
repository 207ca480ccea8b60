"""The evaluation core: folds (:mod:`.held_out`), detection records (:mod:`.detections`),
scoring (:mod:`.scoring`) and the Python route (:mod:`.evaluation`), and the analyses
the tables are made of (sweep, deadline, detectability, isolation, leakage, ceiling,
per flight). Tables, figures, recordings and provenance are written by
:mod:`alfa_bench.outputs`; what only the workflow uses is :mod:`alfa_bench.workflow`."""

from alfa_bench.lazy import lazy_names

# each name's module, imported when the name is first used: a job imports only the
# modules it needs
_MODULES = {
    **dict.fromkeys(["Corpus", "Result", "compare", "evaluate", "load_corpus"], ".evaluation"),
    "folds": ".held_out",
    **dict.fromkeys(["detect_all", "detection_record", "read_failures", "read_records",
                     "write_record"], ".detections"),
    **dict.fromkeys(["per_flight_markdown", "per_flight_table"], ".per_flight"),
    **dict.fromkeys(["OUTCOMES", "flight_outcome", "score_records", "summarize"], ".scoring"),
    # the tables moved to alfa_bench.outputs; their names are still importable from here
    **dict.fromkeys(["by_fault_latex", "by_fault_markdown", "by_fault_table",
                     "comparison_latex", "comparison_markdown", "comparison_table",
                     "failures_table", "summary_latex", "summary_markdown", "summary_table"],
                    "alfa_bench.outputs.tables"),
}

__all__ = sorted(_MODULES)
__getattr__, __dir__ = lazy_names(__name__, _MODULES)
