"""The live monitor's latency from a message to its decision, and the rate it sustains.

    ALFA_DIR=... .venv/bin/python benchmarks/bench_live.py [--flight NAME] [--repeat 3]

For each run of issue 49 (``residual_logistic_published_date``, ``coincidence``,
``residual_bank``), fitted without the flight's date, the flight is replayed as the
MAVLink packets of ``alfa-bench replay`` and each packet is parsed by pymavlink,
mapped and fed to the monitor (:mod:`alfa_bench.live.monitor`), timed one by one: the
time from a packet's bytes to the decisions it releases. Beside it, in the same run,
the reference: the detector's bare ``update()`` per grid step on the sampled flight
(what a monitor cannot go below). The sustained rate is packets over the time of all
of them; a link sends ALFA's messages at about 200 a second.

Prints a Markdown table (copied into BENCHMARKS.md).
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

import alfa_bench as ab
from alfa_bench.data import parse_flight_name, sample
from alfa_bench.live import mavlink, replay
from alfa_bench.live.monitor import Monitor

RUNS = ["residual_logistic_published_date", "coincidence", "residual_bank"]


def _date(name: str) -> str:
    return str(parse_flight_name(name)["date"])


def measure(run: str, corpus, name: str) -> dict:
    from pymavlink.dialects.v20 import ardupilotmega as mav

    det = ab.fit_run(run, corpus, [n for n in corpus.flights if _date(n) != _date(name)])
    flight = corpus.flight(name)
    packets = list(replay.packets(flight, det.signals()))
    parser = mav.MAVLink(None)
    parser.robust_parsing = True
    monitor = Monitor(det)
    per_packet, decided = [], []
    for t, packet in packets:
        start = time.perf_counter()
        msg = parser.parse_char(packet)
        kind = msg.get_type()
        n = 0
        if kind in mavlink.MESSAGES:
            n = len(monitor.feed(t, kind, mavlink.decode(kind,
                                                         lambda f, m=msg: getattr(m, f))))
        per_packet.append(time.perf_counter() - start)
        decided.append(n)
    per_packet, decided = np.array(per_packet), np.array(decided)
    s = sample(flight, det.signals(), det.rate_hz)
    det.reset()
    steps = []
    for k in range(s.t.size):
        start = time.perf_counter()
        det.update(s.x[k], s.fresh[k])
        steps.append(time.perf_counter() - start)
    with_step = per_packet[decided > 0]
    return {"run": run, "packets": len(packets), "steps": monitor.steps,
            "p50": np.percentile(with_step, 50) * 1e3, "p99": np.percentile(with_step, 99) * 1e3,
            "all_p99": np.percentile(per_packet, 99) * 1e3,
            "rate": len(packets) / per_packet.sum(),
            "update_p99": np.percentile(steps, 99) * 1e3}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flight", default="carbonZ_2018-07-18-15-53-31_1_engine_failure")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    corpus = ab.load_corpus()
    print(f"Machine: {platform.processor() or platform.machine()}, Python "
          f"{platform.python_version()}; flight {args.flight}; best of {args.repeat}\n")
    print("| run | packets | grid steps | packet to decision p50 / p99, ms | any packet p99, "
          "ms | packets/s sustained | reference: update() p99, ms |")
    print("|---|---|---|---|---|---|---|")
    for run in RUNS:
        best = min((measure(run, corpus, args.flight) for _ in range(args.repeat)),
                   key=lambda r: r["p99"])
        print(f"| `{run}` | {best['packets']} | {best['steps']} | {best['p50']:.2f} / "
              f"{best['p99']:.2f} | {best['all_p99']:.3f} | {best['rate']:.0f} | "
              f"{best['update_p99']:.3f} |")


if __name__ == "__main__":
    main()
