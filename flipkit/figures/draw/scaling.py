"""Solve time and iterations against the nodes per segment (the solve_scaling figure)."""

from __future__ import annotations

import numpy as np

from flipkit.figures.style import SOLVER_COLORS, SOLVER_LABELS


def plot_scaling(ax_time, ax_iter, table: dict) -> dict:
    """Median solve time (log-log) and median iterations against N, one line per solver.

    Args:
        ax_time, ax_iter: 2D axes for the times (s) and the iterations.
        table: :func:`flipkit.experiments.scaling.scaling_table`'s output. An N where a solver
            left a segment unsolved gets an open marker and ``k/n`` beside it.

    Returns:
        ``{solver: slope}``: the least-squares slope of log time against log N over the Ns
        where every segment was solved (``None`` with fewer than two), the empirical order
        of growth.
    """
    slopes = {}
    for k, (solver, d) in enumerate(table.items()):
        color = SOLVER_COLORS.get(solver, f"C{k}")
        label = SOLVER_LABELS.get(solver, solver)
        n = np.asarray(d["N"], float)
        for ax, key in ((ax_time, "time_s"), (ax_iter, "iterations")):
            y = np.array([np.nan if v is None else v for v in d[key]], float)
            ax.plot(n, y, "-", color=color, lw=1.2, label=label if ax is ax_time else None)
            full = np.array(d["solved"]) == np.array(d["segments"])
            ax.plot(n[full], y[full], "o", color=color, ms=3.5)
            ax.plot(n[~full], y[~full], "o", mfc="white", color=color, ms=3.5)
            for x, v, s, m in zip(n[~full], y[~full], np.array(d["solved"])[~full],
                                  np.array(d["segments"])[~full]):
                if np.isfinite(v):
                    ax.annotate(f"{s}/{m}", (x, v), textcoords="offset points", xytext=(3, 3),
                                fontsize=5.5, color=color)
        ok = (np.array(d["solved"]) == np.array(d["segments"])) & np.array(
            [v is not None for v in d["time_s"]])
        slopes[solver] = (float(np.polyfit(np.log(n[ok]), np.log(
            np.array(d["time_s"], dtype=object)[ok].astype(float)), 1)[0])
            if ok.sum() >= 2 else None)
    for ax in (ax_time, ax_iter):
        ax.set_xscale("log")
        ax.set_xticks(sorted({n for d in table.values() for n in d["N"]}))
        ax.set_xticklabels([str(int(v)) for v in ax.get_xticks()])
        ax.minorticks_off()
        ax.set_xlabel("intervals per segment N")
        ax.grid(True, which="major", lw=0.3, alpha=0.5)
    ax_time.set_yscale("log")
    ax_time.set_ylabel("median solve time (s)")
    ax_iter.set_ylabel("median iterations")
    return slopes


__all__ = ["plot_scaling"]
