"""Generic outlier models as runs (methods/outliers.py): ECOD and COPOD scored row by
row as PyOD scores a row alone, a seed where the library takes one, thresholds from
out-of-sample maxima, and one line from a notebook."""

import numpy as np
import pytest

import alfa_bench as ab
from alfa_bench.data import parse_flight_name
from alfa_bench.methods import make_detector, training_segments
from alfa_bench.methods.outliers import PyODDetector, RiverDetector, alone_ecdf_scores


@pytest.mark.parametrize("kind", ["ECOD", "COPOD"])
def test_a_row_is_scored_as_pyod_scores_it_alone(kind):
    from pyod.models.copod import COPOD
    from pyod.models.ecod import ECOD

    rng = np.random.default_rng(1)
    X = rng.standard_normal((400, 5))
    X[:, 1] = rng.exponential(size=400)
    X[:, 2] = np.round(X[:, 2], 1)                 # ties
    rows = 2.0 * rng.standard_normal((30, 5))
    rows[:4, 2] = X[:4, 2]
    model = {"ECOD": ECOD, "COPOD": COPOD}[kind]().fit(X)
    alone = [model.decision_function(r[None, :])[0] for r in rows]
    sums = np.stack([X.sum(axis=0), (X ** 2).sum(axis=0), (X ** 3).sum(axis=0)])
    np.testing.assert_allclose(alone_ecdf_scores(np.sort(X, axis=0), sums, rows, kind), alone,
                               rtol=1e-12, atol=1e-12)
    # in a batch, PyOD's scores move with the other rows: the reason for the above
    assert not np.allclose(model.decision_function(rows), alone)


def test_a_seed_is_set_only_where_none_was_given():
    assert PyODDetector("IForest")._build().random_state == 0
    assert PyODDetector("IForest", params={"random_state": 7})._build().random_state == 7
    assert RiverDetector()._build().seed == 0
    assert not hasattr(PyODDetector("HBOS")._build(), "random_state")


def test_maxima_are_out_of_sample_by_date_and_cover_every_segment(corpus_flights,
                                                                   monkeypatch):
    d = make_detector("pyod", {"model": "KNN"})
    flights = [f for f in corpus_flights.values() if f.fault is not None]
    segments = training_segments(d, flights, margin_s=1.0)
    date = {s.flight: str(parse_flight_name(s.flight)["date"]) for s in segments}
    assert len(set(date.values())) > 1
    fitted_on, seen = [], []
    fit_model, segment_maxima = type(d).fit_model, type(d).segment_maxima
    monkeypatch.setattr(type(d), "fit_model", lambda self, segs: (
        fitted_on.append({date[s.flight] for s in segs}), fit_model(self, segs))[1])
    monkeypatch.setattr(type(d), "segment_maxima", lambda self, segs: (
        seen.append((fitted_on[-1], {date[s.flight] for s in segs})),
        segment_maxima(self, segs))[1])
    d.fit(segments)
    # every flight's maximum by a model that saw no flight of its date
    assert seen and all(not (trained & held) for trained, held in seen)
    assert fitted_on[-1] == set(date.values())              # the model that scores: all
    channel = d.channels()[0]
    assert sorted(d.maxima_flights_[channel]) == sorted(s.flight for s in segments)
    # in sample, a neighbour model scores its own rows lower: its maxima would be lower
    in_sample = [np.nanmax(d.run(s)[0]) for s in segments]
    assert np.mean(in_sample) < np.mean(d.maxima_[channel])
    assert d.fitted()["model"]["library"] == "pyod" and d.fitted()["model"]["rows"] > 0


def test_any_model_is_one_line_from_a_notebook(corpus, tmp_path):
    from pyod.models.hbos import HBOS

    corpus_ = ab.load_corpus(corpus.parent, cache=tmp_path / "cache")
    mine = HBOS(n_bins=8)
    result = ab.evaluate(PyODDetector(mine, inputs=("roll_error", "pitch_error"),
                                      window_s=1.0), corpus_)
    assert result.records and not hasattr(mine, "decision_scores_")   # a copy was fitted
    assert {r["family"] for r in result.records} == {"generic outlier"}


def test_a_pyod_model_is_found_by_its_class_whatever_its_module():
    """FeatureBagging lives in pyod.models.feature_bagging, not in a module named for it
    in lower case; a class PyOD does not define is named as such, with what to do."""
    from alfa_bench.methods.outliers import pyod_module

    assert pyod_module("FeatureBagging") == "feature_bagging"
    assert pyod_module("IForest") == "iforest"
    with pytest.raises(ValueError, match="no module of pyod.models .* defines a class "
                                         "IsolationTree.*What to do: name a model class"):
        make_detector("pyod", {"model": "IsolationTree"}).check_params()
    make_detector("pyod", {"model": "HBOS"}).check_params()


def test_a_half_space_tree_knows_every_row_it_learned(corpus_flights):
    """river's HalfSpaceTrees scores against its last complete window of rows: the
    window is widened to every row learned, and the fit report lists the model's
    parameters."""
    d = make_detector("river", {"model": "HalfSpaceTrees"})
    flights = [f for f in corpus_flights.values() if f.fault is not None]
    d.fit(training_segments(d, flights, margin_s=1.0))
    assert d.rows_ > 250
    assert d.estimator_.window_size == d.rows_
    # the reference mass at each tree's root: every row learned
    assert all(tree.r_mass == d.rows_ for tree in d.estimator_.trees)
    params = d.fitted()["model"]["params"]
    assert params["window_size"] == d.rows_ and params["height"] == 8 and params["seed"] == 0
    # fewer rows than river's default window: still one window of every row
    few = make_detector("river", {"model": "HalfSpaceTrees", "max_rows": 100})
    few.fit(training_segments(few, flights, margin_s=1.0))
    assert few.rows_ == few.estimator_.window_size == 100
    # a window the run sets is its own
    own = make_detector("river", {"model": "HalfSpaceTrees",
                                  "params": {"window_size": 50}})
    own.fit(training_segments(own, flights, margin_s=1.0))
    assert own.estimator_.window_size == 50


def test_every_pyod_model_class_builds_or_says_why():
    """Each detector class the installed PyOD defines builds by its name, or is refused
    with what it needs (torch, combo, xgboost) or the argument it lacks: never another
    error."""
    import re
    from pathlib import Path

    import pyod.models

    folder = Path(pyod.models.__path__[0])
    names = sorted({m for f in folder.glob("*.py")
                    for m in re.findall(r"^class (\w+)\(BaseDetector\)", f.read_text(), re.M)})
    assert len(names) > 30
    built = []
    for name in names:
        try:
            make_detector("pyod", {"model": name}).check_params()
        except ValueError as e:
            said = str(e)
            assert said.startswith(f"pyod model {name!r}") and "What to do: " in said, said
            assert "needs None" not in said, said
        else:
            built.append(name)
    assert {"IForest", "KNN", "HBOS", "ECOD", "COPOD", "PCA", "LOF", "OCSVM"} <= set(built)
    # a parameter out of range is the parameter's fault, not a missing package's
    with pytest.raises(ValueError, match="with params .*contamination.* takes"):
        make_detector("pyod", {"model": "KNN", "params": {"contamination": 0.9}}).check_params()


def test_a_kept_fit_is_the_fresh_fit_token_and_all(corpus_flights):
    """Two fits made anew learn the same (what keeping a fit rests on), and a model
    taken from MODEL_FITS leaves the detector as a fresh fit does: the same learned
    attributes in the same order, so the same fit token (a state taken under one is
    continued under the other)."""
    from alfa_bench.methods import fits
    from alfa_bench.methods.base import fit_token, learned_digest

    flights = [f for f in corpus_flights.values() if f.fault is not None]
    segments = training_segments(make_detector("pyod", {"model": "HBOS"}), flights, 1.0)
    with fits.fresh_fits():
        one = make_detector("pyod", {"model": "HBOS"}).fit(segments)
    with fits.fresh_fits():
        two = make_detector("pyod", {"model": "HBOS"}).fit(segments)
    assert list(vars(one)) == list(vars(two))
    assert learned_digest(one) == learned_digest(two) and fit_token(one) == fit_token(two)
    fits.MODEL_FITS.clear()
    make_detector("pyod", {"model": "HBOS"}).fit(segments)
    made = len(fits.MODEL_FITS)              # the model, and those of its maxima's folds
    kept = make_detector("pyod", {"model": "HBOS"}).fit(segments)       # every fit kept
    assert len(fits.MODEL_FITS) == made > 0
    assert list(vars(kept)) == list(vars(one))
    assert learned_digest(kept) == learned_digest(one) and fit_token(kept) == fit_token(one)


def test_a_model_built_from_estimator_objects_is_neither_kept_nor_changed(corpus_flights):
    """PyOD's LSCP fits the detectors it is given in place: the run's parameters are
    copied before the build, and a fit whose parameters hold objects is not kept (a
    kept one could change after it was kept)."""
    from pyod.models.lof import LOF

    from alfa_bench.methods import fits

    given = [LOF(n_neighbors=5), LOF(n_neighbors=10)]
    d = PyODDetector(model="LSCP", params={"detector_list": given})
    flights = [f for f in corpus_flights.values() if f.fault is not None]
    fits.MODEL_FITS.clear()
    d.fit(training_segments(d, flights, 1.0))
    assert not len(fits.MODEL_FITS)
    assert not any(hasattr(g, "decision_scores_") for g in given)


class _Drawing:
    """A model whose fit draws from NumPy's global random state, and counts its fits."""
    fits: list = []

    def fit(self, X):
        np.random.random()  # noqa: NPY002
        _Drawing.fits.append(X.shape)
        return self

    def decision_function(self, X):
        return X[:, 0]


def test_warming_fits_a_model_once_and_moves_neither_the_run_nor_the_random_state(
        monkeypatch):
    """The fork server warms every configured run before its jobs (Detector.warm): a
    PyOD model is fitted and scored once per process and class, then dropped; the
    detector is left as built and NumPy's global random state as it was, so a job
    forked after it computes what it computes alone. A nested selection warms its base."""
    from alfa_bench.methods import outliers

    monkeypatch.setattr(outliers, "_WARM", set())
    monkeypatch.setattr(_Drawing, "fits", [])
    d = PyODDetector(model=_Drawing())
    built = dict(vars(d))
    np.random.seed(3)  # noqa: NPY002
    state = np.random.get_state()[1].copy()  # noqa: NPY002
    d.warm()
    d.warm()
    PyODDetector(model=_Drawing()).warm()
    assert len(_Drawing.fits) == 1 and vars(d) == built
    np.testing.assert_array_equal(np.random.get_state()[1], state)  # noqa: NPY002

    warmed = []
    monkeypatch.setattr(PyODDetector, "warm", lambda self: warmed.append(self.get_params()))
    make_detector("nested_selection", {"detector": "pyod", "params": {"model": "HBOS"},
                                       "grid": {"window_s": [1.0, 2.0]}}).warm()
    assert [w["model"] for w in warmed] == ["HBOS"]
