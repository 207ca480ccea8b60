"""Snakemake script: threshold sweeps of every method from its stored traces, as a
table and a figure."""

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.analysis.sweep import sweep_table
from alfa_bench.data import read_manifest
from alfa_bench.outputs.figures import sweep_figure
from alfa_bench.outputs.provenance import stamp
from alfa_bench.outputs.records import read_records
from alfa_bench.outputs.traces import read_traces
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
sweep = sweep_table(read_records(sm.input.detections),
                    read_traces(sm.input.traces, probes=False), manifest, sm.params.subsets,
                    float(sm.params.deadline_s))
sweep.to_csv(sm.output.csv, index=False)
sweep_figure(sweep, sm.params.subset, sm.output.figure)
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
