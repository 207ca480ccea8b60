"""Snakemake script: build results/flights.csv from the flights found, and
results/load_failures.csv from those that cannot be read (strict: stop at the first),
with a corpus's logs left out at conversion; write each flight read to the parsed-flight
cache."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

import pandas as pd

from alfa_bench.data import FAILURE_COLUMNS, build_manifest, scan_flights
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
if sm.params.strict:
    manifest = build_manifest(sm.input.processed, cache=sm.output.cache,
                              signals=sm.params.signals)
    failures = pd.DataFrame(columns=[*FAILURE_COLUMNS, "subsets"])
else:
    manifest, failures = scan_flights(sm.input.processed, cache=sm.output.cache,
                                      signals=sm.params.signals)
for path in sm.input.left_out:
    left = pd.read_csv(path, dtype=str, keep_default_na=False)
    failures = pd.concat([failures, pd.DataFrame({
        "flight": left["log"], "stage": "load", "method": "", "file": left["file"],
        "column": left["field"], "line": left["line"], "error": left["error"],
        "subsets": "all"})], ignore_index=True)
manifest.to_csv(sm.output.manifest, index=False)
failures.to_csv(sm.output.failures, index=False)
