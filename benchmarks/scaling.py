"""How long `snakemake all` would take on more flights, on 2 cores or on a cluster.

    python benchmarks/scaling.py [RUN_DIR] [--overhead-s 5] [--nodes 50]

Reads the wall time of every job of the last run in ``RUN_DIR`` (its
``results/benchmarks/``, the flights in its ``results/flights.csv``) and the order of
the rules (``snakemake --rulegraph``), and scales each job's time linearly with the
number of flights: calibration folds are by day, so with new days a detect job grows
faster than that (docs/speed.md, "Growth"). For ``flights``:

- 2 cores: the longer of half the jobs' summed time and the critical path;
- a cluster of ``nodes`` nodes, one job a node: the critical path plus, for each rule on
  it, ``overhead`` seconds of a job's own start (sbatch, and Snakemake parsing the
  workflow inside the job; 5 s measured on the test cluster), while no more jobs run at
  once than there are nodes (every detect job can: there are fewer). Queue waits are
  the site's and are not counted.
"""

from __future__ import annotations

import argparse
import csv
import re
import subprocess
import sys
from collections import defaultdict
from functools import cache
from pathlib import Path

from alfa_bench.data import read_manifest

REPO = Path(__file__).resolve().parent.parent
FLIGHTS = (47, 470, 4700)


def job_seconds(run: Path) -> dict[str, list[float]]:
    """Each rule's jobs' wall seconds, from ``run/results/benchmarks/``. The reference
    runs' detect jobs (rule detect_reference) write theirs under ``detect/`` too, and
    are counted there: they run beside the other detect jobs."""
    seconds = defaultdict(list)
    for tsv in sorted((run / "results/benchmarks").rglob("*.tsv")):
        rule = tsv.parent.name if tsv.parent.name != "benchmarks" else tsv.stem
        with open(tsv) as f:
            seconds[rule].append(float(next(csv.DictReader(f, delimiter="\t"))["s"]))
    return dict(seconds)


def rule_graph(run: Path) -> dict[str, set[str]]:
    """``{rule: the rules it waits for}`` of ``snakemake all --rulegraph`` in ``run``."""
    dot = subprocess.run([sys.executable, "-m", "snakemake", "all", "--rulegraph",
                          "--snakefile", str(REPO / "Snakefile"), "--directory", str(run),
                          "--configfile", str(REPO / "config/config.yaml"), "--forceall"],
                         capture_output=True, text=True, check=True).stdout
    names = dict(re.findall(r'^\s*(\d+)\[label = "(\w+)"', dot, re.M))
    after = {name: set() for name in names.values()}
    for src, dst in re.findall(r"^\s*(\d+) -> (\d+)", dot, re.M):
        after[names[dst]].add(names[src])
    return after


def estimate(seconds: dict[str, list[float]], after: dict[str, set[str]], scale: float,
             overhead_s: float, nodes: int) -> tuple[float, float]:
    """(2 cores, ``nodes`` nodes) wall seconds with every job's time times ``scale``."""

    @cache
    def finish(rule: str, per_job: float) -> float:
        jobs = [s * scale + per_job for s in seconds.get(rule, [])]
        waves = -(-len(jobs) // nodes) if jobs else 0
        own = max(jobs, default=0.0) * waves
        return own + max((finish(r, per_job) for r in after.get(rule, ())), default=0.0)

    total = sum(s * scale for jobs in seconds.values() for s in jobs)
    return max(total / 2, finish("all", 0.0)), finish("all", overhead_s)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run", nargs="?", type=Path, default=Path("."))
    parser.add_argument("--overhead-s", type=float, default=5.0)
    parser.add_argument("--nodes", type=int, default=50)
    args = parser.parse_args()
    seconds = job_seconds(args.run)
    measured = len(read_manifest(args.run / "results/flights.csv"))
    after = rule_graph(args.run)
    jobs = sum(len(v) for v in seconds.values())
    print(f"{jobs} jobs measured on {measured} flights; each job's time scaled by "
          f"flights / {measured}\n")
    print(f"| flights | 2 cores | {args.nodes} nodes (+{args.overhead_s:g} s a job) |")
    print("|---:|---:|---:|")
    for n in FLIGHTS:
        local, cluster = estimate(seconds, after, n / measured, args.overhead_s, args.nodes)
        print(f"| {n} | {local / 60:.1f} min | {cluster / 60:.1f} min |")


if __name__ == "__main__":
    main()
