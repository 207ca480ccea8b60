"""The script jobs' fork server: a Snakemake script of ``scripts/`` (a ``script:`` rule:
the tables, figures, recordings, the paper) run in a fork of a server that imported
what the scripts import, once per run of the workflow (:mod:`.forkserver`).

A script that Snakemake runs starts a Python of its own and pays a second or more for
its imports (pandas, matplotlib, rerun, the analyses), about as much as a merge's work:
the aggregates after one changed run cost mostly that. So each script begins::

    from alfa_bench.workflow.script_job import forked

    forked(snakemake, __file__)

:func:`forked` hands the script's path and Snakemake's ``snakemake`` object to the
server named in the environment (:data:`SERVER_ENV`) and exits with the status of the
fork, which runs the script from its top with the same object; there ``forked``
returns at once. Where no server answers (a cluster executor, which starts none; one
script job alone, for which the workflow starts none) it returns, and the script runs
in its own process: the same code, the same files.

This module imports only the standard library and :mod:`.forkserver` at the top: a
script the server runs pays for nothing else.
"""

from __future__ import annotations

import ast
import base64
import importlib
import os
import pickle
import runpy
import sys
from pathlib import Path

from .forkserver import changed_since, imported_sources, killed, submit

__all__ = ["SERVER_ENV", "forked", "server_jobs"]

#: the environment variable naming the script server's socket, set by the workflow
SERVER_ENV = "ALFA_BENCH_SCRIPT_SERVER"
#: the project's modules the server imported, and their times
_SOURCES: dict[str, int] = {}
#: set in the server's fork, where the script runs: :func:`forked` returns there
_IN_FORK = False


def forked(sm, script: str) -> None:
    """Run the Snakemake script at ``script`` (its ``__file__``), with ``sm`` (its
    ``snakemake``), on the script server when one answers, and exit with its status;
    return where none does, or in the server's fork."""
    server = os.environ.get(SERVER_ENV)
    if _IN_FORK or not server:
        return
    job = base64.b64encode(pickle.dumps(sm, protocol=pickle.HIGHEST_PROTOCOL)).decode()
    status = submit(server, [os.path.realpath(script), job])
    if status is None:
        return
    if status < 0:
        # the fork could write nothing: the log says what ended it
        line = f"alfa-bench: script job {sm.rule}: {killed(-status)}"
        with open(sm.log[0], "a") as log:
            print(line, file=log)
        print(line, file=sys.stderr)
        status = 128 - status
    sys.exit(status)


def script_imports(folder: str | Path) -> list[str]:
    """The modules the scripts in ``folder`` import at their top, in order, once."""
    names: dict[str, None] = {}
    for path in sorted(Path(folder).glob("*.py")):
        for node in ast.parse(path.read_text(), str(path)).body:
            if isinstance(node, ast.Import):
                names.update(dict.fromkeys(a.name for a in node.names))
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names[node.module] = None
    return list(names)


def _run(argv: list[str]) -> None:
    """In the fork: the script of ``argv`` from its top, with its ``snakemake``."""
    global _IN_FORK
    _IN_FORK = True
    script, job = argv
    sm = pickle.loads(base64.b64decode(job))
    runpy.run_path(script, init_globals={"snakemake": sm}, run_name="__main__")


def server_jobs(folder: str) -> tuple:
    """The fork server's three steps (:func:`.forkserver.serve`): import what the
    scripts in ``folder`` import, take a job (unless a module of the project changed
    since: the script then runs on its own, on the new code), and run it in the fork."""
    def preload():
        for name in script_imports(folder):
            importlib.import_module(name)
        _SOURCES.update(imported_sources())

    def take(argv):
        if changed_since(_SOURCES):
            print("a module changed since the server loaded it: scripts run on their own",
                  file=sys.stderr)
            return False
        print(f"{Path(argv[0]).name}: forked", flush=True)
        return True

    return preload, take, _run
