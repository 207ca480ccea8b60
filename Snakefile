# alfa-bench: online fault detectors compared on the ALFA flights.
# Run: snakemake all --cores 2   (with ALFA_DIR set, or the archive is downloaded)
from snakemake.utils import min_version, validate

from alfa_bench.config import config_problem
from alfa_bench.workflow.preflight import stop

min_version("9.0")


configfile: "config/config.yaml"


# a wrong key or value ends the run on what it is and where, not on the schema
if _problem := config_problem(config, f"{workflow.basedir}/config/schema.yaml",
                              workflow.configfiles, dict(workflow.config_settings.config)):
    stop(_problem)
validate(config, "config/schema.yaml")


report: "report/workflow.rst"


include: "rules/common.smk"
include: "rules/data.smk"
include: "rules/detect.smk"
include: "rules/tables.smk"
include: "rules/sweep.smk"
include: "rules/rerun.smk"
include: "rules/parts.smk"
include: "rules/paper.smk"
include: "rules/inject.smk"
include: "rules/report.smk"


rule all:
    input:
        rules.tables.output,
        rules.index_page.output,
        rules.per_flight.output,
        rules.protocol_steps.output,
        rules.features_learners.output,
        rules.deadline.output,
        rules.leakage.output,
        rules.ceiling.output,
        rules.runtime.output,
        rules.sweep.output,
        rules.flight_figures.output,
        rules.rerun_flights.output,
        expand(rules.run_parts.output.recordings, method=METHODS),
        rules.paper_sources.output,
        rules.detectability.output,
        rules.isolation.output,
        # the PDF where a LaTeX engine (latexmk + pdflatex) is installed
        rules.paper_pdf.output if LATEX else [],
        # last: the run's provenance, with the checksum of everything above
        RUN_FILE,


include: "rules/provenance.smk"
include: "rules/stale.smk"
