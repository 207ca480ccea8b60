"""Scoring, tables and provenance of detector runs."""

import importlib

# each name's module, imported when the name is first used: a job imports only the
# modules it needs (every script imports this package, for its log)
_MODULES = {
    "folds": "calibration",
    "detect_all": "detections",
    "detection_record": "detections",
    "read_failures": "detections",
    "read_records": "detections",
    "write_record": "detections",
    "per_flight_markdown": "per_flight",
    "per_flight_table": "per_flight",
    "OUTCOMES": "scoring",
    "flight_outcome": "scoring",
    "summarize": "scoring",
    "by_fault_latex": "tables",
    "by_fault_markdown": "tables",
    "by_fault_table": "tables",
    "comparison_latex": "tables",
    "comparison_markdown": "tables",
    "comparison_table": "tables",
    "failures_table": "tables",
    "summary_latex": "tables",
    "summary_markdown": "tables",
    "summary_table": "tables",
}

__all__ = sorted(_MODULES)


def __getattr__(name: str):
    if name not in _MODULES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_MODULES[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return list(__all__)
