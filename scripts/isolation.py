"""Snakemake script: isolation confusion matrices, of the injected sensor faults (which
sensor) and of ALFA's actuator faults (which actuator class), merged from each run's
part."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.isolation import isolation_markdown
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.parts import read_parts
from alfa_bench.outputs.provenance import stamp
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
real, injected = read_manifest(sm.input.manifest), read_manifest(sm.input.injected)
for parts, truth, csv, md in [
        (sm.input.sensors, "sensor", sm.output.sensors_csv, sm.output.sensors_md),
        (sm.input.actuators, "actuator", sm.output.actuators_csv, sm.output.actuators_md)]:
    rows = read_parts(parts)
    rows.to_csv(csv, index=False)
    Path(md).write_text(isolation_markdown(rows, truth))
    prov = (run_provenance(sm.config, injected, real) if truth == "sensor"
            else run_provenance(sm.config, real))
    stamp(csv, prov)
    stamp(md, prov)
