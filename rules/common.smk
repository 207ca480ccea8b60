import atexit
import functools
import os
import shlex
import sys
from pathlib import Path

import pandas as pd

from snakemake.exceptions import WorkflowError
from snakemake.logging import logger

from alfa_bench.workflow.preflight import alfa_dir_problem, failure_message, stop
from alfa_bench.workflow import forkserver
from alfa_bench.workflow.dependencies import module_sources, script_sources
from alfa_bench.workflow.detect_job import SERVER_ENV, write_job_config
from alfa_bench.workflow.param_checks import KeptChecks
from alfa_bench.workflow.parts_job import SERVER_ENV as PARTS_SERVER_ENV
from alfa_bench.workflow.script_job import SERVER_ENV as SCRIPT_SERVER_ENV
from alfa_bench.workflow.logs import closing_lines
from alfa_bench.workflow.stale import remove, stale_results
from alfa_bench.workflow.resources import count_flights, job_resources
from alfa_bench.outputs.provenance import RUN_FILE
from alfa_bench.analysis.held_out import own_calibration
from alfa_bench.data import SIGNALS, resolve_alfa_dir
from alfa_bench.methods import detector_module, make_detector

# a corpus of logs instead of ALFA (docs/own-flights.md): converted before the plan, its
# not-applicable runs out of the config (workflow/corpus.py)
CORPUS = config.get("corpus")
if CORPUS:
    from alfa_bench.logs.corpus import CorpusError, convert_corpus, read_signals
    from alfa_bench.workflow.corpus import CONVERTED, corpus_config

    try:
        _converted = (convert_corpus(CORPUS, CONVERTED) if workflow.is_main_process
                      else None)
    except CorpusError as _e:
        stop(f"config corpus: {_e}")
    if _converted is not None and _converted.flights.empty:
        stop(f"config corpus: no log of {CORPUS} could be read ({len(_converted.left_out)} "
             f"left out): {CONVERTED / 'left_out.csv'} says why, by file, line and field")
    corpus_config(config, _converted.signals if _converted else read_signals(CONVERTED),
                  any(f.endswith("with_emr_traj") for f in pd.read_csv(
                      CONVERTED / "flights.csv")["flight"]))

METHODS = list(config["methods"])
# the runs scored on the injected sensor faults and for isolation: the reference rows
# speak of ALFA's metric and emulation, not of sensors
DETECTORS = [m for m, spec in config["methods"].items()
             if spec.get("role", "method") != "reference"]
REFERENCES = [m for m in METHODS if m not in DETECTORS]
PRIMARY = config["primary_subset"]
if PRIMARY not in config["subsets"]:
    raise WorkflowError(f"config primary_subset {PRIMARY!r} is not one of subsets "
                        f"{config['subsets']}")
# the tables list the subsets in this order: the headline first
SUBSETS = [PRIMARY, *(s for s in config["subsets"] if s != PRIMARY)]
# where `snakemake injected_csv` writes the injected flights, and so their folder name
INJECTED_PROCESSED = "results/injected/processed"

def _check_config_runs():
    """The schema checks the config's shape; each method's detector and parameter names
    are checked against the registry here, before any job runs (a check passed before
    is kept: workflow/param_checks.py)."""
    checks = KeptChecks()
    for name, spec in config["methods"].items():
        try:
            detector = make_detector(spec["detector"], spec.get("params"))
            # a library's model by name, imported
            checks.check(spec, detector.check_params)
        except (KeyError, TypeError, ValueError) as e:
            raise WorkflowError(f"config methods.{name}: {e}") from None
        # a misspelt signal is the config's error, not every flight's bad data
        unknown = [s for s in detector.signals() if s not in SIGNALS]
        if unknown:
            raise WorkflowError(f"config methods.{name}: unknown signal(s) {unknown}; known: "
                                f"{sorted(SIGNALS)}")
        if not detector.causal and spec.get("role", "method") != "reference":
            raise WorkflowError(f"config methods.{name}: detector {spec['detector']!r} is not "
                                "causal, so it can only be a reference row (role: reference)")
        # the run's own grouping, else the config's: either way it is the run's
        grouping = own_calibration(config["calibration"], spec)["group_by"]
        if grouping != "date" and spec.get("role", "method") != "reference":
            raise WorkflowError(f"config methods.{name}: calibration.group_by: {grouping} lets "
                                "flights of the scored date train it, so it can only be a "
                                "reference row (role: reference)")
    checks.save()


# by the process that plans the run: a cluster job's process, which parses the workflow
# again, imports no detector
if workflow.is_main_process:
    _check_config_runs()


# what a run taken out of the config left: named once, removed on request
STALE = stale_results("results", METHODS)
if STALE and workflow.is_main_process:
    logger.warning(f"{len(STALE)} result folder(s) or file(s) no configured run writes any "
                   f"more, e.g. {STALE[0]}: nothing reads them; `snakemake remove_stale` "
                   "removes them")


def detector_code(method):
    """The source files of the modules ``method``'s job runs on: the job's own
    (workflow/detect_job.py) and its detector's; a job's input, so that a changed module
    re-runs the jobs of the detectors that use it, and no other. A detector that wraps
    another (nested selection: ``params.detector``) runs on both."""
    spec = config["methods"][method]
    names = [spec["detector"], (spec.get("params") or {}).get("detector")]
    modules = ["alfa_bench.workflow.detect_job", *(detector_module(n) for n in names if n)]
    return sorted({f for m in modules if m for f in module_sources(m)})


def script_code(name):
    """The source files of the project's modules that ``scripts/<name>.py`` imports: its
    rule's input, so that a changed module re-runs the jobs whose scripts use it, and
    those after them. (The download's is left out: the archive is the config's MD5's.)"""
    return script_sources(Path(workflow.basedir) / "scripts" / f"{name}.py")


@functools.cache
def recorded_signals():
    """The raw signals the flights' parts record: every run's detector's, in config
    order (a changed parameter of a run re-records no flight unless it changes them)."""
    detectors = [make_detector(s["detector"], s.get("params")) for s in config["methods"].values()]
    return list(dict.fromkeys(s for d in detectors for s in d.signals()))


@functools.cache
def _fault_classes():
    """Each flight's fault class, from the manifest, read once per report."""
    from alfa_bench.data import read_manifest

    return read_manifest("results/flights.csv").set_index("flight")["fault_class"].to_dict()


def figure_fault_class(wildcards):
    """The report files each flight's figure under its fault class."""
    return _fault_classes()[wildcards.flight]


# the corpus's flights, else ALFA_DIR, else the config's alfa_dir, else the downloaded
# archive
_alfa = CONVERTED if CORPUS else resolve_alfa_dir(config.get("alfa_dir"))
# who named the folder, for the messages that end a run on it
ALFA_SOURCE = ("the config's corpus" if CORPUS else
               "ALFA_DIR" if os.environ.get("ALFA_DIR") else
               "the config's alfa_dir" if _alfa is not None else "the download's dest")
if not CORPUS and _alfa is not None and (_why := alfa_dir_problem(_alfa, ALFA_SOURCE)):
    stop(_why)
DOWNLOAD = _alfa is None
ALFA_DIR = Path(config["download"]["dest"]) if DOWNLOAD else _alfa
PROCESSED = ALFA_DIR / "processed"
# every rule's mem_mb and runtime, for a scheduler to place its jobs (profiles/slurm)
JOB_RESOURCES = job_resources(count_flights(PROCESSED))
# where the flights came from, in every result's provenance (config is what it records)
config["alfa_dir"] = str(ALFA_DIR)
config["data_origin"] = (
    f"corpus of logs: {CORPUS}" if CORPUS else
    f"downloaded: {config['download']['file']}, MD5 {config['download']['md5']}" if DOWNLOAD
    else "ALFA_DIR" if os.environ.get("ALFA_DIR") else "config alfa_dir")


wildcard_constraints:
    method="|".join(METHODS),


# A detect job's command (workflow/detect_job.py): the run's files as arguments; the
# config, after its overrides, in a file named in the environment the jobs inherit
JOB_CONFIG = write_job_config(config)
DETECT_JOB = (f"{shlex.quote(sys.executable)} -m alfa_bench.workflow.detect_job "
              "{wildcards.method} --manifest {input.manifest:q} --cache {input.cache:q} "
              "--detections {output.detections:q} --traces {output.traces:q} "
              "--panels {output.panels:q} --benchmark {output.benchmark:q} --log {log:q} "
              "{params.injected}")


# A run's parts job's command (workflow/parts_job.py)
PARTS_JOB = (f"{shlex.quote(sys.executable)} -m alfa_bench.workflow.parts_job "
             "{wildcards.method} --manifest {input.manifest:q} "
             "--detections {input.detections:q} --traces {input.traces:q} "
             "--recordings {output.recordings:q} --sweep {output.sweep:q} "
             "--per-flight {output.per_flight:q} --records {output.records:q} "
             "--subsets {params.subsets:q} --deadline-s {params.deadline_s} --log {log:q} "
             "{params.injected}")


# On one machine the detect jobs fork from a server that has loaded the imports and the
# flights once, the parts jobs from another, the scripts from a third
# (workflow/forkserver.py); a cluster's jobs run each in its own process. One detect job
# alone (one run changed) runs in its own process too: the server loads every run's
# imports, and it ended about a second later than the job on its own (BENCHMARKS.md);
# so does one script job alone.
# A local run takes no rate limit: Snakemake's default one (100 jobs a second) makes each
# pass of its scheduler start a 1 s timer for another pass, and each job's start and end
# one more such chain, so that by the end of a run it selects jobs (and stats their
# inputs) hundreds of times a second (docs/speed.md)
onstart:
    if workflow.local_exec:
        workflow.scheduler.job_rate_limiter = None
        needed = [j.rule for j in workflow.dag.needrun_jobs()]
        if sum(r.name in ("detect", "detect_reference") for r in needed) > 1:
            forkserver.start(SERVER_ENV, "alfa_bench.workflow.detect_job:server_jobs",
                             [JOB_CONFIG], "results/logs/detect_server.log")
        if any(r.name.startswith("run_parts") for r in needed):
            forkserver.start(PARTS_SERVER_ENV, "alfa_bench.workflow.parts_job:server_jobs",
                             [], "results/logs/parts_server.log")
        if sum(r.is_script for r in needed) > 1:
            forkserver.start(SCRIPT_SERVER_ENV, "alfa_bench.workflow.script_job:server_jobs",
                             [Path(workflow.basedir) / "scripts"],
                             "results/logs/script_server.log")
