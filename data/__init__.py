"""ALFA data layer: flights, signals, manifest, download."""

from .download import fetch_alfa, processed_dir, resolve_alfa_dir
from .errors import AlfaDataError, MissingTopicError
from .flight import FAULT_CLASSES, Fault, Flight, Topic, find_flights, load_flight
from .manifest import SUBSETS, build_manifest, read_manifest, subset_flights
from .signals import SIGNALS, Sampled, Signal, sample, series

__all__ = [
    "FAULT_CLASSES", "SIGNALS", "SUBSETS", "AlfaDataError", "Fault", "Flight",
    "MissingTopicError", "Sampled", "Signal", "Topic", "build_manifest", "fetch_alfa",
    "find_flights", "load_flight", "processed_dir", "read_manifest", "resolve_alfa_dir",
    "sample", "series", "subset_flights",
]
