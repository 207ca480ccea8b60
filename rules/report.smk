# docs/report.png, from the report `snakemake --report results/report.html` writes
rule report_screenshot:
    input:
        "results/report.html",
    output:
        "docs/report.png",
    log:
        "results/logs/report_screenshot.log",
    script:
        "../scripts/report_screenshot.py"
