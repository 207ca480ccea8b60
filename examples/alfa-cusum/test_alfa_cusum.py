"""The plugin checks itself against alfa-bench's detector contract."""

from alfa_cusum import Cusum

from alfa_bench.methods.contract import parametrize_with_checks


@parametrize_with_checks([Cusum(), Cusum(signal="pitch_error", false_alarm=0.2)])
def test_cusum(detector, check):
    check(detector)
