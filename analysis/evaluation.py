"""Score a detector from Python, as the workflow scores its runs, in three lines::

    import alfa_bench as ab

    corpus = ab.load_corpus()                      # ALFA_DIR, the config, or the download
    result = ab.evaluate(MyDetector(), corpus)     # or the name of a config run
    ab.compare(result)                             # ranked beside results/ of the workflow

:func:`load_corpus` finds the flights as the workflow does and parses each once into a
cache of the workflow's own format; :func:`evaluate` fits a calibrated detector per
fold of :func:`~.held_out.folds` on the other groups' flights only, and scores it
with the config's margins, subsets and deadline (the same code as a detect job:
:func:`~.detections.detect_all`, so the same records); :func:`compare` ranks results
beside a workflow's published runs on common ground, as ``comparison.csv`` does.
"""

from __future__ import annotations

import hashlib
import logging
import os
from collections import ChainMap
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
import yaml
from threadpoolctl import threadpool_limits

from alfa_bench.data import (
    FAILURE_COLUMNS,
    Flight,
    fetch_alfa,
    processed_dir,
    read_cached,
    read_manifest,
    resolve_alfa_dir,
    scan_flights,
)
from alfa_bench.data.cache import cache_path
from alfa_bench.data.flight import entries
from alfa_bench.data.manifest import flight_sha256
from alfa_bench.methods import Detector, Trace, detector_name, make_detector
from alfa_bench.outputs.tables import comparison_table, failures_table

from .detections import detect_all, read_failures, read_records
from .per_flight import per_flight_table

__all__ = ["Corpus", "Result", "compare", "evaluate", "load_config", "load_corpus"]

log = logging.getLogger(__name__)

#: the workflow's config, beside the sources of this checkout
_REPO_CONFIG = Path(__file__).resolve().parent.parent / "config" / "config.yaml"


def load_config(path: str | os.PathLike | None = None) -> dict:
    """The workflow config at ``path`` (default: ``config/config.yaml`` of the working
    directory, else of this checkout), checked against its schema."""
    import jsonschema

    if path is None:
        here = Path("config/config.yaml")
        path = here if here.is_file() else _REPO_CONFIG
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no workflow config at {path}: pass config= the path of "
                                "a config.yaml (the repository's config/config.yaml)")
    config = yaml.safe_load(path.read_text())
    schema = yaml.safe_load((path.parent / "schema.yaml").read_text())
    jsonschema.validate(config, schema)
    return config


@dataclass(frozen=True)
class Corpus:
    """The flights a run scores: the manifest of those that load, the load failures,
    and each flight parsed once (read from :attr:`cache` when first asked for).

    Attributes
    ----------
    processed : Path
        ALFA's ``processed/`` folder.
    manifest : DataFrame
        As ``results/flights.csv``.
    failures : DataFrame
        As ``results/load_failures.csv``.
    config : dict
        The workflow config the runs are scored by.
    cache : Path
        The parsed flights, one ``<flight>.npz`` each (:mod:`alfa_bench.data.cache`).
    """

    processed: Path
    manifest: pd.DataFrame
    failures: pd.DataFrame
    config: dict
    cache: Path
    _flights: dict = field(default_factory=dict, repr=False, compare=False)

    def flight(self, name: str) -> Flight:
        """Flight ``name``, parsed once."""
        if name not in self._flights:
            sha = self.manifest.set_index("flight").at[name, "sha256"]
            self._flights[name] = read_cached(cache_path(self.cache, name), sha)
        return self._flights[name]

    @property
    def flights(self) -> Mapping[str, Flight]:
        """Every flight with ground truth, by name, read when first used."""
        return _Lazy(self, self.manifest.loc[self.manifest["ground_truth"], "flight"].tolist())


class _Lazy(Mapping):
    def __init__(self, corpus: Corpus, names: list[str]):
        self.corpus, self.names = corpus, names

    def __getitem__(self, name: str) -> Flight:
        if name not in self.names:
            raise KeyError(name)
        return self.corpus.flight(name)

    def __iter__(self):
        return iter(self.names)

    def __len__(self) -> int:
        return len(self.names)


def _default_cache(processed: Path) -> Path:
    key = hashlib.blake2b(str(processed.resolve()).encode(), digest_size=8).hexdigest()
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return root / "alfa-bench" / key


def load_corpus(alfa_dir: str | os.PathLike | None = None, *, config: dict | None = None,
                cache: str | os.PathLike | None = None) -> Corpus:
    """The flights of ``alfa_dir`` (default: found as the workflow finds them:
    ``ALFA_DIR``, else the config's ``alfa_dir``, else the official archive, downloaded
    and verified), parsed once into ``cache`` (default: a folder per ALFA copy under
    ``~/.cache/alfa-bench``). A later call parses again only if a flight's files changed
    (their SHA-256 is the manifest's key)."""
    config = load_config() if config is None else config
    found = Path(alfa_dir) if alfa_dir is not None else resolve_alfa_dir(config.get("alfa_dir"))
    if found is None:
        d = config["download"]
        found = fetch_alfa(d["api"], d["file"], d["dest"], d.get("md5"), d.get("sha256"))
    processed = processed_dir(found)
    cache = Path(cache) if cache is not None else _default_cache(processed)
    manifest_csv, failures_csv = cache / "flights.csv", cache / "load_failures.csv"
    if manifest_csv.is_file() and failures_csv.is_file():
        manifest = read_manifest(manifest_csv)
        failures = pd.read_csv(failures_csv, dtype=str, keep_default_na=False)
        known = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
        now = {p.name: flight_sha256(p) if p.is_dir() else "" for p in entries(processed)}
        if ({n: now.get(n) for n in known} == known
                and set(now) == set(known) | set(failures["flight"])):
            return Corpus(processed, manifest, failures, config, cache)
        log.info("%s changed since it was cached: parsing it again", processed)
    manifest, failures = scan_flights(processed, cache=cache)
    manifest.to_csv(manifest_csv, index=False)
    failures.to_csv(failures_csv, index=False)
    # read back, as every workflow job reads results/flights.csv
    return Corpus(processed, read_manifest(manifest_csv),
                  pd.read_csv(failures_csv, dtype=str, keep_default_na=False), config, cache)


@dataclass
class Result:
    """One method scored over a corpus by :func:`evaluate`.

    Attributes
    ----------
    method : str
        The run's name in every table.
    records : list of dict
        One detection record per scored flight, as the workflow writes them.
    traces : dict of str to Trace
        Per flight, the scores, alarms and intermediates.
    per_flight : DataFrame
        The columns of ``per_flight.csv``.
    summary : DataFrame
        The columns of ``comparison.csv``, a row per subset.
    failures : DataFrame
        The flights not scored, and why.
    injected : list of dict
        The records of the injected sensor-fault grid, if asked for.
    fitted : dict of str to Detector
        Per fold, the clone of the detector fitted for it (one under ``""`` for an
        uncalibrated detector): the caller's detector is never fitted.
    """

    method: str
    records: list[dict]
    traces: dict[str, Trace]
    per_flight: pd.DataFrame
    summary: pd.DataFrame
    failures: pd.DataFrame
    injected: list[dict]
    corpus: Corpus = field(repr=False)
    detector: Detector = field(repr=False)
    subsets: list[str] = field(repr=False)
    deadline_s: float = field(repr=False)
    fitted: dict[str, Detector] = field(default_factory=dict, repr=False)

    def recording(self, flight: str, path: str | os.PathLike) -> Path:
        """Write the rerun recording of ``flight`` with this method's scores and
        intermediates (open it with ``rerun <path>``); return its path."""
        from alfa_bench.outputs.provenance import run_provenance
        from alfa_bench.outputs.rerun_log import (
            write_rerun_log,  # rerun: only where a recording is written
        )

        write_rerun_log(self.corpus.flight(flight), {self.method: self.traces[flight]},
                        list(self.detector.signals()), Path(path),
                        run_provenance(self.corpus.config, self.corpus.manifest))
        return Path(path)


def _stable(config: dict) -> tuple[float, float]:
    """The config's survival for a stable detection, and its pool interval."""
    return config["stability"]["stable"], config["stability"]["interval"]


def _subsets(config: dict) -> list[str]:
    primary = config["primary_subset"]
    return [primary, *(s for s in config["subsets"] if s != primary)]


def evaluate(detector: Detector | str, corpus: Corpus, *, name: str | None = None,
             subsets: list[str] | None = None, deadline_s: float | None = None,
             injected: bool = False, check: bool = True) -> Result:
    """Score ``detector`` on every labelled flight of ``corpus``, as the workflow does.

    Parameters
    ----------
    detector : Detector or str
        An unfitted detector, or the name of a run of the corpus's config (its
        detector and parameters).
    corpus : Corpus
        From :func:`load_corpus`.
    name : str, optional
        The run's name in the tables: by default the config run's, or the detector's
        class name in lower case.
    subsets : list of str, optional
        Default: the config's, the primary one first.
    deadline_s : float, optional
        Default: the config's ``scoring.deadline_s``.
    injected : bool
        Also score the config's injected sensor-fault grid (:attr:`Result.injected`).
    check : bool
        Run the quick contract checks on a detector instance first (shapes, thresholds,
        causality on one synthetic flight: :func:`~alfa_bench.methods.checks.quick_check`,
        about a second); a config run's detector is checked by the test suite.

    ``detector`` is never fitted itself: each fold fits a clone (:attr:`Result.fitted`).
    """
    config = corpus.config
    if isinstance(detector, str):
        if detector not in config["methods"]:
            raise KeyError(f"no run {detector!r} in the config; its runs: "
                           f"{', '.join(config['methods'])}. Pass one of them, or a "
                           "Detector instance")
        spec = config["methods"][detector]
        name = name or detector
        detector = make_detector(spec["detector"], spec.get("params"))
    else:
        if check:
            from alfa_bench.methods.checks import quick_check  # the synthetic corpus

            quick_check(detector)
        spec = {"detector": detector_name(detector), "params": detector.get_params()}
        name = name or type(detector).__name__.lower()
    subsets = list(subsets or _subsets(config))
    deadline_s = float(config["scoring"]["deadline_s"] if deadline_s is None else deadline_s)
    manifest, flights = corpus.manifest, corpus.flights
    grid = manifest.iloc[:0]
    if injected:
        flights, grid = _with_grid(corpus)
    scored = pd.concat([manifest, grid], ignore_index=True) if len(grid) else manifest
    failed: list[dict] = []
    records, traces, extra, on_grid, fitted = [], {}, [], set(grid["flight"]), {}
    # one BLAS thread, as Snakemake gives each job: a least-squares fit on two threads
    # differs from the workflow's in its last digits
    with threadpool_limits(1, user_api="blas"):
        for record, trace in detect_all(name, spec, flights, scored, config["calibration"],
                                        failed, calibrate_on=manifest, detector=detector,
                                        stability=config.get("stability"), fitted=fitted):
            if record["flight"] in on_grid:
                extra.append(record)
            else:
                records.append(record)
                traces[record["flight"]] = trace
    failures = failures_table(corpus.failures,
                              [pd.DataFrame(failed, columns=FAILURE_COLUMNS)])
    per_flight = per_flight_table(records, {(name, f): t for f, t in traces.items()},
                                  manifest, deadline_s)
    summary = comparison_table(records, manifest, subsets, deadline_s, failures,
                               *_stable(config))
    return Result(name, records, traces, per_flight, summary, failures, extra, corpus,
                  detector, subsets, deadline_s, fitted)


def _with_grid(corpus: Corpus) -> tuple[Mapping[str, Flight], pd.DataFrame]:
    """The corpus's flights and its injected grid's (built when scored), and the grid's
    manifest, as the inject rule and the detect jobs build them."""
    from alfa_bench.data.inject import InjectedGrid
    from alfa_bench.data.manifest import manifest_of, manifest_row

    manifest, spec = corpus.manifest, corpus.config["injection"]
    free = manifest.loc[manifest["fault_class"] == "none", "flight"]
    built = InjectedGrid({n: corpus.flight(n) for n in free}, manifest,
                         "results/injected/processed", spec["sensors"], spec["faults"],
                         spec["onsets"])
    grid = manifest_of([manifest_row(built[n], sha) for n, sha in built.sha256.items()])
    return ChainMap(dict(corpus.flights), built), grid


def compare(*results: Result, published: str | os.PathLike | None = "results"
            ) -> pd.DataFrame:
    """The comparison table (``comparison.csv``'s columns) of ``results`` ranked beside
    the runs of a workflow's results folder ``published`` (None: the results alone),
    on common ground: each subset's flights are the published manifest's, and a run
    that did not score one of them is not ranked. Deadline and subsets are the first
    result's."""
    if not results:
        raise ValueError("compare needs at least one Result")
    first = results[0]
    manifest = first.corpus.manifest
    records = [r for res in results for r in res.records]
    failures = [res.failures for res in results]
    names = [res.method for res in results]
    if published is not None:
        out = Path(published)
        manifest = read_manifest(out / "flights.csv")
        folders = sorted(p for p in (out / "detections").iterdir() if p.is_dir())
        clash = sorted({p.name for p in folders} & set(names))
        if clash:
            raise ValueError(f"{clash} already named in {out}: evaluate(..., name=...) "
                             "another name")
        _check_same_flights(manifest, results, out)
        records += read_records(folders)
        failures += [failures_table(pd.read_csv(out / "load_failures.csv", dtype=str,
                                                keep_default_na=False),
                                    read_failures(folders))]
    if len(set(names)) != len(names):
        raise ValueError(f"two results share a name: {names}")
    return comparison_table(records, manifest, first.subsets, first.deadline_s,
                            pd.concat(failures, ignore_index=True).drop_duplicates(),
                            *_stable(first.corpus.config))


def _check_same_flights(manifest: pd.DataFrame, results, out: Path) -> None:
    """Each flight of the published ``manifest`` that a result scored must be the same
    files (SHA-256) in both."""
    published = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
    for res in results:
        mine = dict(zip(res.corpus.manifest["flight"], res.corpus.manifest["sha256"],
                        strict=True))
        other = sorted(f for f in mine if f in published and mine[f] != published[f])
        if other:
            raise ValueError(f"{res.method} scored other files than {out} under the same "
                             f"flight names, e.g. {other[0]}: compare runs of one ALFA copy")
