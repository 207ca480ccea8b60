"""Exceptions raised by the ALFA data layer, one type per kind of trouble.

:class:`AlfaDataError` is bad flight data, and only that: a stage turns it into a
failure row for the flight (and method) and goes on. The others are not a flight's
fault and stop the run: a signal name no catalogue holds (a config or code error), a
folder that is not there, a download that failed, a stale cache. Every message names
the flight, and where they apply the file, the column and the line, so that a broken
input can be found without a debugger.
"""

from __future__ import annotations

__all__ = ["FAILURE_COLUMNS", "AlfaDataError", "DownloadError", "MissingFolderError",
           "MissingTopicError", "StaleCacheError", "UnknownSignalError", "failure_row"]

#: Columns of a failures table: where a flight was given up, and why.
FAILURE_COLUMNS = ["flight", "stage", "method", "file", "column", "line", "error"]


class AlfaDataError(ValueError):
    """Input that cannot be read without risking a wrong number.

    Parameters
    ----------
    message : str
        What is wrong.
    flight, file, column : str, optional
        Where it is wrong.
    line : int, optional
        1-based line number in ``file`` (the header is line 1).
    """

    def __init__(
        self,
        message: str,
        *,
        flight: str | None = None,
        file: str | None = None,
        column: str | None = None,
        line: int | None = None,
    ):
        self.flight, self.file, self.column, self.line = flight, file, column, line
        where = [f"flight {flight}"] if flight else []
        if file:
            where.append(f"file {file}")
        if column:
            where.append(f"column {column!r}")
        if line is not None:
            where.append(f"line {line}")
        super().__init__(f"{', '.join(where)}: {message}" if where else message)


class MissingTopicError(AlfaDataError):
    """A topic a method needs has no CSV file in the flight folder."""


class UnknownSignalError(LookupError):
    """A signal name that :data:`~.signals.SIGNALS` does not hold: a config or code
    error, never a flight's."""


class MissingFolderError(FileNotFoundError):
    """The folder of the flights (``ALFA_DIR``, ``processed/``) is not there."""


class DownloadError(OSError):
    """The archive could not be fetched, verified or unpacked; the message says what
    to do."""


class StaleCacheError(RuntimeError):
    """The parsed-flight cache was made from other files than the manifest's."""


def failure_row(error: AlfaDataError, stage: str, method: str = "") -> dict:
    """A row of a failures table for ``error``, raised at ``stage`` (``load``,
    ``calibration``, ``detect``) of ``method`` (empty for all methods)."""
    return {"flight": error.flight or "", "stage": stage, "method": method,
            "file": error.file or "", "column": error.column or "",
            "line": "" if error.line is None else error.line, "error": str(error)}
