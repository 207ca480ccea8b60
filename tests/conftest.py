import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from alfa_bench.data import build_manifest, load_flight, resolve_alfa_dir  # noqa: E402
from alfa_bench.data.synthetic import write_corpus, write_flight  # noqa: E402

REAL_ALFA = resolve_alfa_dir()


def pytest_report_header(config):
    if REAL_ALFA and (REAL_ALFA / "processed").is_dir():
        return f"ALFA_DIR={REAL_ALFA}: tests on the real flights will run"
    return ("*** ALFA_DIR is not set or has no processed/: the tests on the real ALFA "
            "flights are SKIPPED ***")


@pytest.fixture(scope="session")
def real_processed() -> Path:
    if not (REAL_ALFA and (REAL_ALFA / "processed").is_dir()):
        pytest.skip("real ALFA flights not available: set ALFA_DIR to the folder "
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
