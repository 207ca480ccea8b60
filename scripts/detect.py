"""Snakemake script: run one configured method over every flight with ground truth;
write its detection records, traces, and the flights it had to exclude."""

import json
import logging
from pathlib import Path

import pandas as pd

from alfa_bench.analysis import detect_all, write_record
from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import run_provenance, stamp
from alfa_bench.analysis.traces import write_trace
from alfa_bench.data import FAILURE_COLUMNS, load_flight, read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
out, traces = Path(sm.output.detections), Path(sm.output.traces)
out.mkdir(parents=True, exist_ok=True)
traces.mkdir(parents=True, exist_ok=True)
flights = {name: load_flight(Path(sm.params.processed) / name)
           for name in manifest.loc[manifest["ground_truth"], "flight"]}
failures = None if sm.params.strict else []
for record, trace in detect_all(sm.wildcards.method, json.loads(sm.params.spec), flights, manifest,
                                dict(sm.params.calibration), failures):
    write_record(record, out / f"{record['flight']}.json")
    write_trace(trace, traces / f"{record['flight']}.npz", record["provenance"])
    logging.info("%s: %s, first alarm %s", record["flight"], record["outcome"],
                 record["first_alarm_s"])
pd.DataFrame(failures or [], columns=FAILURE_COLUMNS).to_csv(out / "failures.csv", index=False)
stamp(out / "failures.csv", run_provenance(sm.config, manifest))
