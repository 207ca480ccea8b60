"""Scoring, tables and provenance of detector runs."""

from .calibration import folds
from .detections import (
    detect_all,
    detection_record,
    read_failures,
    read_records,
    write_record,
)
from .per_flight import per_flight_markdown, per_flight_table
from .scoring import OUTCOMES, flight_outcome, summarize
from .tables import (
    by_fault_latex,
    by_fault_markdown,
    by_fault_table,
    comparison_latex,
    comparison_markdown,
    comparison_table,
    failures_table,
    summary_latex,
    summary_markdown,
    summary_table,
)

__all__ = ["OUTCOMES", "by_fault_latex", "by_fault_markdown", "by_fault_table",
           "comparison_latex", "comparison_markdown", "comparison_table", "detect_all",
           "detection_record", "failures_table", "flight_outcome", "folds",
           "per_flight_markdown", "per_flight_table", "read_failures",
           "read_records", "summarize",
           "summary_latex", "summary_markdown", "summary_table", "write_record"]
