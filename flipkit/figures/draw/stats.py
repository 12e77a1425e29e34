"""Statistics panels: success ratios with Wilson intervals against the paper's, solve times,
and the sensitivity study."""

from __future__ import annotations

import numpy as np
from scipy.stats import norm

from flipkit.experiments.ratios import wilson
from flipkit.figures.style import ACTUAL_COLOR, DESIRED_COLOR, SOLVER_COLORS, SOLVER_LABELS


def wilson_interval(successes, trials, z: float = 1.96) -> tuple[np.ndarray, np.ndarray]:
    """Wilson score interval (lower, upper) of a binomial success ratio (95 % by default),
    element by element, at the two-sided level of ``z``: scipy's, as ``flipkit validate``
    reports it (:func:`flipkit.experiments.ratios.wilson`).

    The bounds contain the observed ratio ``k / n``; at ``k = 0`` the lower bound is 0 and at
    ``k = n`` the upper bound is 1. Entries with ``n = 0`` are NaN.

    Args:
        successes: Successes ``k`` (array-like of whole numbers, ``0 <= k <= n``).
        trials: Trials ``n`` (array-like of whole numbers, ``n >= 0``), broadcast with ``k``.
        z: Standard-normal quantile of the two-sided level (1.96 for 95 %).

    Raises:
        ValueError: If a count is negative, not a whole number, or ``k > n``.
    """
    k, n = np.broadcast_arrays(np.asarray(successes, float), np.asarray(trials, float))
    if not (np.all(np.isfinite(k)) and np.all(np.isfinite(n))):
        raise ValueError("wilson_interval: counts must be finite")
    if np.any(k < 0) or np.any(n < 0) or np.any(k > n):
        raise ValueError("wilson_interval: counts must satisfy 0 <= successes <= trials")
    if np.any(k != np.round(k)) or np.any(n != np.round(n)):
        raise ValueError("wilson_interval: counts must be whole numbers")
    level = 2.0 * float(norm.cdf(z)) - 1.0
    lo, hi = np.full(k.shape, np.nan), np.full(k.shape, np.nan)
    for i in np.ndindex(k.shape):
        if n[i] > 0:
            lo[i], hi[i] = wilson(int(k[i]), int(n[i]), level)
    return lo, hi


def ratio_error_bars(successes, trials, z: float = 1.96):
    """Observed ratios and their Wilson error bars, ready for ``Axes.errorbar``.

    Returns:
        ``(ratio, [below, above])``: NaN where ``n = 0``; the bars are never negative.
    """
    k, n = np.asarray(successes, float), np.asarray(trials, float)
    lo, hi = wilson_interval(k, n, z)
    ratio = np.where(n > 0, k / np.where(n > 0, n, 1), np.nan)
    return ratio, [np.maximum(ratio - lo, 0.0), np.maximum(hi - ratio, 0.0)]


def plot_success(ax, labels, ours_k, ours_n, paper_k, paper_n, title: str = "",
                 pooled: bool = True) -> None:
    """Success ratios per location: ours (filled circles, 95 % Wilson interval) beside the
    paper's (open squares); with ``pooled`` a last column "all" pools every location."""
    labels = [str(v) for v in labels]
    ours_k, ours_n = np.asarray(ours_k, float), np.asarray(ours_n, float)
    paper_k, paper_n = np.asarray(paper_k, float), np.asarray(paper_n, float)
    if pooled:
        labels = labels + ["all"]
        ours_k, ours_n = np.append(ours_k, ours_k.sum()), np.append(ours_n, ours_n.sum())
        paper_k, paper_n = np.append(paper_k, paper_k.sum()), np.append(paper_n, paper_n.sum())
    x = np.arange(len(labels), dtype=float)
    if pooled:
        x[-1] += 0.5
        ax.axvline(x[-1] - 0.75, color="0.6", lw=0.6, ls=":")
    ratio, bars = ratio_error_bars(ours_k, ours_n)
    ax.errorbar(x + 0.12, ratio, yerr=bars, fmt="o", color=ACTUAL_COLOR,
                ms=4, capsize=1.5, lw=0.8, label="ours (simulated), 95 % CI")
    ax.plot(x - 0.12, paper_k / paper_n, "s", mfc="white", mec=DESIRED_COLOR, ms=4.5, mew=1.0,
            label="paper (real robot)")
    ax.set_xticks(x, labels)
    ax.set_ylim(-0.05, 1.08)
    ax.set_ylabel("success ratio")
    if title:
        ax.set_title(title)


def plot_success_series(ax, labels, series, paper_k, paper_n, title: str = "",
                        pooled: bool = True) -> None:
    """Success ratios per location of several simulated pipelines side by side (each with a
    95 % Wilson interval) beside the paper's (open squares); with ``pooled`` a last column
    "all" pools every location.

    Args:
        ax: 2D axes. labels: Location labels.
        series: ``[{"label", "k" (successes per location), "n" (trials per location),
            optional "color", "marker", "open" (hollow marker)}]``, drawn left to right.
        paper_k, paper_n: The paper's successes and trials per location.
    """
    labels = [str(v) for v in labels]
    paper_k, paper_n = np.asarray(paper_k, float), np.asarray(paper_n, float)
    if pooled:
        labels = labels + ["all"]
        paper_k, paper_n = np.append(paper_k, paper_k.sum()), np.append(paper_n, paper_n.sum())
    x = np.arange(len(labels), dtype=float)
    if pooled:
        x[-1] += 0.5
        ax.axvline(x[-1] - 0.75, color="0.6", lw=0.6, ls=":")
    width = 0.7 / (len(series) + 1)
    ax.plot(x - 0.35 + width / 2, paper_k / paper_n, "s", mfc="white", mec=DESIRED_COLOR,
            ms=4, mew=1.0, label="paper (real robot)")
    for j, sr in enumerate(series, 1):
        k, n = np.asarray(sr["k"], float), np.asarray(sr["n"], float)
        if pooled:
            k, n = np.append(k, k.sum()), np.append(n, n.sum())
        ratio, bars = ratio_error_bars(k, n)
        color = sr.get("color", f"C{j - 1}")
        ax.errorbar(x - 0.35 + width * (j + 0.5), ratio, yerr=bars,
                    fmt=sr.get("marker", "o"), color=color, mfc="white" if sr.get("open")
                    else color, ms=3.5, capsize=1.2, lw=0.7, label=sr["label"])
    ax.set_xticks(x, labels)
    ax.set_ylim(-0.05, 1.08)
    ax.set_ylabel("success ratio")
    if title:
        ax.set_title(title)


def plot_solve_times(ax, names, times, budget: float | None = None, log: bool = True,
                     failed=None) -> dict:
    """Solve time per group (subbehaviour) and solver: points per location, box over them.

    Args:
        ax: 2D axes.
        names: Group names along x (e.g. the subbehaviours and ``"total"``).
        times: ``{solver: {name: [seconds per location]}}``; missing or None entries skipped.
        budget: A horizontal budget line (s), e.g. the paper's 20 s per trajectory.
        failed: Same form as ``times``: solves that did not converge, drawn as crosses.

    Returns:
        ``{solver: {name: median seconds}}``.
    """
    solvers = list(times)
    width = 0.8 / max(len(solvers), 1)
    rng = np.random.default_rng(0)
    medians = {}
    for k, solver in enumerate(solvers):
        medians[solver] = {}
        color = SOLVER_COLORS.get(solver, f"C{k}")
        for j, name in enumerate(names):
            vals = np.array([v for v in times[solver].get(name, []) if v is not None], float)
            if vals.size == 0:
                continue
            pos = j - 0.4 + width * (k + 0.5)
            ax.boxplot([vals], positions=[pos], widths=width * 0.8, showfliers=False,
                       patch_artist=True, boxprops={"facecolor": color, "alpha": 0.25,
                                                    "edgecolor": color},
                       medianprops={"color": color, "lw": 1.5},
                       whiskerprops={"color": color}, capprops={"color": color})
            jitter = rng.uniform(-0.25, 0.25, vals.size) * width
            ax.plot(pos + jitter, vals, "o", color=color, ms=2.5, alpha=0.9,
                    label=SOLVER_LABELS.get(solver, solver) if j == 0 else None)
            medians[solver][name] = float(np.median(vals))
        for j, name in enumerate(names):
            bad = np.array([v for v in (failed or {}).get(solver, {}).get(name, [])
                            if v is not None], float)
            if bad.size:
                pos = j - 0.4 + width * (k + 0.5)
                ax.plot(np.full(bad.size, pos), bad, "x", color=color, ms=4, mew=1.0,
                        label=f"{SOLVER_LABELS.get(solver, solver)}: not converged"
                        if not any(h.get_label().endswith(f"{SOLVER_LABELS.get(solver, solver)}"
                                                          ": not converged")
                                   for h in ax.lines) else None)
    if budget is not None:
        ax.axhline(budget, color="k", ls="--", lw=1.0,
                   label=f"paper budget, {budget:g} s per trajectory")
    if log:
        ax.set_yscale("log")
    ax.set_xticks(range(len(names)), [str(n).replace("_", " ") for n in names])
    ax.set_xlim(-0.6, len(names) - 0.4)
    ax.set_ylabel("solve time (s)")
    return medians


def plot_sensitivity(axes, result: dict, stages=("scoop", "pickup", "flip"),
                     labels=None) -> list:
    """One panel per stage: per parameter (rows), the success ratio at the low end
    (down-triangle) and the high end (up-triangle) of its range, the nominal cell's ratio as
    a vertical line. ``result`` is :func:`flipkit.experiments.sensitivity.run_sensitivity`'s.

    Returns:
        The parameter names, top to bottom.
    """
    names = list(result["parameters"])
    y = np.arange(len(names))[::-1]
    nominal = result.get("nominal")
    for ax, stage in zip(axes, stages):
        for end, marker, color in (("low", "v", DESIRED_COLOR), ("high", "^", ACTUAL_COLOR)):
            r = [result["parameters"][n][end] for n in names]
            ratio = np.array([c["success"][stage] / c["trials"] if c["trials"] else np.nan
                              for c in r])
            off = -0.12 if end == "low" else 0.12
            ax.plot(ratio, y + off, marker, color=color, ms=3.5, ls="none",
                    label=f"{end} end of range")
        if nominal is not None:
            if nominal["trials"]:
                ax.axvline(nominal["success"][stage] / nominal["trials"], color="0.3", lw=0.9,
                       ls=":", label="nominal")
        ax.set_xlim(-0.05, 1.05)
        ax.set_ylim(-0.6, len(names) - 0.4)
        ax.set_title(stage)
        ax.set_xlabel("success ratio")
        ax.set_yticks(y, labels or names)
    return names
