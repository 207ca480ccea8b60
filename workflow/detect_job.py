"""A detect job: one configured run over every flight with ground truth and, for a run
scored on it, over the injected sensor-fault grid, built in memory from the cached
fault-free flights; each fold is fitted once, on real flights only. Writes the
detection records, traces, the run's panel of each flight's figure, the flights it
had to exclude, and the job's own time and costs (``results/benchmarks/detect/<run>.tsv``:
Snakemake's benchmark columns, then :data:`~.job_costs.COLUMNS`).

With ``--fits <folder>`` (the workflow gives ``results/fits``) the fits the detectors
keep (:mod:`alfa_bench.methods.fits`) are read from and written to that folder too,
bounded by the config's ``fits: max_mb``, so that the jobs of a run, later runs and
re-runs share them.

The rule's command is this module::

    python -m alfa_bench.workflow.detect_job <run> --manifest <manifest> --log <log> ...

It hands its arguments to the workflow's fork server (:mod:`.forkserver`) when one
answers, so that the imports and the flights are paid once per workflow run, not once
per job; else it runs the job in its own process. Either way :func:`run` does the
work, and writes the same files.

This module imports only the standard library at the top: the client of a job that
the server runs pays for nothing else.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import logging
import os
import resource
import sys
import time
from pathlib import Path

__all__ = ["BENCHMARK_COLUMNS", "CONFIG_ENV", "SERVER_ENV", "code_changed", "forked", "main",
           "parse", "prepare", "preload", "run", "server_jobs", "write_job_config"]

_START = time.perf_counter()
#: the environment variable naming the fork server's socket, set by the workflow
SERVER_ENV = "ALFA_BENCH_DETECT_SERVER"
#: the environment variable naming the workflow's config file (:func:`write_job_config`)
CONFIG_ENV = "ALFA_BENCH_JOB_CONFIG"
#: a job's time, as Snakemake's ``benchmark:`` files name the columns
BENCHMARK_COLUMNS = ("s", "h:m:s", "max_rss", "cpu_time")
#: what the server has loaded, by the files it came from: the flights every job shares
_LOADED: dict[tuple, tuple] = {}
#: the source files of the project's modules the server imported, and their times
_SOURCES: dict[str, int] = {}


def write_job_config(config: dict, folder: str | Path = ".snakemake/alfa-bench") -> Path:
    """Write the workflow's ``config`` (after its overrides, as every result's
    provenance records it) where this process's detect jobs read it, and name the file
    in :data:`CONFIG_ENV`, which they inherit. The file is named for its content, so
    that two runs of other configs (a dry run beside a run) never read each other's;
    the jobs' command does not hold the name, so a config changed elsewhere re-runs no
    job that does not read the change."""
    text = json.dumps(config, sort_keys=True, allow_nan=False)
    path = Path(folder) / f"config-{hashlib.sha256(text.encode()).hexdigest()[:16]}.json"
    if not path.is_file():
        path.parent.mkdir(parents=True, exist_ok=True)
        # each process that parses the workflow writes it: whole, or not at all
        part = path.with_suffix(f".{os.getpid()}.part")
        part.write_text(text)
        part.replace(path)
    os.environ[CONFIG_ENV] = str(path.resolve())
    return path


def parse(argv: list[str]) -> argparse.Namespace:
    """The job's arguments (the rule's command line)."""
    p = argparse.ArgumentParser(prog="python -m alfa_bench.workflow.detect_job")
    p.add_argument("method")
    p.add_argument("--config", default=os.environ.get(CONFIG_ENV),
                   help=f"the workflow's config, as JSON (default: ${CONFIG_ENV})")
    p.add_argument("--manifest", required=True)
    p.add_argument("--cache", required=True)
    p.add_argument("--detections", required=True)
    p.add_argument("--traces", required=True)
    p.add_argument("--panels", required=True)
    p.add_argument("--benchmark", required=True)
    p.add_argument("--log", required=True)
    p.add_argument("--injected", help="the injected grid's manifest")
    p.add_argument("--injected-out", help="where the injected records go")
    p.add_argument("--processed", help="the injected flights' folder name")
    p.add_argument("--fits", help="the folder of fits the jobs share (the config's "
                   "fits: max_mb bounds it); none: fits are kept in the job only")
    args = p.parse_args(argv)
    if args.config is None:
        p.error(f"the workflow's config: give --config, or set {CONFIG_ENV}")
    return args


def preload(config: dict) -> None:
    """Import what the detect jobs of ``config`` run on: the data layer, the records,
    each configured run's detector module and library model (PyOD's, river's), warmed
    (:meth:`~alfa_bench.methods.base.Detector.warm`), and the figure panels. The fork
    server calls it once; its jobs start from here."""
    from alfa_bench.data.inject import InjectedGrid  # noqa: F401
    from alfa_bench.methods import make_detector
    from alfa_bench.outputs.flight_figures import FlightPanel
    from alfa_bench.outputs.records import write_detections  # noqa: F401

    for spec in config["methods"].values():
        detector = make_detector(spec["detector"], spec.get("params"))
        detector.check_params()
        detector.warm()
    FlightPanel("")                 # matplotlib's fonts and text metrics, loaded
    from .forkserver import imported_sources

    _SOURCES.update(imported_sources())


def code_changed() -> bool:
    """Whether a module of the project imported by :func:`preload` changed since: a
    job forked now would run the old code, and its outputs, newer than the change,
    would never be re-run."""
    from .forkserver import changed_since

    return changed_since(_SOURCES)


def prepare(args: argparse.Namespace) -> tuple:
    """The manifest, the cached flights and, for a run scored on it, the injected grid
    (and its manifest) of ``args``: read once per process, and checked against each
    other. The server prepares before it forks, so that its jobs share them."""
    key = (args.manifest, args.cache, args.injected, args.processed, args.config,
           *(os.stat(p).st_mtime_ns for p in (args.manifest, args.injected) if p))
    if key in _LOADED:
        return _LOADED[key]
    from collections import ChainMap

    from alfa_bench.data import AlfaDataError, load_cached, read_manifest
    from alfa_bench.data.inject import InjectedGrid

    config = json.loads(Path(args.config).read_text())
    manifest = read_manifest(args.manifest)
    flights = load_cached(args.cache, manifest)
    on_grid = None
    if args.injected:
        grid, on_grid = config["injection"], read_manifest(args.injected)
        free = manifest.loc[manifest["fault_class"] == "none", "flight"]
        built = InjectedGrid({name: flights[name] for name in free}, manifest, args.processed,
                             grid["sensors"], grid["faults"], grid["onsets"])
        if built.sha256 != dict(zip(on_grid["flight"], on_grid["sha256"], strict=True)):
            raise AlfaDataError(f"{args.injected} is not the grid the config and the cached "
                                "flights give: re-run the inject rule")
        flights = ChainMap(flights, built)       # each injected flight built when scored
    _LOADED.clear()                              # one workflow's flights at a time
    _LOADED[key] = config, manifest, flights, on_grid
    return _LOADED[key]


def run(args: argparse.Namespace, started: float = _START) -> None:
    """The job: score ``args.method`` and write its files, then its time since
    ``started`` (:func:`time.perf_counter`; by default, this module's import)."""
    from alfa_bench.methods import fits, make_detector
    from alfa_bench.outputs.records import write_detections
    from alfa_bench.workflow.dependencies import module_sources
    from alfa_bench.workflow.job_costs import measured
    from alfa_bench.workflow.logs import log_to

    log_to(args.log)
    reading = time.perf_counter()
    config, manifest, flights, on_grid = prepare(args)
    reading = time.perf_counter() - reading
    injected = None if on_grid is None else (on_grid, Path(args.injected_out))
    spec = config["methods"][args.method]
    fits.use_files(args.fits and Path(args.fits), int(config["fits"]["max_mb"] * 1e6),
                   module_sources)
    # the run's detector and those it builds, imported before their timers are set
    detector = make_detector(spec["detector"], spec.get("params"))
    detector.check_params()
    with measured(type(detector)) as costs:
        write_detections(args.method, spec, flights, manifest, dict(config["calibration"]),
                         strict=config["strict"], config=config, out=Path(args.detections),
                         traces=Path(args.traces), panels=Path(args.panels),
                         injected=injected)
    costs["reading_s"] += reading
    if args.fits:
        logging.getLogger(__name__).info(
            "fits: %d made, %d kept, %d read from %s, %d refused there, %d kept in the job "
            "only (not arrays and JSON)", costs["fits_made"], costs["fits_kept"],
            costs["fits_read"], args.fits, fits.COUNTS["refused"], fits.COUNTS["unstorable"])
    _write_benchmark(Path(args.benchmark), time.perf_counter() - started, costs)


def server_jobs(config_file: str) -> tuple:
    """The fork server's three steps (:func:`.forkserver.serve`) for the detect jobs of
    the workflow config at ``config_file`` (:func:`write_job_config`): preload what they
    run on, prepare the flights a job reads (unless a module changed since the preload:
    the job then runs on its own), and run the job in the fork."""
    def preload_config():
        preload(json.loads(Path(config_file).read_text()))

    def prepare_job(argv):
        if code_changed():
            print("a module changed since the server loaded it: jobs run on their own",
                  file=sys.stderr)
            return False
        prepare(parse(argv))
        return True

    return preload_config, prepare_job, forked


def forked(argv: list[str]) -> None:
    """The job of ``argv`` in a child of the fork server, timed from the fork."""
    run(parse(argv), time.perf_counter())


def _write_benchmark(path: Path, wall_s: float, costs: dict) -> None:
    """The job's wall time from its start (its fork from the server, or its process's
    start when run alone), its CPU time and peak resident memory, MB, in Snakemake's
    benchmark columns; then its ``costs`` (:data:`~.job_costs.COLUMNS`)."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    cpu_s = usage.ru_utime + usage.ru_stime
    hms = time.strftime("%H:%M:%S", time.gmtime(wall_s))
    names = list(costs)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\t".join([*BENCHMARK_COLUMNS, *names]) + "\n"
                    f"{wall_s:.4f}\t{hms}\t{usage.ru_maxrss / 1024:.2f}\t{cpu_s:.4f}\t"
                    + "\t".join(f"{costs[n]:.4f}" if isinstance(costs[n], float)
                                else str(costs[n]) for n in names) + "\n")


def main(argv: list[str] | None = None) -> int:
    """Run the job on the fork server when one answers, else here; its exit status."""
    argv = sys.argv[1:] if argv is None else argv
    if "--config" not in argv and os.environ.get(CONFIG_ENV):
        argv = [*argv, "--config", os.environ[CONFIG_ENV]]    # this workflow's, to the server
    from .forkserver import run_job

    return run_job(SERVER_ENV, "detect", argv, parse, run)


if __name__ == "__main__":
    sys.exit(main())
