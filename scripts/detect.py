"""Snakemake script: run one configured method over every flight with ground truth."""

import logging
from pathlib import Path

from alfa_bench.analysis import detect_all, write_record
from alfa_bench.analysis.logs import log_to
from alfa_bench.data import load_flight, read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
out = Path(sm.output[0])
out.mkdir(parents=True, exist_ok=True)
flights = {name: load_flight(Path(sm.params.processed) / name)
           for name in manifest.loc[manifest["ground_truth"], "flight"]}
for record in detect_all(sm.wildcards.method, dict(sm.params.spec), flights, manifest,
                         dict(sm.params.calibration)):
    write_record(record, out / f"{record['flight']}.json")
    logging.info("%s: %s, first alarm %s", record["flight"], record["outcome"],
                 record["first_alarm_s"])
