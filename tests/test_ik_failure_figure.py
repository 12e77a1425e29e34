"""Figure ``ik_failure``: the outcome classes each map shows, the example location's rule and
the drawing of both methods' maps and joint paths (hand-made compare-ik records)."""

import matplotlib.pyplot as plt
import numpy as np
import pytest

from flipkit.config import TABLE1_LOCATIONS, CellConfig
from flipkit.errors import ConfigError
from flipkit.figures import draw
from flipkit.figures.runs import example_location


def entry(loc, ee_status="failed", ee_class="dynamic", coll_status="solved", judge=None):
    return {"location": list(loc),
            "ee_ik": {"status": ee_status, "class": None if ee_status == "solved" else ee_class,
                      "subbehavior": None if ee_status == "solved" else "flip"},
            "collocation": {"status": coll_status, "judge": judge}}


PASS = {"status": "solved", "class": None}
SLOW = {"status": "failed", "class": "time_scalable"}
ENTRIES = [entry(TABLE1_LOCATIONS[0], "failed", "ee", judge=PASS),
           entry(TABLE1_LOCATIONS[1], "failed", "kinematic", judge=SLOW),
           entry(TABLE1_LOCATIONS[2], "failed", "time_scalable", judge=PASS),
           entry(TABLE1_LOCATIONS[3], "solved", coll_status="failed"),
           entry(TABLE1_LOCATIONS[4], "failed", "dynamic", judge=PASS)]


def test_outcome_classes():
    ee, coll = draw.outcome_classes(ENTRIES)
    assert ee == ["ee", "kinematic", "time_scalable", "solved", "dynamic"]
    assert coll == ["solved", "time_scalable", "solved", "no_plan", "solved"]


def test_example_is_the_first_judged_failure_with_a_joint_path():
    assert example_location(ENTRIES) == list(TABLE1_LOCATIONS[2])  # not the ee-infeasible one
    only_slow = [ENTRIES[1], ENTRIES[0]]  # no collocation plan passes where EE + IK has a path
    assert example_location(only_slow) == list(TABLE1_LOCATIONS[1])
    assert example_location([ENTRIES[3]]) is None


def test_maps_and_joint_path_draw():
    fig, axes = plt.subplots(1, 3)
    frac = draw.plot_outcome_maps(axes[0], axes[1], CellConfig(), ENTRIES,
                                  table_locations=TABLE1_LOCATIONS)
    assert frac["ee_ik"]["solved"] == pytest.approx(0.2)
    assert frac["collocation"]["solved"] == pytest.approx(0.6)
    assert sum(frac["ee_ik"].values()) == pytest.approx(1.0)
    t = np.linspace(0, 2, 201)
    path = {"t": t, "q": np.outer(np.sin(t), np.ones(6)), "boundaries": [0, 1, 2],
            "names": ["scoop", "flip"], "failed": "flip", "label": "flip: joint velocity"}
    draw.plot_joint_path(axes[2], path, title="x", limits=(-np.ones(6), np.ones(6)))
    assert len(axes[2].lines) >= 6
    with pytest.raises(ConfigError):
        draw.plot_joint_path(axes[2], {**path, "q": path["q"][:, :5]})
    with pytest.raises(ConfigError):
        draw.plot_outcome_maps(axes[0], axes[1], CellConfig(), [])
    plt.close(fig)
