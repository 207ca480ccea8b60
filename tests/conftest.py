import hashlib
import sys
import tempfile
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))

from loopback import make_archive, serve_archive  # noqa: E402
from slurm_cluster import slurm_profile, slurm_unavailable, through_slurm  # noqa: E402
from unavailable import unavailable  # noqa: E402
from workflow_runs import GRID, REPO, run_workflow  # noqa: E402

from alfa_bench.data import build_manifest, load_flight, resolve_alfa_dir  # noqa: E402
from alfa_bench.data.synthetic import write_corpus, write_flight  # noqa: E402

REAL_ALFA = resolve_alfa_dir()


def pytest_report_header(config):
    if REAL_ALFA and (REAL_ALFA / "processed").is_dir():
        return f"ALFA_DIR={REAL_ALFA}: tests on the real flights will run"
    return ("*** ALFA_DIR is not set or has no processed/: the tests on the real ALFA "
            "flights are SKIPPED ***")


@pytest.hookimpl(tryfirst=True, optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """The workers' share of the suite (tests/scheduling.py), for ``--dist loadgroup``."""
    if config.getvalue("dist") == "loadgroup":
        from scheduling import SharedRunsScheduling

        return SharedRunsScheduling(config, log)
    return None


def pytest_collection_modifyitems(items):
    # the contract of each config run: the registry's checks again, with its parameters
    for item in items:
        if "[config:" in item.nodeid:
            item.add_marker(pytest.mark.slow)


@pytest.fixture(scope="session")
def real_processed() -> Path:
    if not (REAL_ALFA and (REAL_ALFA / "processed").is_dir()):
        unavailable("real ALFA flights not available: set ALFA_DIR to the folder "
                    "holding processed/")
    return REAL_ALFA / "processed"


@pytest.fixture(scope="session")
def corpus(tmp_path_factory) -> Path:
    """A small synthetic corpus; returns its processed/ folder (read-only use)."""
    processed = tmp_path_factory.mktemp("alfa") / "processed"
    write_corpus(processed)
    return processed


@pytest.fixture(scope="session")
def corpus_manifest(corpus):
    """The corpus's manifest (read-only use)."""
    return build_manifest(corpus)


@pytest.fixture(scope="session")
def corpus_flights(corpus, corpus_manifest) -> dict:
    """The corpus's flights, loaded, by name (read-only use)."""
    return {f: load_flight(corpus / f) for f in corpus_manifest["flight"]}


@pytest.fixture
def one_flight(tmp_path) -> Path:
    """A writable synthetic engine-failure flight folder."""
    return write_flight(tmp_path / "processed", "carbonZ_2018-07-18-15-53-31_1_engine_failure",
                        onset_s=50.0)


@pytest.fixture(scope="session")
def overlay(corpus, tmp_path_factory):
    """The workflow runs' own config: the small grid, and the corpus served as ALFA's
    archive from a loopback stand-in for KiltHub (its port fixed, so runs share a config)."""
    archive = make_archive(corpus)
    with serve_archive(archive) as (api, requests):
        path = tmp_path_factory.mktemp("overlay") / "overlay.yaml"
        path.write_text(yaml.safe_dump({"injection": GRID, "download": {
            "api": api, "file": "processed.zip", "md5": hashlib.md5(archive).hexdigest(),
            "sha256": None, "dest": "resources/alfa"}}))
        yield path, requests


#: what the SLURM run makes: a detect job of each kind (numba's kernels, a nested
#: selection, a library's model, a reference) and an aggregate, with the download,
#: manifest, cache and injected grid they need. Each job costs the cluster the same
#: (two Snakemake starts before its script), so more of them test nothing more
SLURM_TARGETS = ["results/detections/rls_arx_zscore", "results/detections/coincidence_nested",
                 "results/detections/pyod_knn", "results/detections/silent",
                 "results/tables/leakage.csv"]


@pytest.fixture(scope="session")
def slurm_run(overlay, tmp_path_factory):
    """The README's first command, on :data:`SLURM_TARGETS`, through a real one-node
    SLURM cluster (tests/slurm_cluster.py) with the project's SLURM profile, one detect
    job killed once while it runs; None where no cluster can be brought up
    (slurm_unavailable)."""
    if slurm_unavailable():
        return None
    root = tmp_path_factory.mktemp("slurm")
    work = root / "run"
    profile = slurm_profile(REPO / "profiles/slurm", root / "profile")
    config, _ = overlay
    return through_slurm(root / "cluster", work, "rule_detect_wildcards_", lambda env: run_workflow(
        work, None, "--configfile", str(REPO / "config/config.yaml"), str(config),
        "--profile", str(profile), target=SLURM_TARGETS, ok=None, quiet=False, env=env))


@pytest.fixture(scope="session")
def runs(overlay):
    """Two runs of the README's first command, each downloading the archive: the
    reference that the workflow tests read and that other ways of running it match,
    and a second that must give its results byte for byte."""
    config, requests = overlay
    dirs = [Path(tempfile.mkdtemp(prefix=f"run{i}", dir=config.parent)) for i in range(2)]
    for d in dirs:
        before = requests.count("/file/1")
        run_workflow(d, None, "--configfile", str(REPO / "config/config.yaml"), str(config))
        assert requests.count("/file/1") == before + 1
    return dirs
