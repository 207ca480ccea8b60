"""ALFA data layer: flights, signals, manifest, download."""

from .cache import load_cached, read_cached
from .download import fetch_alfa, processed_dir, resolve_alfa_dir
from .errors import (
    FAILURE_COLUMNS,
    AlfaDataError,
    DownloadError,
    MissingFolderError,
    MissingTopicError,
    StaleCacheError,
    UnknownSignalError,
    failure_row,
)
from .flight import (
    FAULT_CLASSES,
    Fault,
    Flight,
    Topic,
    find_flights,
    load_flight,
    parse_flight_name,
)
from .manifest import (
    SUBSETS,
    build_manifest,
    in_subset,
    name_subsets,
    read_manifest,
    scan_flights,
    subset_flights,
)
from .signals import (
    KINDS,
    MAX_HOLD_S,
    SIGNALS,
    Sampled,
    Signal,
    first_grid_step,
    hold,
    not_measured,
    reads_actuators,
    sample,
    series,
)

__all__ = [
    "FAILURE_COLUMNS", "FAULT_CLASSES", "KINDS", "MAX_HOLD_S", "SIGNALS", "SUBSETS",
    "AlfaDataError", "DownloadError", "Fault", "Flight", "MissingFolderError",
    "MissingTopicError", "Sampled", "Signal", "StaleCacheError", "Topic", "UnknownSignalError",
    "build_manifest", "failure_row", "fetch_alfa", "find_flights", "first_grid_step", "hold",
    "in_subset",
    "load_cached", "load_flight", "name_subsets", "not_measured", "parse_flight_name",
    "processed_dir", "read_manifest", "reads_actuators",
    "read_cached", "resolve_alfa_dir", "sample", "scan_flights", "series", "subset_flights",
]
