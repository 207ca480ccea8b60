# alfa-bench: online fault detectors compared on the ALFA flights.
# Run: snakemake all --cores 2   (with ALFA_DIR set, or the archive is downloaded)
from snakemake.utils import min_version, validate

min_version("9.0")


configfile: "config/config.yaml"


validate(config, "config/schema.yaml")


include: "rules/common.smk"
include: "rules/data.smk"
include: "rules/detect.smk"
include: "rules/tables.smk"


rule all:
    input:
        rules.tables.output,
