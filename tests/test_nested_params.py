"""A nested selection's config is checked where every run's is, by the dry run
(NestedSelection.check_params): a base that is not registered, a key it does not take
or a candidate that does not build is refused there, naming the base and the key, not
in the run's job."""

import pytest

from alfa_bench.methods import make_detector


@pytest.mark.parametrize("params, said", [
    ({"detector": "residual_bnk"},
     "nested selection of 'residual_bnk': detector: unknown detector 'residual_bnk'"),
    ({"detector": "residual_bank", "grid": {"windw_s": [0.5, 1.0]}},
     "nested selection of 'residual_bank': grid key 'windw_s' is not a hyper-parameter "
     "of 'residual_bank'; it has ['models', 'lags_s', 'window_s'"),
    ({"detector": "residual_bank", "params": {"false_alarms": 0.1}},
     "nested selection of 'residual_bank': params key 'false_alarms' is not a "
     "hyper-parameter"),
    ({"detector": "residual_bank", "grid": {"window_s": 1.0}},
     "nested selection of 'residual_bank': grid key 'window_s' must list its candidate "
     "values"),
    ({"detector": "residual_bank", "grid": {"window_s": [1.0, "2 s"]}},
     "nested selection of 'residual_bank': grid: detector 'residual_bank': parameter "
     "'window_s' must be a number, got '2 s'"),
    ({"detector": "pyod", "params": {"model": "HBOS"},
      "grid": {"params": [{"n_bins": 5}, {"n_binz": 10}]}},
     "nested selection of 'pyod': grid candidate {'params': {'n_binz': 10}}: pyod model "
     "'HBOS' with params {'n_binz': 10} cannot be built"),
], ids=["unknown base", "grid key", "params key", "grid value not a list",
        "candidate value", "candidate's own check"])
def test_a_bad_nested_config_is_refused_by_check_params(params, said):
    nested = make_detector("nested_selection", params)
    with pytest.raises(ValueError) as e:
        nested.check_params()
    assert said in str(e.value), str(e.value)


def test_a_good_nested_config_passes():
    make_detector("nested_selection", {
        "detector": "pyod", "params": {"model": "HBOS"},
        "grid": {"window_s": [1.0, 2.0], "params": [{"n_bins": 5}, {"n_bins": 10}]}}
    ).check_params()
