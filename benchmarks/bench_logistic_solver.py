"""The logistic regressions' solver: L-BFGS (scikit-learn's default) against
Newton-Cholesky, in turns in one process, on the design of ``bench_logistic``'s widest
candidate (every block, every labelled flight of a workflow's ``results/``: its manifest
and cached flights, so run it after ``snakemake all``).

    .venv/bin/python benchmarks/bench_logistic_solver.py [--results results] [--threads 1]

Prints, per C and solver, the fit's wall time, its iterations and the L1 norm of its
coefficients (the two reach the same optimum within the solver's tolerance).
``--threads 1`` limits the BLAS to one thread, as the detect jobs run
(:mod:`workflow.forkserver`); by default it uses every core.
"""

from __future__ import annotations

import argparse
import contextlib
import time
from pathlib import Path
from unittest import mock

import numpy as np
from sklearn.linear_model import LogisticRegression
from threadpoolctl import threadpool_limits

from alfa_bench.data import load_cached, read_manifest
from alfa_bench.methods.base import labelled_segments
from alfa_bench.methods.bench_logistic import BLOCKS, BenchLogistic


def design(results: Path) -> tuple[np.ndarray, np.ndarray]:
    """The standardised rows and labels the widest candidate's regression is fitted on."""
    manifest = read_manifest(results / "flights.csv")
    flights = load_cached(results / "cache", manifest)
    d = BenchLogistic(features=BLOCKS)
    segments = labelled_segments(d, [flights[f] for f in manifest.loc[manifest["ground_truth"],
                                                                      "flight"]])
    # the rows fit_model hands the regression, taken at its call: the design exactly as
    # the detector builds it; the fit itself is the benchmark's
    with mock.patch.object(LogisticRegression, "fit", autospec=True,
                           side_effect=StopIteration) as fit, \
            contextlib.suppress(StopIteration):
        d.fit_model(segments)
    _, X, y = fit.call_args.args
    return X, y


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", type=Path, default=Path("results"))
    ap.add_argument("--threads", type=int, help="BLAS threads (default: every core)")
    args = ap.parse_args()
    X, y = design(args.results)
    with threadpool_limits(args.threads, user_api="blas"):
        timings(X, y)


def timings(X: np.ndarray, y: np.ndarray) -> None:
    """Each solver's fits of ``X``, ``y``, in turns, as a Markdown table."""
    print(f"design: {X.shape[0]} rows, {X.shape[1]} features, {int(y.sum())} positives\n")
    print("| C | solver | fit s | iterations | sum abs coef |")
    print("|---|---|---|---|---|")
    for C in (0.01, 0.1, 1.0):
        for _ in range(2):
            for solver in ("lbfgs", "newton-cholesky"):
                t = time.perf_counter()
                r = LogisticRegression(C=C, class_weight="balanced", max_iter=5000,
                                       solver=solver).fit(X, y)
                print(f"| {C} | {solver} | {time.perf_counter() - t:.3f} | {r.n_iter_[0]} | "
                      f"{np.abs(r.coef_).sum():.6f} |", flush=True)


if __name__ == "__main__":
    main()
