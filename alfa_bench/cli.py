"""``alfa-bench``: the commands that take a detector out of the benchmark.

``alfa-bench fit RUN -o FILE`` fits the config run ``RUN`` on every flight with ground
truth (or ``--flights``) of the ALFA copy the workflow finds (``ALFA_DIR``, the config's
``alfa_dir``, or the download; ``--alfa-dir`` overrides) and writes its model file
(:func:`alfa_bench.models.save_run`).
"""

from __future__ import annotations

import argparse
import logging
import sys


def _fit(args: argparse.Namespace) -> int:
    from alfa_bench.evaluation import load_corpus
    from alfa_bench.models import save_run

    corpus = load_corpus(args.alfa_dir)
    path = save_run(args.run, corpus, args.output, args.flights)
    flights = len(args.flights) if args.flights else len(corpus.flights)
    print(f"{args.run}: fitted on {flights} flights, written to {path}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="alfa-bench", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    fit = commands.add_parser("fit", help="fit a config run and write its model file")
    fit.add_argument("run", help="a run of the config (config/config.yaml's methods)")
    fit.add_argument("-o", "--output", required=True, help="the model file to write")
    fit.add_argument("--flights", nargs="+", help="fit on these flights only (by name)")
    fit.add_argument("--alfa-dir", help="the folder holding processed/ (default: ALFA_DIR, "
                                        "the config's alfa_dir, or the download)")
    fit.set_defaults(handler=_fit)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.handler(args)
    except (KeyError, ValueError, OSError) as e:
        print(f"alfa-bench {args.command}: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
