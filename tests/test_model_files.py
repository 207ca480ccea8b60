"""Model files (methods/model_files.py, alfa_bench/models.py): a fitted run saved and
loaded scores as the fit it was, and a file that is damaged, altered, of another
version or of an unknown detector is refused without running anything from it."""

import io
import json
import zipfile

import numpy as np
import pytest

import alfa_bench as ab
from alfa_bench.data import sample
from alfa_bench.methods import model_files
from alfa_bench.methods.model_files import ModelFileError, load_model, save_model

#: the runs issue 49 takes live, and one of each other kind of state
RUNS = ["residual_logistic_published_date", "coincidence", "residual_bank", "bench_logistic",
        "coincidence_nested", "silent"]


@pytest.fixture(scope="module")
def local(corpus, tmp_path_factory):
    return ab.load_corpus(corpus.parent, cache=tmp_path_factory.mktemp("cache"))


@pytest.fixture(scope="module")
def saved(local, tmp_path_factory):
    folder = tmp_path_factory.mktemp("models")
    return {run: ab.save_run(run, local, folder / f"{run}.abm") for run in RUNS}


@pytest.mark.parametrize("run", RUNS)
def test_a_loaded_model_scores_as_the_fit_it_was(run, local, saved):
    detector, about = load_model(saved[run])
    fresh = ab.fit_run(run, local)
    assert about["run"] == run and not about["reads_actuators"]
    assert set(about["data"]) == set(local.flights)
    assert about["signals"] == list(fresh.signals())
    for name in list(local.flights)[:3]:
        s = sample(local.flight(name), fresh.signals(), fresh.rate_hz)
        np.testing.assert_array_equal(detector.run(s)[0], fresh.run(s)[0])
        np.testing.assert_array_equal(detector.thresholds(), fresh.thresholds())


def _members(path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as z:
        return {n: z.read(n) for n in z.namelist()}


def _write(path, members: dict[str, bytes]) -> None:
    with zipfile.ZipFile(path, "w") as z:
        for n, b in members.items():
            z.writestr(n, b)


def _document(members: dict[str, bytes]) -> dict:
    return json.loads(np.load(io.BytesIO(members["model.json.npy"])).tobytes())


def _with_document(members: dict[str, bytes], body: dict, resign: bool) -> dict[str, bytes]:
    """``members`` with the document ``body``; its SHA-256 recomputed if ``resign``."""
    out = dict(members)
    doc = json.dumps(body).encode()
    out["model.json.npy"] = _npy(np.frombuffer(doc, np.uint8))
    if resign:
        arrays = {n[:-4]: np.load(io.BytesIO(b)) for n, b in members.items()
                  if n.startswith("a")}
        digest = model_files._digest(doc, arrays)
        out["sha256.npy"] = _npy(np.frombuffer(digest.encode(), np.uint8))
    return out


def _npy(a: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, a)
    return buffer.getvalue()


def test_an_altered_file_is_refused_by_its_digest(saved, tmp_path):
    members = _members(saved["residual_bank"])
    array = next(n for n in members if n.startswith("a"))
    a = np.load(io.BytesIO(members[array]))
    a.flat[0] += 1.0
    _write(tmp_path / "array.abm", {**members, array: _npy(a)})
    with pytest.raises(ModelFileError, match="does not match its SHA-256"):
        load_model(tmp_path / "array.abm")
    body = _document(members)
    body["run"] = "something_else"
    _write(tmp_path / "doc.abm", _with_document(members, body, resign=False))
    with pytest.raises(ModelFileError, match="does not match its SHA-256"):
        load_model(tmp_path / "doc.abm")


def test_a_byte_flipped_in_the_archive_is_a_named_error(saved, tmp_path):
    data = bytearray(saved["residual_bank"].read_bytes())
    data[len(data) // 2] ^= 0xFF
    (tmp_path / "flip.abm").write_bytes(bytes(data))
    with pytest.raises(ModelFileError, match="flip.abm: (not a readable model file|its "
                                             "content does not match)"):
        load_model(tmp_path / "flip.abm")


def test_a_state_altered_and_signed_again_is_not_the_fit_saved(saved, tmp_path):
    members = _members(saved["coincidence"])
    body = _document(members)
    body["model"]["state"]["dict"]["scale_"]["dict"]["accel_x_drop"] *= 2
    _write(tmp_path / "state.abm", _with_document(members, body, resign=True))
    with pytest.raises(ModelFileError, match="does not give the fit saved"):
        load_model(tmp_path / "state.abm")


def test_a_state_that_is_not_learned_is_refused(saved, tmp_path):
    """Only learned attributes (ending in ``_``) are set from a file: not a class
    attribute such as the grid rate, which no digest covers."""
    members = _members(saved["coincidence"])
    body = _document(members)
    body["model"]["state"]["dict"]["rate_hz"] = 1000.0
    _write(tmp_path / "rate.abm", _with_document(members, body, resign=True))
    with pytest.raises(ModelFileError, match="'rate_hz' is not a learned attribute"):
        load_model(tmp_path / "rate.abm")


def test_another_version_or_an_unknown_detector_is_refused(saved, tmp_path, monkeypatch):
    members = _members(saved["coincidence"])
    body = _document(members)
    body["model"]["detector"] = "no_such_detector"
    _write(tmp_path / "unknown.abm", _with_document(members, body, resign=True))
    with pytest.raises(ModelFileError, match="'no_such_detector' is not registered"):
        load_model(tmp_path / "unknown.abm")
    monkeypatch.setattr(model_files, "_version", lambda: "9.9.9")
    with pytest.raises(ModelFileError, match="written by alfa-bench .* this is 9.9.9"):
        load_model(saved["coincidence"])


def test_a_detector_fitted_by_other_code_loads_and_says_so(saved, tmp_path, caplog):
    """Each detector in a file records its class's code digest; one whose code here is
    not that code (edited since the fit) still loads, and the load names it, in a
    warning and in ``code_changed``."""
    for run in ("coincidence", "coincidence_nested"):
        with caplog.at_level("WARNING"):
            assert load_model(saved[run])[1]["code_changed"] == []
        assert "not the code that fitted it" not in caplog.text
    members = _members(saved["coincidence_nested"])
    body = _document(members)
    assert body["model"]["source"] and body["model"]["state"]["dict"]["base_"]["source"]
    body["model"]["state"]["dict"]["base_"]["source"] = "0" * 32     # the base edited
    _write(tmp_path / "edited.abm", _with_document(members, body, resign=True))
    with caplog.at_level("WARNING"):
        detector, about = load_model(tmp_path / "edited.abm")
    assert about["code_changed"] == ["coincidence"]
    assert "edited.abm: the code of coincidence is not the code that fitted it" in caplog.text
    assert detector.fitted() == load_model(saved["coincidence_nested"])[0].fitted()


class _Marker:
    """Unpickled, it writes a file: what a bare pickle would run on load."""

    path = None

    def __reduce__(self):
        return (open, (str(self.path), "w"))


def test_a_pickle_inside_is_never_run(saved, tmp_path):
    _Marker.path = tmp_path / "ran"
    members = _members(saved["silent"])
    buffer = io.BytesIO()
    np.save(buffer, np.array([_Marker()], dtype=object), allow_pickle=True)
    _write(tmp_path / "pickle.abm", {**members, "a0.npy": buffer.getvalue()})
    with pytest.raises(ModelFileError, match="not a readable model file"):
        load_model(tmp_path / "pickle.abm")
    assert not _Marker.path.exists()
    (tmp_path / "text.abm").write_text("not a zip")
    with pytest.raises(ModelFileError, match="not a readable model file"):
        load_model(tmp_path / "text.abm")


def test_a_state_that_is_not_arrays_and_json_is_refused_by_name(local, tmp_path):
    d = ab.fit_run("pyod_hbos", local)
    with pytest.raises(ModelFileError, match=r"estimator_: a HBOS cannot be saved"):
        save_model(d, tmp_path / "hbos.abm", run="pyod_hbos")
    ran = ab.fit_run("coincidence", local)
    ran.run(sample(local.flight(next(iter(local.flights))), ran.signals(), ran.rate_hz))
    with pytest.raises(ModelFileError, match="has run or changed since its fit"):
        save_model(ran, tmp_path / "ran.abm", run="coincidence")


def test_the_command_fits_a_run_and_names_what_it_cannot(corpus, tmp_path, monkeypatch,
                                                         capsys):
    from alfa_bench import cli

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    out = tmp_path / "coincidence.abm"
    assert cli.main(["fit", "coincidence", "-o", str(out), "--alfa-dir",
                     str(corpus.parent)]) == 0
    assert load_model(out)[1]["run"] == "coincidence"
    assert "written to" in capsys.readouterr().out
    assert cli.main(["fit", "no_such_run", "-o", str(out), "--alfa-dir",
                     str(corpus.parent)]) == 1
    assert "no run 'no_such_run' in the config" in capsys.readouterr().err
