"""Snakemake script: the sweep and detection-time figures."""

from alfa_bench.analysis import read_records
from alfa_bench.analysis.figures import detection_time_figure, sweep_figure
from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import read_table, run_provenance, stamp
from alfa_bench.data import read_manifest, subset_flights

sm = snakemake  # noqa: F821
log_to(sm.log[0])
subset = sm.params.subset
manifest = read_manifest(sm.input.manifest)
records = read_records(sm.input.detections)
sweep_figure(read_table(sm.input.sweep), subset, sm.output.sweep)
detection_time_figure(records, subset_flights(manifest, subset), sm.output.detection_time)
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
