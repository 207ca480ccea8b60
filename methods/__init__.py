"""Detectors: the streaming contract, the batch runner and the registry.

A new method is one module defining a :class:`Detector` subclass plus one line in
:data:`REGISTRY`; the contract test then checks it automatically.
"""

import inspect

from .base import (
    Detector,
    NotFittedError,
    Trace,
    fault_free_segments,
    run_detector,
    skipped_channels,
)
from .emulation_oracle import EmulationOracle
from .end_of_flight import EndOfFlight
from .ffrls_monitor import FfRlsMonitor
from .glrt_residuals import GlrtResiduals
from .kalman_okid import KalmanOkid
from .learned_fusion import LearnedFusion
from .residual_bank import ResidualBank
from .rls_arx_zscore import RlsArxZscore

__all__ = ["REGISTRY", "Detector", "NotFittedError", "Trace", "fault_free_segments",
           "make_detector", "run_detector", "skipped_channels"]

REGISTRY: dict[str, type[Detector]] = {
    "rls_arx_zscore": RlsArxZscore,
    "glrt_residuals": GlrtResiduals,
    "ffrls_monitor": FfRlsMonitor,
    "kalman_okid": KalmanOkid,
    "residual_bank": ResidualBank,
    "learned_fusion": LearnedFusion,
    "emulation_oracle": EmulationOracle,
    "end_of_flight": EndOfFlight,
}


def make_detector(name: str, params: dict | None = None) -> Detector:
    """Build the registered detector ``name`` with ``params``."""
    try:
        cls = REGISTRY[name]
    except KeyError:
        raise KeyError(f"unknown detector {name!r}; registered: {sorted(REGISTRY)}") from None
    params = dict(params or {})
    signature = inspect.signature(cls.__init__).parameters
    for key, value in params.items():
        if key not in signature or key == "self":
            raise TypeError(f"detector {name!r} has no parameter {key!r}; it has "
                            f"{[p for p in signature if p != 'self']}")
        default = signature[key].default
        numeric = isinstance(default, int | float) and not isinstance(default, bool)
        if numeric and not (isinstance(value, int | float) and not isinstance(value, bool)):
            raise TypeError(f"detector {name!r}: parameter {key!r} must be a number, got "
                            f"{value!r} ({type(value).__name__}); in YAML write 1.0e+6, "
                            "not 1.0e6")
    return cls(**params)
