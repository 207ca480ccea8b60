"""Snakemake script: run one configured method over every flight with ground truth."""

import logging
from pathlib import Path

from alfa_bench.analysis import detection_record, write_record
from alfa_bench.analysis.logs import log_to
from alfa_bench.data import load_flight, read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
out = Path(sm.output[0])
out.mkdir(parents=True, exist_ok=True)
for row in manifest[manifest["ground_truth"]].itertuples():
    flight = load_flight(Path(sm.params.processed) / row.flight)
    record = detection_record(sm.wildcards.method, dict(sm.params.spec), flight, row.sha256)
    write_record(record, out / f"{row.flight}.json")
    logging.info("%s: %s, first alarm %s", row.flight, record["outcome"], record["first_alarm_s"])
