"""The injected grid scored from forks at onset against from t = 0, in the same process.

    ALFA_DIR=/path/to/alfa .venv/bin/python benchmarks/bench_fork.py [--methods ...]
        [--repeat 3]

Needs the parsed-flight cache and manifest of a ``snakemake all`` run
(``results/cache``, ``results/flights.csv``). For each configured run: the detector is
fitted once, on the fault-free data of every date but the first, and then scores the
first date's injected flights twice: each from t = 0 (:func:`run_detector`), and each
continued from the fork at its onset, the source run once up to all its onsets
(:func:`forks`, included in the time). Both build the same injected flights, so the
times differ by the detector's work only. Prints a Markdown table; times are the best
of ``--repeat``, and the first run is checked to give the same alarms both ways.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import yaml

from alfa_bench.data import load_cached, read_manifest
from alfa_bench.data.inject import InjectedGrid
from alfa_bench.methods import forks, make_detector, run_detector, training_segments

ROOT = Path(__file__).resolve().parent.parent


def from_start(det, built: dict) -> dict:
    """Each injected flight run from t = 0: its first alarm."""
    return {n: run_detector(det, f).first_alarm_s() for n, f in built.items()}


def from_forks(det, built: dict, flights) -> dict:
    """Each source run once up to all its onsets, each injected flight continued from
    the fork at its onset: its first alarm."""
    onsets = {}
    for f in built.values():
        onsets.setdefault(f.fault.source, []).append(f.fault.onset_s)
    at = {s: forks(det, flights[s], o) for s, o in onsets.items()}
    return {n: run_detector(det, f, fork=at[f.fault.source].get(f.fault.onset_s))
            .first_alarm_s() for n, f in built.items()}


def best_of(repeat: int, fn, *args) -> float:
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn(*args)
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    config = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    runs = [m for m, s in config["methods"].items() if s.get("role", "method") != "reference"]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--methods", nargs="*", default=runs)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    manifest = read_manifest(ROOT / "results/flights.csv")
    flights = load_cached(ROOT / "results/cache", manifest)
    first = sorted(manifest["date"].astype(str))[0]
    free = manifest.loc[(manifest["fault_class"] == "none")
                        & (manifest["date"].astype(str) == first), "flight"]
    grid = config["injection"]
    day = manifest[manifest["date"].astype(str) == first]
    injected = InjectedGrid({f: flights[f] for f in free}, day, ROOT / "results/injected",
                            grid["sensors"], grid["faults"], grid["onsets"])
    built = {name: injected[name] for name in injected}
    other = [flights[f] for f in manifest.loc[manifest["ground_truth"]
                                              & (manifest["date"].astype(str) != first),
                                              "flight"]]
    print(f"{len(built)} injected flights of {len(free)} sources ({first}); best of "
          f"{args.repeat}\n")
    print("| run | from t = 0, s | forked, s | from t = 0 / forked |")
    print("|---|---|---|---|")
    for method in args.methods:
        spec = config["methods"][method]
        det = make_detector(spec["detector"], spec.get("params"))
        if det.calibrated:
            det.fit(training_segments(det, other, config["calibration"]["margin_s"]))
        # the same alarms both ways (and the kernels compiled before timing)
        assert from_start(det, built) == from_forks(det, built, flights), method
        whole = best_of(args.repeat, from_start, det, built)
        forked = best_of(args.repeat, from_forks, det, built, flights)
        print(f"| {method} | {whole:.2f} | {forked:.2f} | {whole / forked:.2f} |", flush=True)


if __name__ == "__main__":
    main()
