import json

# The fits the detect jobs share (methods/fits.py), across jobs, runs and re-runs, bounded
# by the config's fits: max_mb. No rule's output: a fit read from it is the fit a job
# would make, so no result depends on which fits it holds.
FITS = "results/fits"


# The reference rows (role: reference) on the real flights only: they speak of ALFA's
# metric and emulation, not of sensors.
rule detect_reference:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        code=lambda w: detector_code(w.method),
    output:
        detections=directory("results/detections/{method}"),
        traces=directory("results/traces/{method}"),
        # the run's panel of each flight's figure, which flight_figures stacks
        panels=directory("results/figure_parts/{method}"),
        # the job's own time: a fork of the server's counts from the fork
        benchmark="results/benchmarks/detect/{method}.tsv",
    params:
        # what re-runs the job when it changes (the job reads it from the config file);
        # canonical JSON, so that only a changed value (not a reordered key) re-runs it
        spec=lambda w: json.dumps(config["methods"][w.method], sort_keys=True),
        calibration=config["calibration"],
        stability=config["stability"],
        strict=config["strict"],
        injected="",
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/detect/{method}.log",
    wildcard_constraints:
        method="|".join(REFERENCES),
    shell:
        DETECT_JOB + f" --fits {FITS}"


# Every other run, on the real flights and on the injected sensor-fault grid in one job
# (one fit per fold for both): a changed method re-runs only its own job.
use rule detect_reference as detect with:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        code=lambda w: detector_code(w.method),
        injected="results/injected/flights.csv",
    output:
        detections=directory("results/detections/{method}"),
        traces=directory("results/traces/{method}"),
        panels=directory("results/figure_parts/{method}"),
        benchmark="results/benchmarks/detect/{method}.tsv",
        injected=directory("results/injected/detections/{method}"),
    params:
        spec=lambda w: json.dumps(config["methods"][w.method], sort_keys=True),
        calibration=config["calibration"],
        stability=config["stability"],
        strict=config["strict"],
        injection=config["injection"],
        injected=lambda w, input, output: (
            f"--injected {shlex.quote(input.injected)} --injected-out "
            f"{shlex.quote(output.injected)} --processed {shlex.quote(INJECTED_PROCESSED)}"),
    wildcard_constraints:
        method="|".join(DETECTORS),
