"""What a test does when a program, module or data it needs is not on the machine: it
skips, saying why, except in CI (``CI`` set, as ``.ci/run`` runs), where it fails, so
that CI cannot go green with its own checks skipped."""

from __future__ import annotations

import importlib
import os

import pytest

__all__ = ["in_ci", "require_module", "unavailable"]


def in_ci() -> bool:
    return os.environ.get("CI", "").lower() not in ("", "0", "false")


def unavailable(reason: str, module_level: bool = False):
    """Skip on ``reason`` locally; fail on it in CI."""
    if in_ci():
        pytest.fail(f"CI must run this test: {reason}", pytrace=False)
    pytest.skip(reason, allow_module_level=module_level)


def require_module(name: str, reason: str | None = None, module_level: bool = False):
    """Module ``name``, imported; :func:`unavailable` if it is not installed."""
    try:
        return importlib.import_module(name)
    except ImportError:
        unavailable(reason or f"{name} is not installed", module_level)
