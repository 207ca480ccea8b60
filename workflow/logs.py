"""Logging set-up for workflow scripts: everything to the rule's log file."""

import logging
import sys

__all__ = ["log_to"]


def log_to(path: str) -> None:
    """Send INFO and above of every logger to ``path``, capture warnings, and log an
    uncaught exception there too (it still reaches stderr and fails the job)."""
    logging.basicConfig(filename=path, filemode="w", level=logging.INFO, force=True,
                        format="%(levelname)s %(name)s: %(message)s")
    logging.captureWarnings(True)

    def excepthook(kind, value, tb):
        logging.getLogger("alfa_bench").critical("stopped: %s", value, exc_info=(kind, value, tb))
        sys.__excepthook__(kind, value, tb)

    sys.excepthook = excepthook
