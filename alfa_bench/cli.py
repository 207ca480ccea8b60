"""``alfa-bench``: the commands that take a detector out of the benchmark.

``alfa-bench fit RUN -o FILE`` fits the config run ``RUN`` on every flight with ground
truth (or ``--flights``) of the ALFA copy the workflow finds (``ALFA_DIR``, the config's
``alfa_dir``, or the download; ``--alfa-dir`` overrides) and writes its model file
(:func:`alfa_bench.models.save_run`).

``alfa-bench monitor FILE SOURCE`` runs the model file's detector on ``SOURCE``, in
pymavlink's connection syntax (a ``.tlog``, ``udpin:0.0.0.0:14550``, ``tcp:host:port``,
a serial device): an alarm is a log line (time, channel, score, threshold), progress a
line every ``--every`` seconds (:mod:`alfa_bench.live.monitor`).

``alfa-bench replay FLIGHT -o OUT`` writes a flight of the corpus as MAVLink, to a
``.tlog`` or to a link (``udpout:127.0.0.1:14550``) at ``--speed`` times its pace
(:mod:`alfa_bench.live.replay`).
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path


def _fit(args: argparse.Namespace) -> int:
    from alfa_bench.evaluation import load_corpus
    from alfa_bench.models import save_run

    corpus = load_corpus(args.alfa_dir)
    path = save_run(args.run, corpus, args.output, args.flights)
    flights = len(args.flights) if args.flights else len(corpus.flights)
    print(f"{args.run}: fitted on {flights} flights, written to {path}")
    return 0


def _monitor(args: argparse.Namespace) -> int:
    import time

    from alfa_bench.live.monitor import Monitor, watch
    from alfa_bench.methods.model_files import load_model

    detector, about = load_model(args.model)
    monitor = Monitor(detector, allow_actuators=args.allow_actuators)
    last = [time.monotonic(), 0]

    quiet_since = [time.monotonic(), 0]

    def progress() -> bool:
        now = time.monotonic()
        if monitor.messages != quiet_since[1]:
            quiet_since[:] = [now, monitor.messages]
        if now - last[0] >= args.every:
            rate = (monitor.messages - last[1]) / (now - last[0])
            state = (f"silent for {now - quiet_since[0]:.0f} s" if rate == 0 else
                     "armed" if monitor.armed else
                     f"waiting for {', '.join(monitor.missing()) or 'a later message'}")
            print(f"{about['run']}: {rate:.0f} messages/s, {monitor.steps} grid steps, "
                  f"{state}", flush=True)
            last[:] = [now, monitor.messages]
        return False

    interrupted = False
    try:
        watch(args.source, monitor, clock=args.clock, stop=progress)
    except KeyboardInterrupt:
        interrupted = True
    first = monitor.first_alarm
    if not monitor.steps:
        print(f"{about['run']}: {monitor.messages} messages, never armed: no message gave "
              f"{', '.join(monitor.missing()) or 'a later time'}", file=sys.stderr)
        return 1
    print(f"{about['run']}: {monitor.messages} messages, {monitor.steps} grid steps, "
          + ("no alarm" if first is None else
             f"first alarm at {first.t:.2f} s ({', '.join(first.alarms)})"))
    if monitor.armed and not interrupted and Path(args.source).is_file():
        _log_end(about["run"], monitor)
    return 0


def _log_end(run: str, monitor) -> None:
    """Whether a log that ended with the detector armed ended with the flight: the
    autopilot's last HEARTBEAT says."""
    if monitor.vehicle_armed:
        print(f"{run}: the log stopped mid-flight at {monitor.last_t:.2f} s: the vehicle "
              "was still armed")
    elif monitor.vehicle_armed is None:
        print(f"{run}: the log ends at {monitor.last_t:.2f} s; it holds no HEARTBEAT, so "
              "whether the flight had ended is not known")


def _replay(args: argparse.Namespace) -> int:
    from alfa_bench.evaluation import load_corpus
    from alfa_bench.live import replay

    corpus = load_corpus(args.alfa_dir)
    if args.flight not in set(corpus.manifest["flight"]):
        raise KeyError(f"no flight {args.flight!r} in the corpus at {corpus.processed}")
    flight = corpus.flight(args.flight)
    if args.output.endswith(".tlog"):
        replay.write_tlog(flight, args.output)
        print(f"{args.flight}: written to {args.output}")
        return 0
    from pymavlink import mavutil

    link = mavutil.mavlink_connection(args.output, input=False)
    sent = replay.send(flight, link, speed=args.speed)
    print(f"{args.flight}: {sent} packets sent to {args.output}")
    return 0


def _positive(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be above 0, got {text}")
    return value


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="alfa-bench", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    shown = {"formatter_class": argparse.ArgumentDefaultsHelpFormatter}
    fit = commands.add_parser("fit", help="fit a config run and write its model file",
                              **shown)
    fit.add_argument("run", help="a run of the config (config/config.yaml's methods)")
    fit.add_argument("-o", "--output", required=True, help="the model file to write")
    fit.add_argument("--flights", nargs="+", help="fit on these flights only (by name)")
    fit.add_argument("--alfa-dir", help="the folder holding processed/ (default: ALFA_DIR, "
                                        "the config's alfa_dir, or the download)")
    fit.set_defaults(handler=_fit)
    mon = commands.add_parser("monitor", help="run a model file on a MAVLink link or log",
                              **shown)
    mon.add_argument("model", help="a model file (alfa-bench fit)")
    mon.add_argument("source", help="a .tlog, udpin:0.0.0.0:14550, tcp:host:port, a serial "
                                    "device")
    mon.add_argument("--clock", choices=["log", "link"],
                     help="a log's timestamps, or the messages' own times (default: log "
                          "for a file, link otherwise)")
    mon.add_argument("--every", type=_positive, default=5.0,
                     help="progress every so many s")
    mon.add_argument("--allow-actuators", action="store_true",
                     help="run a model that reads signals ALFA's fault emulation writes")
    mon.set_defaults(handler=_monitor)
    rep = commands.add_parser("replay", help="write a flight as MAVLink to a .tlog or link",
                              **shown)
    rep.add_argument("flight", help="a flight of the corpus, by name")
    rep.add_argument("-o", "--output", required=True,
                     help="a .tlog to write, or a link (udpout:127.0.0.1:14550)")
    rep.add_argument("--speed", type=_positive, default=1.0,
                     help="times the logged pace (inf: as fast as it goes)")
    rep.add_argument("--alfa-dir", help="the folder holding processed/")
    rep.set_defaults(handler=_replay)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.handler(args)
    except ModuleNotFoundError as e:
        if e.name != "pymavlink":
            raise
        print(f"alfa-bench {args.command}: pymavlink is not installed; it comes with the "
              "live extra: pip install \"alfa-bench[live]\"", file=sys.stderr)
        return 1
    except (KeyError, ValueError, OSError) as e:
        # a KeyError's str() is its repr: print the message
        message = e.args[0] if isinstance(e, KeyError) and e.args else e
        print(f"alfa-bench {args.command}: {message}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
