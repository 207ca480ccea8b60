"""The logistic regressions' solver: L-BFGS (scikit-learn's default) against
Newton-Cholesky, in turns in one process, on the design of ``bench_logistic``'s widest
candidate (every block, every labelled flight of ``$ALFA_DIR``'s cached results).

    ALFA_DIR=/path/to/alfa .venv/bin/python benchmarks/bench_logistic_solver.py [--results results]

Prints, per C and solver, the fit's wall time, its iterations and the L1 norm of its
coefficients (the two reach the same optimum within the solver's tolerance).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from sklearn.linear_model import LogisticRegression

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
    seen = {}

    def keep(model, X, y):
        seen["X"], seen["y"] = X, y
        return model

    fit = LogisticRegression.fit
    LogisticRegression.fit = keep       # the design, as fit_model builds it
    try:
        d.fit_model(segments)
    except AttributeError:              # keep() fitted nothing: no coef_ to read
        pass
    finally:
        LogisticRegression.fit = fit
    return seen["X"], seen["y"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", type=Path, default=Path("results"))
    X, y = design(ap.parse_args().results)
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
