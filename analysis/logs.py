"""Logging set-up for workflow scripts: everything to the rule's log file."""

import logging

__all__ = ["log_to"]


def log_to(path: str) -> None:
    """Send INFO and above of every logger to ``path``, and capture warnings."""
    logging.basicConfig(filename=path, filemode="w", level=logging.INFO, force=True,
                        format="%(levelname)s %(name)s: %(message)s")
    logging.captureWarnings(True)
