"""A generic outlier run scored in one batch call per flight against one call per step,
in the same process.

    .venv/bin/python benchmarks/bench_outliers.py [--models IForest,KNN,...] [--repeat 3]

Each PyOD model of ``--models`` (the adapter of ``methods/outliers.py``, its defaults)
is fitted on the synthetic corpus's fault-free segments, then scores one synthetic
flight twice: :meth:`~alfa_bench.methods.outliers.OutlierModel.run`, one call of the
model for the flight, and stepping :meth:`~alfa_bench.methods.Detector.update`, one
call per grid step (what the streaming contract alone would do). Both give the same
scores (checked). Prints a Markdown table of the best of ``--repeat``: time per flight,
per row, and their ratio.

A second table scores ``--continuations`` flights continued from one fork at half the
flight (as the injected grid's flights of one source are): one
:meth:`~alfa_bench.methods.Detector.run` each, against one
:meth:`~alfa_bench.methods.Detector.run_many` for them all (the same scores, checked).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from alfa_bench.data import load_flight, sample
from alfa_bench.data.synthetic import write_corpus
from alfa_bench.methods import Detector, forks, training_segments
from alfa_bench.methods.outliers import PyODDetector


def best(fn, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return min(times), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", default="IForest,ECOD,HBOS,PCA,KNN")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--continuations", type=int, default=100)
    args = parser.parse_args()
    processed = Path(tempfile.mkdtemp(prefix="bench-outliers-")) / "processed"
    write_corpus(processed)
    flights = [load_flight(p) for p in sorted(processed.iterdir())]
    fitted = []
    print("| model | rows | batch, ms a flight | per step, ms a flight | per step / batch |")
    print("|---|---|---|---|---|")
    for model in args.models.split(","):
        d = PyODDetector(model)
        d.fit(training_segments(d, flights, margin_s=1.0))
        s = sample(flights[0], d.signals(), d.rate_hz)
        batch, (score, _) = best(lambda d=d, s=s: d.run(s), args.repeat)
        stepped, (ref, _) = best(lambda d=d, s=s: Detector.run(d, s), args.repeat)
        np.testing.assert_allclose(score, ref, rtol=1e-9, atol=1e-9)
        print(f"| {model} | {s.t.size} | {1e3 * batch:.1f} | {1e3 * stepped:.1f} | "
              f"{stepped / batch:.0f}x |")
        fitted.append((model, d, s))
    print("\n| model | flights continued | one call each, ms | one call for all, ms | ratio |")
    print("|---|---|---|---|---|")
    for model, d, s in fitted:
        fork = next(iter(forks(d, flights[0], [s.t[s.t.size // 2]]).values()))
        items = [(s, fork.sampled.t.size, fork.state)] * args.continuations
        each, scores = best(lambda d=d, items=items: [d.run(x, False, k, state)
                                                      for x, k, state in items], args.repeat)
        together, many = best(lambda d=d, items=items: d.run_many(items), args.repeat)
        for (a, _), (b, _) in zip(scores, many, strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9)
        print(f"| {model} | {args.continuations} | {1e3 * each:.1f} | {1e3 * together:.1f} | "
              f"{each / together:.1f}x |")


if __name__ == "__main__":
    main()
