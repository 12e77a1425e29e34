"""Success counts' Wilson intervals (flipkit.experiments.ratios) against published values and
the figures' own formula."""

import numpy as np
import pytest

from flipkit.errors import ConfigError
from flipkit.experiments.ratios import format_intervals, success_intervals
from flipkit.figures.draw.stats import wilson_interval


def test_wilson_intervals_of_known_counts():
    out = success_intervals({"scoop": 100, "pickup": 99, "flip": 95, "none": 0}, 100)
    # Wilson 95 %: 100/100 -> [0.963, 1]; 99/100 -> [0.9455, 0.9982]; 95/100 -> [0.8882, 0.9785]
    assert out["scoop"] == pytest.approx([0.9630, 1.0], abs=5e-5)
    assert out["pickup"] == pytest.approx([0.9455, 0.9982], abs=5e-5)
    assert out["flip"] == pytest.approx([0.8882, 0.9785], abs=1e-4)
    assert out["none"] == pytest.approx([0.0, 0.0370], abs=5e-5)


def test_agrees_with_the_figures_intervals():
    n = 37
    ours = success_intervals({str(k): k for k in range(n + 1)}, n)
    lo, hi = wilson_interval(np.arange(n + 1), np.full(n + 1, n))
    assert np.array([ours[str(k)] for k in range(n + 1)]) == pytest.approx(
        np.column_stack([lo, hi]), abs=1e-4)  # z = 1.96 there, the exact quantile here


def test_a_wider_level_gives_a_wider_interval():
    narrow = success_intervals({"flip": 97}, 100, level=0.9)["flip"]
    wide = success_intervals({"flip": 97}, 100, level=0.99)["flip"]
    assert wide[0] < narrow[0] < 0.97 < narrow[1] < wide[1]


def test_format():
    line = format_intervals(success_intervals({"scoop": 100, "flip": 99}, 100))
    assert line == "95 % Wilson intervals: scoop 96.3–100.0 %, flip 94.6–99.8 %"


@pytest.mark.parametrize("success, trials", [
    ({"flip": 101}, 100), ({"flip": -1}, 100), ({"flip": 1.5}, 100), ({"flip": True}, 100),
    ({"flip": 1}, 0), ({"flip": 1}, 2.0),
])
def test_bad_counts_are_refused(success, trials):
    with pytest.raises(ConfigError):
        success_intervals(success, trials)
    with pytest.raises(ConfigError, match="level"):
        success_intervals({"flip": 1}, 2, level=1.0)
