"""ALFA through its own ``.tlog`` logs: every labelled local flight written as MAVLink by
``alfa-bench replay``, with a ``labels.csv`` from the ALFA run's manifest, then
``snakemake all --config corpus=...``; each run's per-flight outcomes beside the ALFA
run's, for every run the MAVLink map carries the signals of.

    ALFA_DIR=/path/to/alfa .venv/bin/python benchmarks/round_trip.py [--alfa-run DIR] \
        [--work DIR] [--leader RUN]

- ``--alfa-run DIR``: a finished ``snakemake all`` over ``ALFA_DIR`` (its ``results/``);
  without it one is run in ``--work``/alfa.
- ``--work DIR``: where the logs, the labels and the corpus run go (default: a new
  temporary folder).
- ``--leader RUN``: the run the goal is stated on (default: the ALFA run's first ranked
  run on the headline subset).

Prints, per run, the flights both scored and how many outcomes agree, then every
differing outcome with both first alarms. A flight's name differs between the two
(``results/corpus/flights.csv`` maps them).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[1]


def snakemake(workdir: Path, *config: str) -> None:
    cmd = [sys.executable, "-m", "snakemake", "all", "--cores", "2", "--quiet",
           "--snakefile", str(REPO / "Snakefile"), "--directory", str(workdir),
           "--configfile", str(REPO / "config/config.yaml"),
           *(["--config", *config] if config else [])]
    subprocess.run(cmd, check=True)


def write_logs(alfa_results: Path, logs: Path) -> None:
    """Each labelled flight of the ALFA run as ``<flight>.tlog``, and ``labels.csv``."""
    from alfa_bench.evaluation import load_corpus
    from alfa_bench.live import replay

    manifest = pd.read_csv(alfa_results / "flights.csv", dtype={"date": str})
    corpus = load_corpus(os.environ["ALFA_DIR"])
    logs.mkdir(parents=True, exist_ok=True)
    rows = []
    for r in manifest[manifest["ground_truth"]].itertuples():
        path = logs / f"{r.flight}.tlog"
        if not path.is_file():
            replay.write_tlog(corpus.flight(r.flight), path)
        fault = "" if r.fault_class == "none" else r.fault_class
        rows.append({"log": path.name, "fault": fault,
                     "onset_s": "" if not fault else repr(float(r.onset_s)),
                     "group": r.date,
                     "emergency_trajectory": str(bool(r.emergency_trajectory)).lower()})
    pd.DataFrame(rows).to_csv(logs / "labels.csv", index=False)


def compare(alfa_results: Path, corpus_results: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Per run, the flights both scored and the outcomes that agree; and the rows that
    differ."""
    names = pd.read_csv(corpus_results / "corpus/flights.csv")
    to_alfa = dict(zip(names["flight"], names["log"].str.removesuffix(".tlog"), strict=True))
    alfa = pd.read_csv(alfa_results / "tables/per_flight.csv")
    logs = pd.read_csv(corpus_results / "tables/per_flight.csv")
    logs["flight"] = logs["flight"].map(to_alfa)
    both = alfa.merge(logs, on=["method", "flight"], suffixes=("_alfa", "_tlog"))
    both["same"] = both["outcome_alfa"] == both["outcome_tlog"]
    per_run = both.groupby("method", sort=False).agg(
        flights=("same", "size"), same=("same", "sum")).reset_index()
    per_run["share"] = per_run["same"] / per_run["flights"]
    diff = both.loc[~both["same"], ["method", "flight", "outcome_alfa", "first_alarm_s_alfa",
                                    "outcome_tlog", "first_alarm_s_tlog"]]
    return per_run, diff


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--alfa-run", type=Path)
    parser.add_argument("--work", type=Path)
    parser.add_argument("--leader")
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="round_trip"))
    alfa = args.alfa_run
    if alfa is None:
        (work / "alfa").mkdir(parents=True, exist_ok=True)
        snakemake(work / "alfa")
        alfa = work / "alfa/results"
    write_logs(alfa, work / "logs")
    (work / "corpus").mkdir(parents=True, exist_ok=True)
    snakemake(work / "corpus", f"corpus={work / 'logs'}")
    per_run, diff = compare(alfa, work / "corpus/results")
    comparison = pd.read_csv(alfa / "tables/comparison.csv")
    primary = comparison["subset"].iloc[0]
    ranked = comparison[(comparison["subset"] == primary) & comparison["rank"].notna()]
    leader = args.leader or ranked.sort_values("rank")["method"].iloc[0]
    print(f"work: {work}")
    print(f"leader on {primary}: {leader}")
    print(per_run.to_string(index=False))
    print(f"\n{len(diff)} differing outcomes:")
    print(diff.to_string(index=False))
    row = per_run[per_run["method"] == leader]
    if len(row):
        r = row.iloc[0]
        print(f"\nleader {leader}: {int(r['same'])} of {int(r['flights'])} outcomes equal "
              f"({100 * r['share']:.1f} %)")


if __name__ == "__main__":
    main()
