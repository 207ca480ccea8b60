"""Snakemake script: the runs of stability.refit fitted again on the first calibration
pools of each fold, beside the same pools' thresholds alone."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.analysis.stability import refit_first_alarms, refit_table
from alfa_bench.data import load_cached, read_manifest
from alfa_bench.outputs.provenance import stamp
from alfa_bench.outputs.records import read_records
from alfa_bench.outputs.tables import refit_markdown
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
flights = load_cached(sm.input.cache, manifest)
refits = sm.params.stability["refit"]["pools"]
refitted = {m: refit_first_alarms(spec, flights, manifest, dict(sm.params.calibration),
                                  sm.params.stability, refits)
            for m, spec in sm.params.specs.items()}
table = refit_table(read_records(sm.input.detections), refitted, manifest,
                    sm.params.subsets, float(sm.params.deadline_s))
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(refit_markdown(table))
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
