"""Detectors: the streaming contract, the batch runner and the registry.

A new method is one module defining a :class:`Detector` subclass plus one line in
:data:`BUILTIN_ENTRIES` (name = ``"module:Class"``); the contract test then checks it
automatically. A detector kept in a package of its own registers through the
entry-point group :data:`PLUGIN_GROUP` (``[project.entry-points."alfa_bench.methods"]``
in its ``pyproject.toml``, name = ``"module:Class"``); once installed it is in
:data:`REGISTRY` beside the built-in ones, a config run can name it, and the contract
test covers it (``examples/alfa-cusum``).
"""

import importlib
from importlib.metadata import entry_points

from .base import (
    DEFAULT_RATE_HZ,
    FAMILIES,
    CalibrationError,
    Detector,
    Fork,
    Labelled,
    NotFittedError,
    PairDetector,
    StaleStateError,
    Trace,
    clone,
    continue_forks,
    fault_free_segments,
    fit_token,
    fork_for,
    forks,
    init_parameters,
    labelled_segments,
    run_detector,
    source_digest,
    training_segments,
)
from .extremes import MaximaThresholds
from .unmoved import UnmovedSensors, skipped_channels

__all__ = ["BUILTIN", "BUILTIN_ENTRIES", "DEFAULT_RATE_HZ", "FAMILIES", "PLUGIN_GROUP", "REGISTRY",
           "CalibrationError", "Detector", "Fork", "Labelled", "MaximaThresholds",
           "NotFittedError", "PairDetector", "StaleStateError", "Trace", "UnmovedSensors",
           "clone", "continue_forks", "detector_module", "detector_name", "fault_free_segments",
           "fit_token", "fork_for",
           "forks", "labelled_segments", "make_detector", "plugins", "run_detector",
           "skipped_channels", "source_digest", "training_segments"]

#: the entry-point group third-party detectors register under
PLUGIN_GROUP = "alfa_bench.methods"

#: the detectors that ship with alfa-bench, each as an entry point's ``"module:Class"``.
#: They are imported when BUILTIN or REGISTRY is first read: the detector modules import
#: numba and scipy, which a job that only reads traces (Trace) has no use for.
BUILTIN_ENTRIES = {
    "rls_arx_zscore": "rls_arx_zscore:RlsArxZscore",
    "glrt_residuals": "glrt_residuals:GlrtResiduals",
    "ffrls_monitor": "ffrls_monitor:FfRlsMonitor",
    "kalman_okid": "kalman_okid:KalmanOkid",
    "residual_bank": "residual_bank:ResidualBank",
    "learned_fusion": "learned_fusion:LearnedFusion",
    "residual_logistic": "residual_logistic:ResidualLogistic",
    "residual_logistic_published": "residual_logistic:ResidualLogisticPublished",
    "bench_logistic": "bench_logistic:BenchLogistic",
    "nested_selection": "nested_selection:NestedSelection",
    "coincidence": "coincidence:Coincidence",
    "emulation_oracle": "emulation_oracle:EmulationOracle",
    "end_of_flight": "end_of_flight:EndOfFlight",
    "silent": "silent:Silent",
    "pyod": "outliers:PyODDetector",
    "river": "outliers:RiverDetector",
}


def plugins() -> dict[str, type[Detector]]:
    """The detectors installed packages register under :data:`PLUGIN_GROUP`. A name
    that shadows a built-in detector, or an entry that is not a :class:`Detector`
    subclass, is an error naming the package's entry."""
    found = {}
    for ep in entry_points(group=PLUGIN_GROUP):
        where = f"entry point {ep.name} = {ep.value!r} (group {PLUGIN_GROUP})"
        if ep.name in BUILTIN_ENTRIES:
            raise ImportError(f"{where} would shadow the built-in detector {ep.name!r}")
        cls = ep.load()
        if not (isinstance(cls, type) and issubclass(cls, Detector)):
            raise TypeError(f"{where} is not a Detector subclass")
        found[ep.name] = cls
    return found


def _builtin_class(name: str) -> type[Detector]:
    module, cls = BUILTIN_ENTRIES[name].split(":")
    return getattr(importlib.import_module(f".{module}", __name__), cls)


def _builtin() -> dict[str, type[Detector]]:
    return {name: _builtin_class(name) for name in BUILTIN_ENTRIES}


def __getattr__(name: str):
    """``BUILTIN``: the detectors that ship with alfa-bench; ``REGISTRY``: every detector
    a config run can name, the built-in ones and the installed plugins. Each is built
    once, on first use."""
    if name in globals():
        return globals()[name]
    if name == "BUILTIN":
        globals()["BUILTIN"] = _builtin()
    elif name == "REGISTRY":
        globals()["REGISTRY"] = {**__getattr__("BUILTIN"), **plugins()}
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return globals()[name]


def detector_module(name: str) -> str | None:
    """The module that defines the registered detector ``name``, found without
    importing it (None: no detector has that name). A cluster job parses the workflow,
    which names every run's code, to run one detector."""
    if name in BUILTIN_ENTRIES:
        return f"{__name__}.{BUILTIN_ENTRIES[name].split(':')[0]}"
    return next((ep.module for ep in entry_points(group=PLUGIN_GROUP, name=name)), None)


def detector_name(detector: Detector) -> str:
    """The name a record gives ``detector``'s class: its registry name, else
    ``"module:Class"`` (a detector written in a script or notebook)."""
    cls = type(detector)
    found = [n for n, c in __getattr__("REGISTRY").items() if c is cls]
    return found[0] if found else f"{cls.__module__}:{cls.__qualname__}"


def make_detector(name: str, params: dict | None = None) -> Detector:
    """Build the registered detector ``name`` with ``params``. A built-in one imports
    its own module only: every job builds one, and the detector modules import numba,
    scipy and scikit-learn."""
    if name in BUILTIN_ENTRIES:
        cls = _builtin_class(name)
    else:
        registry = __getattr__("REGISTRY")
        try:
            cls = registry[name]
        except KeyError:
            raise KeyError(f"unknown detector {name!r}; registered: "
                           f"{sorted(registry)}") from None
    params = dict(params or {})
    signature = init_parameters(cls)
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
