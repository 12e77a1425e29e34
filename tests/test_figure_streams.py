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


def test_the_throughput_plot_counts_blocked_burgers_as_missed():
    """A rate whose windows hold but whose burgers are blocked is not one where every burger
    is within; the blocked counts are summed, and unchecked rows report None."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flipkit.figures.draw import plot_throughput

    def row(rate, within, timed, blocked, met=True):
        return {"policy": "cpsat", "rate_per_h": rate, "n_burgers": 10, "n_within": within,
                "per_hour_within": rate * within / 10, "windows_met": met,
                "n_blocked": blocked, "n_within_timing": timed, "utilisation": 0.5,
                "max_lateness_s": 0.0, "status": "OPTIMAL", "minutes": 5}

    fig, ax = plt.subplots()
    out = plot_throughput(ax, [row(60, 10, 10, 0), row(120, 7, 10, 3), row(180, 4, 9, 5, False)])
    assert out["max_rate_all_within_per_h"]["cpsat"] == 60
    assert out["first_break_per_h"]["cpsat"] == 120 and out["n_blocked"]["cpsat"] == 8
    assert out["n_within"]["cpsat"] == 21 and out["rates_all_within"]["cpsat"] == 1
    fig2, ax2 = plt.subplots()
    unchecked = [dict(row(60, 10, 10, 0), n_blocked=None, n_within_timing=None)]
    assert plot_throughput(ax2, unchecked)["n_blocked"]["cpsat"] is None
    plt.close(fig)
    plt.close(fig2)
