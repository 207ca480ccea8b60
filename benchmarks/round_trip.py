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
- ``--values-only``: also the ALFA flights with each mapped column's values replaced by
  what the link carried (read back from the logs) at ALFA's own row times, scored as
  ALFA: which differences the values alone make, and which the logs' row times.

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


def snakemake(workdir: Path, *config: str, alfa_dir: Path | None = None) -> None:
    """``snakemake all`` in ``workdir`` (on ``alfa_dir`` where given, else ``ALFA_DIR``)."""
    env = {**os.environ, **({"ALFA_DIR": str(alfa_dir)} if alfa_dir else {})}
    cmd = [sys.executable, "-m", "snakemake", "all", "--cores", "2", "--quiet",
           "--snakefile", str(REPO / "Snakefile"), "--directory", str(workdir),
           "--configfile", str(REPO / "config/config.yaml"),
           *(["--config", *config] if config else [])]
    subprocess.run(cmd, check=True, env=env)


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


def write_values_only(alfa_results: Path, corpus_results: Path, out: Path) -> None:
    """The ALFA flights under ``out/processed``, each column the link carries holding
    the value read back from the flight's log at each ALFA row time (1 µs of slack for
    the log's stamps), every other column and every row time as ALFA has them."""
    import shutil

    import numpy as np

    from alfa_bench.data import SIGNALS

    names = pd.read_csv(corpus_results / "corpus/flights.csv")
    processed = Path(os.environ["ALFA_DIR"]) / "processed"
    for log, flight in zip(names["log"], names["flight"], strict=True):
        name = log.removesuffix(".tlog")
        target = out / "processed" / name
        shutil.copytree(processed / name, target, dirs_exist_ok=True)
        converted = corpus_results / "corpus/processed" / flight
        origin = int(pd.read_csv(converted / f"{flight}-log-origin.csv")["%time"].iloc[0])
        for topic in {sig.topic for sig in SIGNALS.values()}:
            mine = converted / f"{flight}-{topic}.csv"
            if not mine.is_file():
                continue
            theirs = target / f"{name}-{topic}.csv"
            frame = pd.read_csv(theirs, dtype={"%time": "int64"})
            link = pd.read_csv(mine, dtype={"%time": "int64"})
            t0 = min(int(pd.read_csv(p, usecols=["%time"], dtype="int64")["%time"].iloc[0])
                     for p in (processed / name).glob("*.csv"))
            at = (frame["%time"].to_numpy() - t0) + origin + 1000
            row = np.searchsorted(link["%time"].to_numpy(), at, side="right") - 1
            ok = row >= 0
            for column in link.columns[1:]:
                values = frame[column].to_numpy(dtype=float, copy=True)
                values[ok] = link[column].to_numpy()[row[ok]]
                frame[column] = values
            frame.to_csv(theirs, index=False)


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


def _outcomes(results: Path) -> pd.DataFrame:
    table = pd.read_csv(results / "tables/per_flight.csv")
    return table[["method", "flight", "outcome", "first_alarm_s"]].rename(
        columns={"outcome": "outcome_values", "first_alarm_s": "first_alarm_s_values"})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--alfa-run", type=Path)
    parser.add_argument("--work", type=Path)
    parser.add_argument("--leader")
    parser.add_argument("--values-only", action="store_true")
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="round_trip"))
    alfa = args.alfa_run
    if alfa is None:
        (work / "alfa").mkdir(parents=True, exist_ok=True)
        snakemake(work / "alfa")
        alfa = work / "alfa/results"
    write_logs(alfa, work / "logs")
    (work / "corpus").mkdir(parents=True, exist_ok=True)
    if not (work / "corpus/results/tables/per_flight.csv").is_file():
        snakemake(work / "corpus", f"corpus={work / 'logs'}")
    per_run, diff = compare(alfa, work / "corpus/results")
    if args.values_only:
        values = work / "values"
        write_values_only(alfa, work / "corpus/results", values / "alfa")
        (values / "run").mkdir(parents=True, exist_ok=True)
        snakemake(values / "run", alfa_dir=values / "alfa")
        both = diff.merge(_outcomes(values / "run/results"), on=["method", "flight"],
                          how="left")
        print("\nthe differing outcomes, with the ALFA flights holding the link's values at "
              "ALFA's row times:")
        print(both.to_string(index=False))
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
