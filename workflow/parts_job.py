"""A run's parts job (``rules/parts.smk``): from the run's own records and traces, its
part of each flight's rerun recording (``results/rerun/<run>/<flight>.rrd``) and its
parts of the tables whose work is per run (``results/parts/<table>/<run>``: the sweep,
the per-flight rows, the records; for a run scored on the injected grid, the
detectability and both isolation matrices), which those tables' rules merge.

The rule's command is this module::

    python -m alfa_bench.workflow.parts_job <run> --manifest <manifest> --log <log> ...

A job's work is a second or less, and a process of its own would pay as much again
for its imports (pandas, rerun, the analyses): so, as the detect jobs do, it hands its
arguments to the workflow's parts server (:mod:`.forkserver`, :data:`SERVER_ENV`),
which has imported them once, and runs in a fork of it; where no server answers (a
cluster executor) it runs in its own process. Either way :func:`run` does the work,
and writes the same files.

This module imports only the standard library at the top: the client of a job that
the server runs pays for nothing else.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

__all__ = ["SERVER_ENV", "main", "parse", "preload", "run", "server_jobs"]

#: the environment variable naming the parts server's socket, set by the workflow
SERVER_ENV = "ALFA_BENCH_PARTS_SERVER"
#: the project's modules the server imported, and their times
_SOURCES: dict[str, int] = {}
#: the injected grid's outputs: given all together, for a run scored on the grid
_INJECTED = ("injected_manifest", "injected", "detectability", "isolation_sensors",
             "isolation_actuators")


def parse(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="python -m alfa_bench.workflow.parts_job")
    p.add_argument("method")
    for name in ("manifest", "detections", "traces", "recordings", "sweep", "per-flight",
                 "records", "log"):
        p.add_argument(f"--{name}", required=True)
    p.add_argument("--subsets", required=True, help="the subsets, as a JSON list")
    p.add_argument("--deadline-s", required=True, type=float)
    for name in _INJECTED:
        p.add_argument(f"--{name.replace('_', '-')}")
    args = p.parse_args(argv)
    given = [n for n in _INJECTED if getattr(args, n)]
    if given and len(given) != len(_INJECTED):
        p.error(f"the injected grid's arguments go together: {', '.join(_INJECTED)}")
    return args


def preload() -> None:
    """Import what the parts jobs run on. The server calls it once; its jobs start
    from here."""
    # scipy.special: the sweep's intervals (analysis.scoring.wilson_interval) import it
    # where they are computed, which in a fork cost each job a quarter of a second
    import scipy.special  # noqa: F401

    from alfa_bench.analysis import detectability, isolation, per_flight, sweep  # noqa: F401
    from alfa_bench.outputs import parquet, parts, records, rerun_log, traces  # noqa: F401

    from .forkserver import imported_sources

    _SOURCES.update(imported_sources())


def run(args: argparse.Namespace) -> None:
    """The job: write ``args.method``'s parts."""
    from alfa_bench.analysis.detectability import detectability_table
    from alfa_bench.analysis.isolation import isolation_rows
    from alfa_bench.analysis.per_flight import per_flight_rows
    from alfa_bench.analysis.sweep import sweep_table
    from alfa_bench.data import read_manifest
    from alfa_bench.outputs.parquet import record_rows
    from alfa_bench.outputs.parts import write_part, write_part_rows
    from alfa_bench.outputs.provenance import read_provenance
    from alfa_bench.outputs.records import iter_records, read_records
    from alfa_bench.outputs.rerun_log import write_run_part
    from alfa_bench.outputs.traces import read_trace, read_traces
    from alfa_bench.workflow.logs import log_to

    log_to(args.log)
    manifest = read_manifest(args.manifest)
    out = Path(args.recordings)
    out.mkdir(parents=True, exist_ok=True)
    for flight in manifest.loc[manifest["ground_truth"], "flight"]:
        # a flight the run excluded has no trace, and no part: the recording is without it
        trace = Path(args.traces) / f"{flight}.npz"
        if trace.exists():
            write_run_part(flight, args.method, read_trace(trace), out / f"{flight}.rrd",
                           read_provenance(trace))
    logging.info("%s: recordings written", args.method)

    records = read_records([args.detections])
    traces = read_traces([args.traces], probes=False)
    subsets = json.loads(args.subsets)
    write_part(sweep_table(records, traces, manifest, subsets, args.deadline_s), args.sweep)
    write_part_rows(per_flight_rows(records, traces, manifest, args.deadline_s),
                    args.per_flight)
    write_part_rows(record_rows(records), args.records)
    if args.injected:
        injected = read_manifest(args.injected_manifest)
        write_part(detectability_table(iter_records([args.injected]), injected, records),
                   args.detectability)
        write_part(isolation_rows(iter_records([args.injected]), "sensor"),
                   args.isolation_sensors)
        write_part(isolation_rows(records, "actuator"), args.isolation_actuators)
    logging.info("%s: parts written", args.method)


def server_jobs() -> tuple:
    """The fork server's three steps (:func:`.forkserver.serve`): import what the jobs
    run on, take a job (unless a module changed since the import: the job then runs on
    its own, on the new code), and run it in the fork."""
    def take(argv):
        from .forkserver import changed_since

        if changed_since(_SOURCES):
            print("a module changed since the server loaded it: jobs run on their own",
                  file=sys.stderr)
            return False
        return True

    return preload, take, lambda argv: run(parse(argv))


def main(argv: list[str] | None = None) -> int:
    """Run the job on the parts server when one answers, else here; its exit status."""
    argv = sys.argv[1:] if argv is None else argv
    from .forkserver import run_job

    return run_job(SERVER_ENV, "parts", argv, parse, run)


if __name__ == "__main__":
    sys.exit(main())
