"""Property-based tests of the success-ratio statistics and the panels that draw counts.

The edges matter: 0/n, n/n and n = 1 are where a closed form rounds past the observed ratio
(a pooled 100/100 once gave an upper bound of 1 - 1.1e-16 and a negative error bar, which
matplotlib refuses).
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from flipkit.figures import draw  # noqa: E402
from flipkit.figures.draw.stats import ratio_error_bars  # noqa: E402


@st.composite
def counts(draw_, max_n: int = 2000, size: int | None = None):
    """Lists of (k, n) with 0 <= k <= n, biased toward the edges 0, 1 and n."""
    m = size or draw_(st.integers(1, 12))
    ns = draw_(st.lists(st.one_of(st.just(0), st.just(1), st.integers(0, max_n)),
                        min_size=m, max_size=m))
    ks = [draw_(st.one_of(st.just(0), st.just(n), st.integers(0, n))) for n in ns]
    return ks, ns


@given(counts())
def test_wilson_contains_ratio_and_stays_in_unit_interval(kn):
    k, n = map(np.asarray, kn)
    lo, hi = draw.wilson_interval(k, n)
    has = n > 0
    assert np.all(np.isnan(lo[~has])) and np.all(np.isnan(hi[~has]))
    p = k[has] / n[has]
    assert np.all((0 <= lo[has]) & (lo[has] <= p) & (p <= hi[has]) & (hi[has] <= 1))
    assert np.all(lo[has][k[has] == 0] == 0.0)
    assert np.all(hi[has][k[has] == n[has]] == 1.0)
    # Interior ratios have a strictly positive width on both sides.
    inner = has & (k > 0) & (k < n)
    assert np.all(lo[inner] < k[inner] / n[inner]) and np.all(hi[inner] > k[inner] / n[inner])


@given(st.integers(1, 5000))
def test_wilson_is_symmetric_under_success_failure_swap(n):
    rng = np.random.default_rng(n)
    k = int(rng.integers(0, n + 1))
    lo, hi = draw.wilson_interval([k], [n])
    lo2, hi2 = draw.wilson_interval([n - k], [n])
    assert np.isclose(lo[0], 1 - hi2[0], atol=1e-12) and np.isclose(hi[0], 1 - lo2[0], atol=1e-12)


@given(st.integers(1, 400))
def test_wilson_width_shrinks_with_more_trials(n):
    # Same ratio (one half or all), four times the trials: a narrower interval.
    for k_of in (lambda m: m, lambda m: 0, lambda m: m // 2):
        a = np.subtract(*reversed(draw.wilson_interval([k_of(2 * n)], [2 * n])))
        b = np.subtract(*reversed(draw.wilson_interval([k_of(8 * n)], [8 * n])))
        assert b[0] < a[0]


def test_wilson_known_values_and_bad_counts():
    # 95 % Wilson interval of 100/100 is [0.9630, 1]; of 1/1, [0.2065, 1].
    lo, hi = draw.wilson_interval([100, 1, 0], [100, 1, 1])
    assert np.isclose(lo[0], 0.96300, atol=1e-4) and hi[0] == 1.0
    assert np.isclose(lo[1], 0.20654, atol=1e-4) and hi[1] == 1.0
    assert lo[2] == 0.0 and np.isclose(hi[2], 0.79346, atol=1e-4)
    for k, n in (([3], [2]), ([-1], [4]), ([np.nan], [4]), ([1], [np.inf]), ([1.5], [4])):
        with pytest.raises(ValueError):
            draw.wilson_interval(k, n)


@given(counts())
def test_error_bars_are_never_negative(kn):
    ratio, (below, above) = ratio_error_bars(*kn)
    ok = ~np.isnan(ratio)
    assert np.all(below[ok] >= 0) and np.all(above[ok] >= 0)
    assert np.all(ratio[ok] + above[ok] <= 1 + 1e-15) and np.all(ratio[ok] - below[ok] >= -1e-15)


@settings(max_examples=25, deadline=None)
@given(counts(max_n=200, size=4), counts(max_n=200, size=4))
def test_success_panels_draw_any_counts(ours, other):
    paper_k, paper_n = [9, 10, 0, 5], [10, 10, 10, 10]
    fig, axes = plt.subplots(1, 2)
    try:
        draw.plot_success(axes[0], list("abcd"), *ours, paper_k, paper_n)
        draw.plot_success_series(axes[1], list("abcd"),
                                 [{"label": "x", "k": ours[0], "n": ours[1]},
                                  {"label": "y", "k": other[0], "n": other[1], "open": True}],
                                 paper_k, paper_n)
        assert [t.get_text() for t in axes[0].get_xticklabels()][-1] == "all"
    finally:
        plt.close(fig)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 30), st.integers(0, 30), st.integers(0, 30),
                          st.integers(0, 30)), min_size=1, max_size=5))
def test_sensitivity_panel_draws_any_counts(rows):
    def cell(n, k):
        k = min(k, n)
        return {"trials": n, "success": {"scoop": k, "pickup": k, "flip": k}}

    result = {"parameters": {f"p{i}": {"low": cell(a, b), "high": cell(c, d)}
                             for i, (a, b, c, d) in enumerate(rows)},
              "nominal": cell(rows[0][0], rows[0][1])}
    fig, axes = plt.subplots(1, 3)
    try:
        names = draw.plot_sensitivity(axes, result)
        assert names == [f"p{i}" for i in range(len(rows))]
    finally:
        plt.close(fig)
