"""Stored detector traces: what the sweeps, figures and rerun logs read back.

``results/traces/{method}/{flight}.npz`` holds a run's grid times, scores, channel
thresholds and probes, and its provenance (a JSON string, ``provenance``). Alarms
are not stored: by the detector contract a channel
alarms exactly when its score exceeds its threshold. The archive is written with
fixed member dates (:func:`~alfa_bench.data.cache.write_npz`), so the same trace gives
the same bytes.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np

from alfa_bench.data.cache import write_npz
from alfa_bench.methods import Trace

__all__ = ["read_trace", "read_traces", "write_trace"]


def write_trace(trace: Trace, path: str | Path, provenance: dict) -> None:
    """Write ``trace`` and its ``provenance`` to ``path`` (an ``.npz`` that
    :func:`numpy.load` reads)."""
    names = list(trace.probes)
    arrays = {
        "t": trace.t,
        "score": trace.score,
        "threshold": trace.threshold,
        "channels": np.array(trace.channels, dtype=str),
        "probe_names": np.array(names, dtype=str),
        "probes": (np.column_stack([trace.probes[n] for n in names]) if names
                   else np.empty((trace.t.size, 0))),
        "provenance": np.array([json.dumps(provenance, sort_keys=True, allow_nan=False)]),
    }
    write_npz(path, arrays, compress=True)


def read_trace(path: str | Path, probes: bool = True) -> Trace:
    """The :class:`~alfa_bench.methods.Trace` stored at ``path``, alarms included; its
    probes (intermediates) only with ``probes``: they are most of the file, and only
    the recordings show them."""
    with np.load(path, allow_pickle=False) as z:
        score, threshold = z["score"], z["threshold"]
        with np.errstate(invalid="ignore"):
            alarm = score > threshold
        values = z["probes"] if probes else None
        return Trace(t=z["t"], score=score, alarm=alarm,
                     channels=tuple(str(c) for c in z["channels"]), threshold=threshold,
                     probes={} if values is None else
                     {str(n): values[:, i] for i, n in enumerate(z["probe_names"])})


def read_traces(folders, probes: bool = True) -> Mapping[tuple[str, str], Trace]:
    """Every trace in the given ``results/traces/{method}`` folders, by (method, flight),
    each read from its file (with its probes if ``probes``) when looked up and not kept,
    so that memory does not grow with the corpus (at 16 times ALFA's flights, reading
    them all took 4.4 GB)."""
    return _Traces({(Path(d).name, p.stem): p
                    for d in folders for p in sorted(Path(d).glob("*.npz"))}, probes)


class _Traces(Mapping[tuple[str, str], Trace]):
    def __init__(self, paths: dict[tuple[str, str], Path], probes: bool):
        self.paths, self.probes = paths, probes

    def __getitem__(self, key: tuple[str, str]) -> Trace:
        return read_trace(self.paths[key], self.probes)

    def __contains__(self, key) -> bool:         # Mapping's would read the file
        return key in self.paths

    def __iter__(self) -> Iterator[tuple[str, str]]:
        return iter(self.paths)

    def __len__(self) -> int:
        return len(self.paths)
