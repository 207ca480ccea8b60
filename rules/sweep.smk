# every run's sweep, from its part (rules/parts.smk)
rule sweep:
    # among the jobs ready, first: the paper waits on it
    priority: 2
    input:
        manifest="results/flights.csv",
        parts=expand("results/parts/sweep/{method}.csv", method=METHODS),
        code=script_code("sweep"),
    output:
        # not in the report: 7.6 MB of rows no reader reads there (the figure is)
        csv="results/tables/sweep.csv",
        figure=report("results/figures/sweep.png", caption="../report/sweep.rst",
                      category="Threshold sweeps"),
    params:
        subsets=SUBSETS,
        subset=PRIMARY,
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/sweep.log",
    benchmark:
        "results/benchmarks/sweep.tsv"
    script:
        "../scripts/sweep.py"


# each method's panels, drawn by its detect job, stacked per flight
rule flight_figures:
    input:
        manifest="results/flights.csv",
        detections=expand("results/detections/{method}", method=METHODS),
        panels=expand("results/figure_parts/{method}", method=METHODS),
        code=script_code("flight_figures"),
    output:
        report(directory("results/figures/flights"), patterns=["{flight}.png"],
               caption="../report/flight.rst", category="Flights",
               subcategory=figure_fault_class),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/flight_figures.log",
    benchmark:
        "results/benchmarks/flight_figures.tsv"
    script:
        "../scripts/flight_figures.py"


# The README shows a tracked copy of the sweep, refreshed by this explicit target
# (`snakemake readme_figure`), never by `all`: a run leaves the work tree as it was.
rule readme_figure:
    input:
        "results/figures/sweep.png",
    output:
        "paper/figures/sweep.png",
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/readme_figure.log",
    shell:
        "cp {input} {output} 2> {log}"
