import hashlib
import socket
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))

from loopback import make_archive, serve_archive  # noqa: E402
from slurm_cluster import slurm_profile, slurm_unavailable, through_slurm  # noqa: E402
from unavailable import unavailable  # noqa: E402
from workflow_runs import GRID, REPO, made_once, run_workflow  # noqa: E402

from alfa_bench.data import build_manifest, load_flight, resolve_alfa_dir  # noqa: E402
from alfa_bench.data.synthetic import write_corpus, write_flight  # noqa: E402

REAL_ALFA = resolve_alfa_dir()


def pytest_report_header(config):
    if REAL_ALFA and (REAL_ALFA / "processed").is_dir():
        return f"ALFA_DIR={REAL_ALFA}: tests on the real flights will run"
    return ("*** ALFA_DIR is not set or has no processed/: the tests on the real ALFA "
            "flights are SKIPPED ***")


#: the port the corpus's archive is served on, reserved by the session's first process
ARCHIVE_PORT = pytest.StashKey[socket.socket]()


def pytest_configure(config):
    # every worker serves the same archive on one port (SO_REUSEPORT), so that every
    # workflow run of the session has the same config and results compare byte for
    # byte across workers; a bound socket that does not listen keeps the port
    if not hasattr(config, "workerinput"):
        reserved = socket.socket()
        reserved.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        reserved.bind(("127.0.0.1", 0))
        config.stash[ARCHIVE_PORT] = reserved


def pytest_unconfigure(config):
    if ARCHIVE_PORT in config.stash:
        config.stash[ARCHIVE_PORT].close()


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    node.workerinput["archive_port"] = node.config.stash[ARCHIVE_PORT].getsockname()[1]


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
    # the SLURM run's tests last: their worker makes the damaged corpus's run first,
    # while the other makes the reference runs they compare with (tests/scheduling.py)
    items.sort(key=lambda item: "slurm_run" in getattr(item, "fixturenames", ()))


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
def overlay(corpus, tmp_path_factory, pytestconfig):
    """The workflow runs' own config: the small grid, and the corpus served as ALFA's
    archive from a loopback stand-in for KiltHub, on the session's port (every worker's
    the same: runs share a config)."""
    archive = make_archive(corpus)
    port = (pytestconfig.workerinput["archive_port"] if hasattr(pytestconfig, "workerinput")
            else pytestconfig.stash[ARCHIVE_PORT].getsockname()[1])
    with serve_archive(archive, port=port) as (api, _):
        path = tmp_path_factory.mktemp("overlay") / "overlay.yaml"
        path.write_text(yaml.safe_dump({"injection": GRID, "download": {
            "api": api, "file": "processed.zip", "md5": hashlib.md5(archive).hexdigest(),
            "sha256": None, "dest": "resources/alfa"}}))
        yield path


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
    return through_slurm(root / "cluster", work, "rule_detect_wildcards_", lambda env: run_workflow(
        work, None, "--configfile", str(REPO / "config/config.yaml"), str(overlay),
        "--profile", str(profile), target=SLURM_TARGETS, ok=None, quiet=False, env=env))


@pytest.fixture(scope="session")
def runs(overlay, tmp_path_factory):
    """Two runs of the README's first command, each downloading the archive: the
    reference that the workflow tests read and that other ways of running it match,
    and a second, made at the same time, that must give its results byte for byte.
    Made once per session, by the first worker that asks (workflow_runs.made_once)."""
    def run(i):
        d = Path(tempfile.mkdtemp(prefix=f"run{i}", dir=overlay.parent))
        run_workflow(d, None, "--configfile", str(REPO / "config/config.yaml"), str(overlay))
        log = (d / "results/logs/download_alfa.log").read_text()
        assert "downloading processed.zip" in log and "verified processed.zip" in log
        return str(d)

    def make():
        # at once: each run leaves a core idle much of its time
        with ThreadPoolExecutor(2) as pool:
            return list(pool.map(run, range(2)))

    return [Path(d) for d in made_once(tmp_path_factory, "runs", make)]
