"""The solve-scaling experiment (flipkit.experiments.scaling) and its panel."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from flipkit.errors import ConfigError, InvalidChoiceError  # noqa: E402
from flipkit.experiments.scaling import scaling_item, scaling_table, solve_scaling  # noqa: E402
from flipkit.figures import draw  # noqa: E402


@pytest.mark.parametrize("n_values", [(11,), (2,), (10.5,), ()])
def test_bad_node_counts_are_refused(n_values):
    with pytest.raises(ConfigError, match="even integers"):
        solve_scaling(n_values, solvers=("sqp",), segments=1)


def test_bad_solver_and_segment_count_are_refused():
    with pytest.raises(InvalidChoiceError, match="fatrop"):
        solve_scaling((10,), solvers=("snopt",), segments=1)
    with pytest.raises(ConfigError, match="segments"):
        solve_scaling((10,), solvers=("sqp",), segments=7)


def test_one_item_solves_at_the_asked_node_count():
    row = scaling_item({"N": 10, "solver": "sqp", "segments": 1})
    assert row["N"] == 10 and row["solver"] == "sqp" and len(row["segments"]) == 1
    seg = row["segments"][0]
    assert seg["status"] == "solved" and seg["iterations"] >= 1 and seg["time_s"] > 0


def _row(n, solver, times, statuses=None):
    statuses = statuses or ["solved"] * len(times)
    return {"N": n, "solver": solver, "setup_s": 0.0,
            "segments": [{"segment": k + 1, "status": s, "time_s": t, "iterations": 10 * n,
                          "objective": 1.0} for k, (t, s) in enumerate(zip(times, statuses))]}


def test_table_takes_medians_of_solved_segments_only():
    rows = [_row(10, "sqp", [1.0, 3.0, 100.0], ["solved", "solved", "max_iter"]),
            _row(20, "sqp", [2.0, 4.0, 6.0])]
    t = scaling_table(rows)["sqp"]
    assert t["N"] == [10, 20] and t["time_s"] == [2.0, 4.0]
    assert t["solved"] == [2, 3] and t["segments"] == [3, 3]


def test_panel_reports_the_order_of_growth():
    # time = 1e-3 N^2 for one solver, N^1 for another: slopes 2 and 1 on log-log axes
    rows = [_row(n, "sqp", [1e-3 * n**2]) for n in (10, 20, 40)]
    rows += [_row(n, "ipopt", [1e-2 * n]) for n in (10, 20, 40)]
    rows += [_row(n, "fatrop", [1.0], ["fatrop_failed"]) for n in (10, 20)]
    fig, (a, b) = plt.subplots(1, 2)
    slopes = draw.plot_scaling(a, b, scaling_table(rows))
    plt.close(fig)
    assert slopes["sqp"] == pytest.approx(2.0) and slopes["ipopt"] == pytest.approx(1.0)
    assert slopes["fatrop"] is None  # never every segment solved
