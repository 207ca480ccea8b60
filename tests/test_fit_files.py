"""Fits kept on disk (methods/fits.py: FitFiles, use_files): a fit read back is the fit a
fresh fit makes; a file of another key, of other code or damaged is refused; two
writers leave one whole file; the folder stays within its bound; the contract's refit
check never reads it; a notebook class's code digest is the same in every process; a
detect job run again reads its fits and writes the same records, and its costs."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from config_runs import CONFIG

from alfa_bench.methods import base, fits, labelled_segments, make_detector
from alfa_bench.methods.bench_logistic import BenchLogistic
from alfa_bench.methods.model_files import read_archive, write_archive
from alfa_bench.methods.nested_selection import INNER_FITS
from alfa_bench.workflow.dependencies import module_sources
from alfa_bench.workflow.detect_job import BENCHMARK_COLUMNS, SERVER_ENV
from alfa_bench.workflow.job_costs import COLUMNS


@pytest.fixture
def folder(tmp_path):
    """The stores empty, their fits kept in ``tmp_path`` too; in the process only after."""
    fits.use_files(tmp_path, 10**8, module_sources)
    fits.MODEL_FITS.clear()
    INNER_FITS.clear()
    fits.COUNTS.clear()
    yield tmp_path
    fits.use_files(None)
    fits.MODEL_FITS.clear()
    INNER_FITS.clear()


class Level(base.Detector):
    """A cheap fit kept by :func:`~alfa_bench.methods.fits.kept_fit`: each signal's mean
    level, and how many rows it read."""

    calibrated = True

    def __init__(self, threshold=1.0):
        self.threshold = threshold

    def signals(self):
        return ("pitch_error", "roll_error")

    def fit(self, segments):
        fits.kept_fit(self, segments, self._fit, ("level_", "rows_"))
        return self

    def _fit(self, segments):
        x = np.vstack([s.x for s in segments])
        self.level_, self.rows_ = np.nanmean(x, axis=0), len(x)

    def update(self, x, fresh):
        return np.abs(x[:1] - self.level_[:1])


@pytest.fixture(scope="module")
def segments(corpus_flights):
    return base.training_segments(Level(), list(corpus_flights.values()), 1.0)


def _fit(segments) -> Level:
    return Level().fit(segments)


def _again(segments) -> Level:
    """The fit again, in a process that has kept none: from the folder."""
    fits.MODEL_FITS.clear()
    return _fit(segments)


def _same(fit: base.Detector, fresh: base.Detector) -> None:
    assert list(vars(fit)) == list(vars(fresh))
    assert base.learned_digest(fit) == base.learned_digest(fresh)
    assert base.fit_token(fit) == base.fit_token(fresh)


def test_a_fit_read_back_is_the_fresh_fit(folder, corpus_flights):
    segments = labelled_segments(BenchLogistic(), list(corpus_flights.values()))
    made = BenchLogistic(features=("study",)).fit(segments)
    files = sorted(p.name for p in folder.iterdir())
    assert files and all(n.startswith("model-") and n.endswith(".npz") for n in files)
    assert fits.COUNTS["made"] == len(files) and not fits.COUNTS["read"]
    fits.MODEL_FITS.clear()
    read = BenchLogistic(features=("study",)).fit(segments)
    assert fits.COUNTS["read"] == len(files) and fits.COUNTS["made"] == len(files)
    with fits.fresh_fits():
        fresh = BenchLogistic(features=("study",)).fit(segments)
    for fit in (read, made):
        _same(fit, fresh)
        np.testing.assert_array_equal(fit.coef_, fresh.coef_)


def test_the_inner_fits_of_a_nested_run_come_back_as_they_were_made(folder,
                                                                   corpus_flights):
    spec = CONFIG["methods"]["residual_bank_nested"]
    nested = make_detector(spec["detector"], {**spec["params"],
                                              "grid": {"false_alarm": [0.05, 0.2]}})
    training = labelled_segments(nested, list(corpus_flights.values()))
    made = base.clone(nested).fit(training)
    assert any(p.name.startswith("inner-") for p in folder.iterdir())
    INNER_FITS.clear()
    read = base.clone(nested).fit(training)
    assert fits.COUNTS["read"] > 0
    assert read.fitted() == made.fitted() and base.fit_token(read) == base.fit_token(made)


def _rewrite(path, change) -> None:
    """Write ``path`` again, its document changed by ``change``, with a valid digest."""
    body, arrays = read_archive(path)
    change(body)
    write_archive(path, body, [arrays[f"a{i}"] for i in range(len(arrays))])


@pytest.mark.parametrize("part", ["key", "modules", "versions", "store"])
def test_a_file_of_another_key_is_refused_and_fitted_again(folder, segments, part, caplog):
    """A file whose document differs from the key's in any part, its digest intact (a
    file written by other code, other library versions, or renamed), is refused."""
    made = _fit(segments)

    def change(body):
        document = body["document"]
        if part == "key":
            document["key"]["params"]["threshold"] = 7.0
        elif part == "store":
            document["store"] = "inner"
        else:
            document[part] = "other"

    for path in folder.iterdir():
        _rewrite(path, change)
    fits.COUNTS.clear()
    again = _again(segments)
    assert not fits.COUNTS["read"] and fits.COUNTS["refused"] == 1
    assert f"written for another {part}" in caplog.text
    _same(again, made)


def test_a_damaged_file_is_refused(folder, segments, caplog):
    made = _fit(segments)
    for path in folder.iterdir():
        data = bytearray(path.read_bytes())
        data[len(data) // 2] ^= 0xFF
        path.write_bytes(bytes(data))
    fits.COUNTS.clear()
    again = _again(segments)
    assert not fits.COUNTS["read"] and fits.COUNTS["refused"] == 1
    assert "fit refused" in caplog.text
    _same(again, made)


def test_two_writers_leave_one_whole_file_and_the_bound_evicts_the_least_used(folder):
    """A fit written twice (two jobs at once) is one whole file, never a temporary one,
    and the same bytes each time (two runs leave the same folder); beyond the bound,
    the file least recently read or written goes first."""
    store = fits.KeptFits(4, "model")
    keys = [fits.FitKey({"module": __name__, "class": "X", "source": "s", "params": {},
                         "data": [i]}) for i in range(3)]
    fit = {"w_": np.arange(2000.0)}
    store.put(keys[0], fit)
    once = next(folder.iterdir()).read_bytes()
    store.put(keys[0], fit)
    assert [p.name for p in folder.iterdir()] == [f"model-{keys[0]}.npz"]
    assert next(folder.iterdir()).read_bytes() == once       # the same bytes, undated
    size = next(folder.iterdir()).stat().st_size
    fits.use_files(folder, int(2.5 * size), module_sources)
    store.put(keys[1], fit)
    first = fits._FILES.path("model", keys[0])
    os.utime(first, (1, 1))                           # long unused ...
    store.clear()
    assert store.get(keys[0]) is not None             # ... read now: the last used
    store.put(keys[2], fit)
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        f"model-{k}.npz" for k in (keys[0], keys[2]))


def test_the_refit_check_neither_reads_nor_writes_the_folder(folder, segments):
    _fit(segments)
    written = {p: p.stat().st_mtime_ns for p in folder.iterdir()}
    fits.COUNTS.clear()
    with fits.fresh_fits():
        _fit(segments)
    assert not fits.COUNTS["read"] and fits.COUNTS["made"] > 0
    assert {p: p.stat().st_mtime_ns for p in folder.iterdir()} == written


def test_what_is_not_arrays_and_json_stays_in_the_process(folder):
    """A library's estimator object (as an outlier model's ``estimator_``), or the
    CalibrationError an inner fit failed with, is kept in the process only."""
    store = fits.KeptFits(4, "model")
    key = fits.FitKey({"module": __name__, "class": "X", "source": "s", "params": {},
                       "data": []})
    estimator = object()
    store.put(key, {"center_": np.zeros(3), "estimator_": estimator})
    store.put(fits.FitKey({**key.document, "data": [1]}), base.CalibrationError("short"))
    assert fits.COUNTS["unstorable"] == fits.COUNTS["made"] == 2
    assert not list(folder.iterdir())
    assert store.get(key)["estimator_"] is estimator


NOTEBOOK = '''
from alfa_bench.methods.base import Detector, source_digest


class Fixed(Detector):
    calibrated = True
    channels_of = frozenset({"roll", "pitch", "yaw"})

    def signals(self):
        return ("pitch_error",)

    def update(self, x, fresh):
        scale = lambda v: 2 * v
        return scale(x[:1]) if x[0] not in {"a", "b", "c"} else x[:1]


print(source_digest(Fixed, package=True))
'''


def test_a_notebook_class_has_the_same_code_digest_in_every_process():
    """A class without a source file (run as ``__main__`` from a string) is digested by
    its compiled code: the same in two processes, whatever their string hashes; and
    another constant is another digest."""
    def digest(source: str, seed: str) -> str:
        return subprocess.run([sys.executable, "-c", source], check=True, text=True,
                              capture_output=True,
                              env={**os.environ, "PYTHONHASHSEED": seed}).stdout.strip()

    first, second = digest(NOTEBOOK, "1"), digest(NOTEBOOK, "2")
    assert first == second and len(first) == 32
    assert digest(NOTEBOOK.replace("2 * v", "3 * v"), "1") != first


def test_a_key_names_its_document():
    key = fits.FitKey({"module": "m", "params": {"a": (1, 2)}})
    assert key == fits.FitKey(json.loads(json.dumps(key.document)))
    assert key != fits.FitKey({"module": "m", "params": {"a": [1, 3]}})


def _job(work, run: str, out, fits_folder) -> dict:
    """The detect job of ``run`` over the workflow run in ``work``'s flights, alone in
    its process, writing to ``out``: its benchmark row."""
    config = next((work / ".snakemake/alfa-bench").glob("config-*.json"))
    out.mkdir(parents=True)
    paths = {a: out / a for a in ("detections", "traces", "panels")}
    subprocess.run([sys.executable, "-m", "alfa_bench.workflow.detect_job", run,
                    "--manifest", str(work / "results/flights.csv"),
                    "--cache", str(work / "results/cache"), "--config", str(config),
                    *(f"--{a}={p}" for a, p in paths.items()),
                    "--benchmark", str(out / "job.tsv"), "--log", str(out / "job.log"),
                    "--fits", str(fits_folder)],
                   check=True, env={k: v for k, v in os.environ.items() if k != SERVER_ENV})
    names, values = (line.split("\t") for line in (out / "job.tsv").read_text().splitlines())
    return dict(zip(names, values, strict=True))


@pytest.mark.workflow
def test_a_jobs_rerun_reads_its_fits_and_writes_the_same_records_and_costs(runs, tmp_path):
    """The workflow's job keeps its fits in the folder it is given; the job again, in a
    new process, reads them instead of fitting, and writes the records the workflow
    wrote. Its benchmark keeps Snakemake's columns, then the cost table's."""
    work, folder = runs[0], tmp_path / "fits"
    assert list((work / "results/fits").glob("inner-*.npz"))     # the workflow's own
    first = _job(work, "residual_bank_nested", tmp_path / "first", folder)
    again = _job(work, "residual_bank_nested", tmp_path / "again", folder)
    assert list(first)[:4] == list(BENCHMARK_COLUMNS)
    assert list(first)[4:] == list(COLUMNS)
    assert int(first["fits_made"]) > int(again["fits_made"]) and int(again["fits_read"]) > 0
    assert int(first["fits_read"]) == 0 and float(first["fitting_s"]) > 0
    assert all(float(first[c]) > 0 for c in ("scoring_s", "reading_s", "writing_s"))
    assert "read from" in (tmp_path / "again/job.log").read_text()
    for name in ("first", "again"):
        made = tmp_path / name / "detections"
        records = sorted(p.name for p in made.glob("*.json"))
        assert records == sorted(p.name for p in (
            work / "results/detections/residual_bank_nested").glob("*.json"))
        for record in records:
            assert _outcome(made / record) == _outcome(
                work / "results/detections/residual_bank_nested" / record), record


def _outcome(path) -> dict:
    """A record but its provenance (which names the files it was written to)."""
    return {k: v for k, v in json.loads(path.read_text()).items() if k != "provenance"}
