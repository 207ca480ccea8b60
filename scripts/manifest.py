"""Snakemake script: build results/flights.csv from the flights found, and
results/load_failures.csv from those that cannot be read (strict: stop at the first);
write each flight read to the parsed-flight cache."""

import pandas as pd

from alfa_bench.data import FAILURE_COLUMNS, build_manifest, scan_flights
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
if sm.params.strict:
    manifest = build_manifest(sm.input.processed, cache=sm.output.cache)
    failures = pd.DataFrame(columns=[*FAILURE_COLUMNS, "subsets"])
else:
    manifest, failures = scan_flights(sm.input.processed, cache=sm.output.cache)
manifest.to_csv(sm.output.manifest, index=False)
failures.to_csv(sm.output.failures, index=False)
