import shutil

# The manuscript's inputs: every file it includes is written by the workflow.
PAPER_INPUTS = [
    *rules.tables.output,
    *rules.per_flight.output,
    *rules.features_learners.output,
    *rules.deadline.output,
    *rules.leakage.output,
    "results/tables/sweep.csv",
    "results/figures/sweep.png",
    "results/figures/detection_time.png",
]
LATEX = shutil.which("latexmk")
# the manuscript's sources live beside the Snakefile, whatever the working directory
PAPER_DIR = Path(workflow.basedir) / "paper"


rule paper_sources:
    input:
        PAPER_INPUTS,
        manifest="results/flights.csv",
        comparison="results/tables/comparison.csv",
        by_fault="results/tables/by_fault.csv",
        per_flight="results/tables/per_flight.csv",
        detectability="results/tables/detectability.csv",
        isolation_sensors="results/tables/isolation_sensors.csv",
        isolation_actuators="results/tables/isolation_actuators.csv",
        sweep="results/tables/sweep.csv",
        leakage="results/tables/leakage.csv",
        ceiling="results/tables/ceiling.csv",
        calibration="results/tables/calibration.csv",
        against_study="results/tables/against_study.csv",
        left_out="results/tables/left_out.csv",
        tex=PAPER_DIR / "paper.tex",
        markdown=PAPER_DIR / "paper.template.md",
        code=script_code("paper"),
    output:
        macros="paper/build/results.tex",
        markdown=report("paper/build/paper.md", caption="../report/paper.rst",
                        category="Manuscript"),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/paper_sources.log",
    benchmark:
        "results/benchmarks/paper_sources.tsv"
    script:
        "../scripts/paper.py"


rule paper_pdf:
    input:
        PAPER_INPUTS,
        "paper/build/results.tex",
        tex=PAPER_DIR / "paper.tex",
    output:
        "paper/build/paper.pdf",
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/paper_pdf.log",
    shell:
        # a fixed date in the PDF, so the same sources give the same bytes
        "SOURCE_DATE_EPOCH=0 FORCE_SOURCE_DATE=1 latexmk -pdf -interaction=nonstopmode -halt-on-error -outdir=paper/build "
        "{input.tex} > {log} 2>&1"
