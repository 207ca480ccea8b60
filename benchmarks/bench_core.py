"""Per-sample cost of the detector core, against references measured in the same run.

    .venv/bin/python benchmarks/bench_core.py [--steps 20000] [--repeat 5]

Prints Markdown tables (copied into BENCHMARKS.md):

1. one RLS-ARX z-score pair (n = 26 parameters, the paper's) per sample: the plain
   per-sample NumPy implementation (tests/reference_rls_arx.py), our compiled batch and
   streaming paths, the same RLS arithmetic in C (benchmarks/rls_step.c, gcc -O2),
   padasip's FilterRLS and statsmodels' RecursiveLS;
2. the other per-step work: the windowed GLRT, the FF-RLS step, the Kalman filter
   (filterpy's predict/update, filterpy in steady state, our kernel);
3. every configured run as a whole, per grid step: its plain per-sample path (the
   reference RLS-ARX detector; the stepwise ``update()`` of the others) against its
   compiled ``run()``;
4. streaming latency of every configured run, one update() per 25 Hz step, against
   the 50 ms budget of a 20 Hz telemetry stream.

Times are the best of ``--repeat`` runs; the first call of each compiled kernel
(its compilation) is excluded.
"""

from __future__ import annotations

import argparse
import ctypes
import platform
import subprocess
import sys
import tempfile
import time
from importlib import metadata
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from reference_rls_arx import PlainRecursiveLeastSquares, PlainRlsArxZscore  # noqa: E402

from alfa_bench.data import Sampled, load_flight, sample  # noqa: E402
from alfa_bench.data.synthetic import write_corpus  # noqa: E402
from alfa_bench.methods import (  # noqa: E402
    Detector,
    fault_free_segments,
    make_detector,
)
from alfa_bench.methods.glrt import WindowedGlrt  # noqa: E402
from alfa_bench.methods.kernels import glrt_advance, kalman_innovations  # noqa: E402
from alfa_bench.methods.rls import RecursiveLeastSquares  # noqa: E402
from alfa_bench.methods.rls_arx_zscore import RlsArxZscore  # noqa: E402

PAIR = [{"name": "roll", "input": "roll_cmd", "output": "roll"}]
NA, NB = 1, 25


def best(fn, repeat: int) -> float:
    """Best wall time of ``repeat`` calls of ``fn``, s."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def arx_stream(n: int) -> Sampled:
    rng = np.random.default_rng(0)
    u = np.repeat(rng.uniform(-15, 15, n // 40 + 1), 40)[:n] + 10 * np.sin(np.arange(n) / 50)
    y = np.zeros(n)
    for k in range(1, n):
        y[k] = 0.8 * y[k - 1] + 0.2 * u[k] + rng.normal(0, 0.1)
    x = np.c_[u, y]
    return Sampled(t=np.arange(n) / 25.0, x=x, fresh=np.ones_like(x, dtype=bool),
                   names=("roll_cmd", "roll"))


def c_reference(tmp: Path):
    """benchmarks/rls_step.c compiled with gcc -O2, or None without a C compiler."""
    lib = tmp / "librls.so"
    try:
        subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-o", str(lib),
                        str(ROOT / "benchmarks/rls_step.c")], check=True, capture_output=True)
    except (OSError, subprocess.CalledProcessError):
        return None
    so = ctypes.CDLL(str(lib))
    so.rls_run.restype = None
    return so


def rls_arx_rows(s: Sampled, repeat: int, tmp: Path) -> list[tuple[str, float]]:
    n = s.t.size
    u, y = s.x[:, 0].copy(), s.x[:, 1].copy()
    p = NA + NB
    plain = PlainRlsArxZscore(pairs=PAIR)
    ours = RlsArxZscore(pairs=PAIR)
    ours.run(s)                                         # compile
    rows = [
        ("plain NumPy, per sample (reference)", best(lambda: Detector.run(plain, s), 1)),
        ("ours, compiled batch (`run`)", best(lambda: ours.run(s), repeat)),
        ("ours, compiled streaming (`update` per step)",
         best(lambda: Detector.run(ours, s), max(1, repeat // 2))),
    ]
    so = c_reference(tmp)
    if so is not None:
        dbl = ctypes.POINTER(ctypes.c_double)

        def c_run():
            theta, cov = np.zeros(p), np.eye(p) * 1e6
            work = [np.zeros(p) for _ in range(3)]
            e = np.zeros(n)
            args = [u, y, theta, cov, *work, e]
            so.rls_run(ctypes.c_size_t(n), ctypes.c_size_t(NA), ctypes.c_size_t(NB),
                       *[a.ctypes.data_as(dbl) for a in args])
        rows.append(("RLS arithmetic only, C (gcc -O2)", best(c_run, repeat)))
    try:
        import padasip
        phi = np.c_[np.r_[0.0, y[:-1]], *[np.r_[np.zeros(j), u[:n - j]] for j in range(NB)]]

        def padasip_run():
            f = padasip.filters.FilterRLS(p, mu=1.0, eps=1e-6, w="zeros")
            for k in range(NB, n):
                f.adapt(y[k], phi[k])
        rows.append(("padasip FilterRLS `adapt` (RLS only)", best(padasip_run, 1)))
    except ImportError:
        pass
    try:
        import statsmodels.api as sm
        phi = np.c_[np.r_[0.0, y[:-1]], *[np.r_[np.zeros(j), u[:n - j]] for j in range(NB)]]
        rows.append(("statsmodels RecursiveLS `fit` (RLS as a Kalman filter, batch)",
                     best(lambda: sm.RecursiveLS(y[NB:], phi[NB:]).fit(), 1)))
    except ImportError:
        pass
    return [(name, t / n) for name, t in rows]


def other_rows(n: int, repeat: int) -> list[tuple[str, str, float]]:
    rng = np.random.default_rng(1)
    x = rng.normal(size=n)
    rows = []

    def glrt_plain():
        g = WindowedGlrt(50, 1.0).reset()
        for v in x:
            g.update(v)

    def glrt_ours():
        glrt_advance(x, np.zeros(50), np.zeros(1, dtype=np.int64), 1.0, np.empty(n))
    glrt_ours()
    rows += [("windowed GLRT, M = 50", "plain NumPy `WindowedGlrt.update`", best(glrt_plain, 1)),
             ("windowed GLRT, M = 50", "ours, compiled kernel", best(glrt_ours, repeat))]

    phis = rng.normal(size=(n, 4))
    ys = phis @ [1.0, -0.5, 0.2, 0.1] + rng.normal(size=n)
    for name, cls in (("plain NumPy step", PlainRecursiveLeastSquares),
                      ("ours, compiled step per call", RecursiveLeastSquares)):
        def ff(cls=cls):
            r = cls(4, 1e3, 0.98, 1e4).reset()
            for phi, yy in zip(phis, ys, strict=True):
                r.update(phi, yy)
        ff()
        rows.append(("FF-RLS step, n = 4, lambda = 0.98", name, best(ff, max(1, repeat // 2))))

    from filterpy.kalman import KalmanFilter
    a = np.diag([0.9, 0.8, 0.7, 0.6])
    b, c, d = rng.normal(size=(4, 2)) * 0.1, rng.normal(size=(1, 4)), np.zeros((1, 2))
    k = np.full((4, 1), 0.1)
    u = rng.normal(size=(n, 2))
    yk = rng.normal(size=n)

    def filterpy_full():
        kf = KalmanFilter(dim_x=4, dim_z=1, dim_u=2)
        kf.F, kf.B, kf.H, kf.Q, kf.R = a, b, c, np.eye(4) * 1e-3, np.eye(1)
        for i in range(n):
            kf.predict(u[i].reshape(-1, 1))
            kf.update(yk[i])

    def filterpy_steady():
        kf = KalmanFilter(dim_x=4, dim_z=1, dim_u=2)
        kf.F, kf.B, kf.H, kf.K = a, b, c, k
        for i in range(n):
            kf.update_steadystate(yk[i])
            kf.predict_steadystate(u[i].reshape(-1, 1))

    def ours_kalman():
        kalman_innovations(a, b, c, d, k, u, yk, 0, np.zeros(4), np.empty(n))
    ours_kalman()
    rows += [("Kalman filter, order 4", "filterpy `predict`/`update` (full covariance)",
              best(filterpy_full, 1)),
             ("Kalman filter, order 4", "filterpy steady state (our streaming path)",
              best(filterpy_steady, 1)),
             ("Kalman filter, order 4", "ours, compiled steady-state kernel (batch)",
              best(ours_kalman, repeat))]
    return [(what, how, t / n) for what, how, t in rows]


def fitted_runs(tmp: Path):
    """Every configured run, fitted on a synthetic corpus, with a scored flight."""
    processed = tmp / "processed"
    write_corpus(processed)
    flights = [load_flight(p) for p in sorted(processed.iterdir())]
    scored = next(f for f in flights if f.fault and f.fault.onset_s)
    config = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    for run, spec in config["methods"].items():
        det = make_detector(spec["detector"], spec.get("params"))
        if det.calibrated:
            det.fit(fault_free_segments(det, flights, margin_s=1.0))
        yield run, det, sample(scored, det.signals(), det.rate_hz)


def detector_rows(runs, repeat: int) -> list[tuple[str, float, float]]:
    """Per configured run: s per step of the plain per-sample path and of ``run()``."""
    rows = []
    for run, det, s in runs:
        plain = (PlainRlsArxZscore(**det.get_params()) if isinstance(det, RlsArxZscore)
                 else det)
        det.run(s)                                      # compile
        rows.append((run, best(lambda p=plain, s=s: Detector.run(p, s), 1) / s.t.size,
                     best(lambda d=det, s=s: d.run(s), repeat) / s.t.size))
    return rows


def latency_rows(runs) -> list[tuple[str, float, float, float]]:
    """Per configured run: median, 99th percentile and max of one update() and the
    alarms of its scores, s."""
    rows = []
    for run, det, s in runs:
        det.reset()
        det.update(s.x[0], s.fresh[0])                  # compile
        det.reset()
        times = np.empty(s.t.size)
        for k in range(s.t.size):
            t = time.perf_counter()
            det.alarms(det.update(s.x[k], s.fresh[k]))
            times[k] = time.perf_counter() - t
        rows.append((run, float(np.median(times)), float(np.quantile(times, 0.99)),
                     float(times.max())))
    return rows


def machine() -> str:
    cpu = next((line.split(":", 1)[1].strip() for line in
                Path("/proc/cpuinfo").read_text().splitlines() if "model name" in line),
               platform.processor()) if Path("/proc/cpuinfo").exists() else platform.processor()
    versions = ", ".join(f"{p} {metadata.version(p)}" for p in
                         ("numpy", "numba", "filterpy", "padasip", "statsmodels")
                         if _installed(p))
    return f"{cpu}; Python {platform.python_version()}; {versions}"


def _installed(package: str) -> bool:
    try:
        metadata.version(package)
        return True
    except metadata.PackageNotFoundError:
        return False


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    print(f"machine: {machine()}\n")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rows = rls_arx_rows(arx_stream(args.steps), args.repeat, tmp)
        plain = rows[0][1]
        c_time = next((t for name, t in rows if name.startswith("RLS arithmetic only")), None)
        flops = 3 * (NA + NB) ** 2
        print(f"### RLS-ARX z-score, one pair, n = {NA + NB}, {args.steps} samples\n")
        print("| implementation | us / sample | plain / this | this / C | GFlop/s at 3n^2 |")
        print("|---|---|---|---|---|")
        for name, t in rows:
            vs_c = f"{t / c_time:.2f}" if c_time else "-"
            print(f"| {name} | {t * 1e6:.2f} | {plain / t:.1f} | {vs_c} | "
                  f"{flops / t / 1e9:.2f} |")
        print("\n### Other per-step work\n")
        print("| work | implementation | us / sample |")
        print("|---|---|---|")
        for what, how, t in other_rows(args.steps, args.repeat):
            print(f"| {what} | {how} | {t * 1e6:.2f} |")
        runs = list(fitted_runs(tmp))
        print("\n### Whole detectors, per grid step (synthetic flight, 20 Hz rows on a 25 Hz"
              " grid)\n")
        print("| run | plain per-sample us / step | ours `run()` us / step | plain / ours |")
        print("|---|---|---|---|")
        for run, plain_t, ours_t in detector_rows(runs, args.repeat):
            print(f"| {run} | {plain_t * 1e6:.1f} | {ours_t * 1e6:.2f} | "
                  f"{plain_t / ours_t:.0f} |")
        print("\n### Streaming latency: one `update()` per step, budget 50 ms (20 Hz)\n")
        print("| run | median ms | p99 ms | max ms | budget / p99 |")
        print("|---|---|---|---|---|")
        for run, med, p99, worst in latency_rows(runs):
            print(f"| {run} | {med * 1e3:.3f} | {p99 * 1e3:.3f} | {worst * 1e3:.3f} | "
                  f"{0.05 / p99:.0f} |")


if __name__ == "__main__":
    main()
