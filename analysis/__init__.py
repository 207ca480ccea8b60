"""The evaluation core: folds (:mod:`.held_out`), detection records (:mod:`.detections`),
their provenance (:mod:`.provenance`), the blocks runs are ranked in (:mod:`.blocks`),
scoring (:mod:`.scoring`), and the analyses the tables are made of (sweep, deadline,
detectability, isolation, leakage, ceiling, per flight, stability).

The rooms lean one way: :mod:`alfa_bench.outputs` (files, tables, figures, recordings)
and :mod:`alfa_bench.workflow` (what only the Snakemake rules use) import from here,
never the other way; the Python route (:mod:`alfa_bench.evaluation`) sits above both."""

from alfa_bench.lazy import lazy_names

# each name's module, imported when the name is first used: a job imports only the
# modules it needs
_MODULES = {
    "folds": ".held_out",
    **dict.fromkeys(["calibration_failure", "detect_all", "detection_record"], ".detections"),
    **dict.fromkeys(["per_flight_markdown", "per_flight_table"], ".per_flight"),
    **dict.fromkeys(["provenance", "run_provenance"], ".provenance"),
    **dict.fromkeys(["OUTCOMES", "flight_outcome", "score_records", "summarize"], ".scoring"),
}

__all__ = sorted(_MODULES)
__getattr__, __dir__ = lazy_names(__name__, _MODULES)
