rule tables:
    input:
        manifest="data/flights.csv",
        detections=expand("results/detections/{method}", method=METHODS),
    output:
        summary="results/tables/summary.csv",
        by_fault="results/tables/by_fault.csv",
        summary_md="results/tables/summary.md",
        by_fault_md="results/tables/by_fault.md",
        comparison="results/tables/comparison.csv",
        comparison_md="results/tables/comparison.md",
    params:
        subsets=config["subsets"],
    log:
        "results/logs/tables.log",
    script:
        "../scripts/tables.py"
