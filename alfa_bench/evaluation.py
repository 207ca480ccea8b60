"""Score a detector from Python, as the workflow scores its runs, in three lines::

    import alfa_bench as ab

    corpus = ab.load_corpus()                      # ALFA_DIR, the config, or the download
    result = ab.evaluate(MyDetector(), corpus)     # or the name of a config run
    ab.compare(result, published="results")        # beside the runs of `snakemake all`

:func:`load_corpus` finds the flights as the workflow does and parses each once into a
cache of the workflow's own format; :func:`evaluate` fits a calibrated detector per
fold of :func:`~.held_out.folds` on the other groups' flights only, and scores it
with the config's margins, subsets and deadline (the same code as a detect job:
:func:`~.detections.detect_all`, so the same records); :func:`compare` ranks results
beside a workflow's published runs on common ground, as ``comparison.csv`` does.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from collections import ChainMap
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
from threadpoolctl import threadpool_limits

from alfa_bench.analysis.detections import detect_all
from alfa_bench.analysis.per_flight import per_flight_table
from alfa_bench.config import load_config
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
from alfa_bench.methods import (
    Detector,
    Trace,
    detector_name,
    make_detector,
    source_digest,
)
from alfa_bench.outputs.records import read_failures, read_records
from alfa_bench.outputs.tables import comparison_table, failures_table

__all__ = ["SCORING_SETTINGS", "Corpus", "Result", "compare", "evaluate", "load_corpus",
           "user_cache"]

log = logging.getLogger(__name__)

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


def user_cache() -> Path:
    """The user's cache folder of alfa-bench (``$XDG_CACHE_HOME/alfa-bench``, by default
    ``~/.cache/alfa-bench``): parsed flights, and the download when the workflow's
    config does not say where."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "alfa-bench"


def _default_cache(processed: Path) -> Path:
    key = hashlib.blake2b(str(processed.resolve()).encode(), digest_size=8).hexdigest()
    return user_cache() / key


def load_corpus(alfa_dir: str | os.PathLike | None = None, *, config: dict | None = None,
                cache: str | os.PathLike | None = None) -> Corpus:
    """The flights of ``alfa_dir`` (default: found as the workflow finds them:
    ``ALFA_DIR``, else the config's ``alfa_dir``, else the official archive, downloaded
    and verified into the user's cache, :func:`user_cache`, never the working folder),
    parsed once into ``cache`` (default: a folder per ALFA copy under the user's
    cache). A later call parses again only if a flight's files changed (their SHA-256
    is the manifest's key). ``config`` is a config dict (default: the one the package
    ships, :func:`~alfa_bench.config.load_config`). A corpus of logs the workflow
    converted (``alfa_dir="results/corpus"``, docs/own-flights.md) is checked on the
    signals it has."""
    config = load_config() if config is None else config
    if alfa_dir is not None:
        found, source = Path(alfa_dir), f"load_corpus(alfa_dir={str(alfa_dir)!r})"
    else:
        found = resolve_alfa_dir(config.get("alfa_dir"))
        source = "ALFA_DIR" if os.environ.get("ALFA_DIR") else "the config's alfa_dir"
    if found is None:
        d = config["download"]
        found = fetch_alfa(d["api"], d["file"], user_cache() / "alfa", d.get("md5"),
                           d.get("sha256"))
        source = "the download"
    processed = processed_dir(found, source)
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
    # a corpus of logs converted by the workflow (results/corpus): its own signals
    signals = None
    if (processed.parent / "signals.csv").is_file():
        from alfa_bench.logs.corpus import read_signals

        signals = [s for s, why in read_signals(processed.parent).items() if why is None]
    manifest, failures = scan_flights(processed, cache=cache, signals=signals)
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
        from alfa_bench.analysis.provenance import run_provenance
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
        causality on one synthetic flight: :func:`~alfa_bench.methods.contract.quick_check`,
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
            from alfa_bench.methods.contract import quick_check  # the synthetic corpus

            quick_check(detector)
        spec = {"detector": detector_name(detector), "params": detector.get_params()}
        if ":" in spec["detector"]:        # not registered: "module:Class"
            spec["source"] = source_digest(type(detector))
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


#: the config settings every result and the published runs must share to be compared
SCORING_SETTINGS = ("scoring.deadline_s", "subsets", "primary_subset", "calibration.group_by",
                    "calibration.margin_s", "stability.pools", "stability.seed",
                    "stability.stable", "stability.interval")


def _setting(config: dict, name: str):
    """The value of the dotted setting ``name`` in ``config`` (None where it is unset)."""
    for key in name.split("."):
        config = (config or {}).get(key)
    return config


def compare(*results: Result, published: str | os.PathLike | None = None) -> pd.DataFrame:
    """The comparison table (``comparison.csv``'s columns) of ``results``, ranked beside
    the runs of a workflow's results folder ``published`` (the ``results/`` of a
    ``snakemake all``, or the checkout holding it), or among themselves with
    ``published`` None. Only the runs of the published run's config are read: a result
    folder left by a run since taken out of it is not ranked.

    Only like is compared with like: every result must be scored with the published
    run's settings (:data:`SCORING_SETTINGS`: deadline, subsets, grouping, margin,
    pools and stable share), on its corpus (the same flights, the same files), by the
    same alfa-bench version; otherwise a :class:`ValueError` names the setting that
    differs. Every run is scored on the flights every ranked (honest) run scored
    (:func:`~alfa_bench.outputs.tables.common_ground`); one that failed on flights the
    others scored is flagged (``failed_flights``). A run not causal, reading actuators or
    calibrated by anything but the date is not ranked, as in the workflow's tables
    (:func:`~alfa_bench.analysis.blocks.block`).

    Raises
    ------
    FileNotFoundError
        Where ``published`` holds no workflow results, saying what to run.
    ValueError
        Where a result was scored otherwise than the published runs, or two results
        share a name, or there is nothing to compare."""
    if not results:
        raise ValueError("compare needs at least one Result")
    names = [res.method for res in results]
    if len(set(names)) != len(names):
        raise ValueError(f"two results share a name: {names}; evaluate(..., name=...) "
                         "another name")
    if published is None and len(results) < 2:
        raise ValueError("compare(result) alone has nothing to rank it beside: pass "
                         "published= the results/ folder of a `snakemake all` run (the "
                         "README's main job), or two or more results")
    first = results[0]
    for res in results[1:]:
        _check_like(first.corpus.config, first.deadline_s, first.subsets,
                    first.corpus.manifest, res, f"result {first.method!r}", res.method)
    manifest = first.corpus.manifest
    records = [r for res in results for r in res.records]
    failures = [res.failures for res in results]
    if published is not None:
        out = _published(published)
        manifest = read_manifest(out / "flights.csv")
        run = json.loads((out / "provenance.json").read_text())["run"]
        for res in results:
            _check_like(run["config"], float(run["config"]["scoring"]["deadline_s"]),
                        _subsets(run["config"]), manifest, res, str(out), res.method,
                        run["code"]["version"])
        # the runs of the published config: a folder left by a run taken out since is stale
        folders = [out / "detections" / m for m in run["config"]["methods"]
                   if (out / "detections" / m).is_dir()]
        clash = sorted({p.name for p in folders} & set(names))
        if clash:
            raise ValueError(f"{clash} already named in {out}: evaluate(..., name=...) "
                             "another name")
        records += read_records(folders)
        failures += [failures_table(pd.read_csv(out / "load_failures.csv", dtype=str,
                                                keep_default_na=False),
                                    read_failures(folders))]
    return comparison_table(records, manifest, first.subsets, first.deadline_s,
                            pd.concat(failures, ignore_index=True).drop_duplicates(),
                            *_stable(first.corpus.config))


def _published(published: str | os.PathLike) -> Path:
    """The results folder ``published`` (or the ``results/`` of the checkout it names),
    checked to hold a workflow's results."""
    out = Path(published)
    if not (out / "flights.csv").exists() and (out / "results/flights.csv").exists():
        out = out / "results"
    missing = [n for n in ("flights.csv", "load_failures.csv", "provenance.json",
                           "detections") if not (out / n).exists()]
    if missing:
        raise FileNotFoundError(
            f"compare(published={str(published)!r}): {out.resolve()} holds no results of a "
            f"workflow run (no {', '.join(missing)}). What to do: run `snakemake all "
            "--cores 2` in a checkout (the README's main job) and pass its results/ "
            "folder, or published=None to rank two or more results among themselves")
    return out


def _check_like(config: dict, deadline_s: float, subsets: list[str], manifest: pd.DataFrame,
                res: Result, where: str, name: str, version: str | None = None) -> None:
    """``res`` (named ``name``) scored as ``config``, ``deadline_s`` and ``subsets`` say,
    on the flights of ``manifest`` (``where`` named them), by alfa-bench ``version``;
    else the ValueError that names what differs."""
    mine = res.corpus.config
    differs = [(k, _setting(mine, k), _setting(config, k)) for k in SCORING_SETTINGS
               if _setting(mine, k) != _setting(config, k)]
    if res.deadline_s != deadline_s:
        differs.append(("deadline_s", res.deadline_s, deadline_s))
    if list(res.subsets) != list(subsets):
        differs.append(("subsets", list(res.subsets), list(subsets)))
    if differs:
        key, a, b = differs[0]
        raise ValueError(f"{name} was scored with {key} = {a!r}, {where} with {b!r}: "
                         "compare runs scored alike (evaluate(..., deadline_s=, subsets=) "
                         "or a corpus loaded with the same config)")
    _check_same_flights(manifest, [res], where)
    if version is not None:
        from alfa_bench import __version__

        if version != __version__:
            raise ValueError(f"{where} was made by alfa-bench {version}, {name} by "
                             f"{__version__}: run the workflow again with this version")


def _check_same_flights(manifest: pd.DataFrame, results, out) -> None:
    """Each result scored the flights of ``manifest`` (from ``out``), the same files
    (SHA-256) under the same names, and no other."""
    published = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
    for res in results:
        mine = dict(zip(res.corpus.manifest["flight"], res.corpus.manifest["sha256"],
                        strict=True))
        other = sorted(f for f in mine if f in published and mine[f] != published[f])
        if other:
            raise ValueError(f"{res.method} scored other files than {out} under the same "
                             f"flight names, e.g. {other[0]}: compare runs of one ALFA copy")
        apart = sorted(set(mine) ^ set(published))
        if apart:
            raise ValueError(f"{res.method} and {out} scored other corpora ({len(mine)} and "
                             f"{len(published)} flights; {apart[0]} is in one only): "
                             "compare runs of one ALFA copy")
