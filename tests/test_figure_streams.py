"""The throughput figure's rates on worker processes (flipkit.figures.streams): the rows of
sweep_rates, in its order, whatever the process."""

from flipkit.figures.streams import throughput_sweep
from flipkit.planning.kitchen.cpsat import MotionTimes
from flipkit.planning.kitchen.durations import MotionModel
from flipkit.planning.kitchen.throughput import sweep_rates

MODEL = MotionModel(MotionTimes(3.40, 2.32), MotionTimes(5.90, 1.35), "test")


def test_rates_on_workers_give_the_rows_of_sweep_rates():
    rates, kw = [60, 900, 120], dict(seed=3, time_limit_s=1.0)
    expected = sweep_rates(rates, 3, MODEL, **kw)
    assert [(r["rate_per_h"], r["policy"]) for r in expected] == [
        (60, "cpsat"), (60, "greedy"), (900, "cpsat"), (900, "greedy"), (120, "cpsat"),
        (120, "greedy")]
    assert "refused" in expected[2]  # a full grill: refused, in its place
    assert throughput_sweep(rates, 3, MODEL, workers=0, **kw) == expected
    assert throughput_sweep(rates, 3, MODEL, workers=2, **kw) == expected
