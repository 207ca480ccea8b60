# docs/index.png: results/index.html as it opens in headless Chromium; an explicit target
# (it writes a tracked file, and needs Chromium)
rule index_screenshot:
    input:
        "results/index.html",
        code=script_code("index_screenshot"),
    output:
        "docs/index.png",
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/index_screenshot.log",
    script:
        "../scripts/index_screenshot.py"


# docs/report.png, from the report `snakemake --report results/report.html` writes
rule report_screenshot:
    input:
        "results/report.html",
        code=script_code("report_screenshot"),
    output:
        "docs/report.png",
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/report_screenshot.log",
    script:
        "../scripts/report_screenshot.py"
