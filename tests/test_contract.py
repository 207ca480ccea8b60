"""The streaming contract, checked for every registered detector and configured run.

A new method is picked up here by its registry line alone. The checks themselves are
public (:mod:`alfa_bench.methods.contract`), so that a plugin's own tests run the same
ones (``examples/alfa-cusum``).
"""

from config_runs import CONFIG

from alfa_bench.methods import REGISTRY, make_detector
from alfa_bench.methods.contract import parametrize_with_checks

RUNS = {name: (spec["detector"], spec.get("params", {})) for name, spec in
        CONFIG["methods"].items()}
CASES = {f"registry:{n}": make_detector(n) for n in REGISTRY}
# a configured run that is a registered detector with its defaults is checked once
for _name, _run in RUNS.items():
    _made = make_detector(*_run)
    if not any(type(d) is type(_made) and d.get_params() == _made.get_params()
               for d in CASES.values()):
        CASES[f"config:{_name}"] = _made


@parametrize_with_checks(CASES)
def test_contract(detector, check):
    check(detector)


def test_a_non_causal_detector_is_only_ever_a_reference_row():
    """A detector that knows the future (the end-of-flight reference) must be a
    reference row in every configured run: it is never ranked."""
    for name, (detector, _) in RUNS.items():
        if not REGISTRY[detector].causal:
            assert CONFIG["methods"][name].get("role") == "reference", name
