"""How solve time grows with the nodes per segment: the translate comparison at N = 10 … 80.

For each (N, solver) the six translate segments of the solver comparison
(:func:`flipkit.experiments.speed.translate_nlps`: the NLP without the arm's clearance rows,
which have no symbolic form) are solved from the same start ``nlp.x0`` by the SQP, FATROP,
exact-Hessian IPOPT, ``sqpmethod`` or L-BFGS IPOPT, as ``bench_translate`` of the
repository's ``bench/bench.py`` solves them at N = 20. One (N, solver) item is one job of a
sweep: one solver runs per worker process, single-threaded, so on a machine with one core
per worker the times are one-core times. Set-up is not counted: the SQP's subproblem compile
(one SQP iteration first, :func:`~flipkit.experiments.speed.warm_up`) and the exact solvers'
SX graph and solver build are reported apart.
"""

from __future__ import annotations

import time

import numpy as np

from flipkit.behaviors.options import SegmentOptions
from flipkit.config import CellConfig
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.experiments.speed import TRANSLATE_SOLVERS, translate_nlps, warm_up
from flipkit.experiments.sweep import run_sweep
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.chain import solve_segment
from flipkit.solvers.exact import ExactOptions, ExactSolver
from flipkit.solvers.names import EXACT_RESULT_NAMES
from flipkit.transcription.ocp_graph import OcpGraph

SCALING_N = (10, 20, 40, 80)  # intervals per segment (the paper: 20)


def scaling_item(item: dict) -> dict:
    """Solve the first ``segments`` translates at ``N`` with ``solver`` (a sweep worker).

    Args:
        item: ``{"N": int, "solver": a key of TRANSLATE_SOLVERS, "segments": int}``.

    Returns:
        ``N``, ``solver``, ``setup_s`` (compile or build, s) and ``segments``:
        ``[{"segment", "status", "time_s" (the solver call alone), "iterations",
        "objective" (Σu²)}]``.
    """
    n, solver = int(item["N"]), str(item["solver"])
    caches = PlannerCaches()  # this item's: its NLPs' models and the SQP's workspace
    nlps = translate_nlps(CellConfig(), SegmentOptions(N=n, arm_clearance=False), caches)
    nlps = nlps[:int(item["segments"])]
    plugin = {v: k for k, v in EXACT_RESULT_NAMES.items()}.get(solver)
    setup, rows = 0.0, []
    if solver == "sqp":
        setup = warm_up(nlps[:1], caches)
    built = {}  # the translates differ only in their bounds: one solver per distinct graph
    for k, nlp in enumerate(nlps):
        if plugin is not None:
            t0 = time.perf_counter()
            graph = OcpGraph(nlp, **ExactOptions().graph_options(plugin))
            if graph.key not in built:
                built[graph.key] = ExactSolver(nlp, plugin, graph=graph)
            setup += time.perf_counter() - t0
            res = built[graph.key].solve(graph=graph)
        else:
            res = solve_segment(nlp, solver, caches=caches)
        rows.append({"segment": k + 1, "status": str(res.status),
                     "time_s": float(res.wall_time_s), "iterations": int(res.iterations),
                     "objective": float(res.objective)})
    return {"N": n, "solver": solver, "setup_s": setup, "segments": rows}


def solve_scaling(n_values=SCALING_N, solvers=tuple(TRANSLATE_SOLVERS), segments: int = 6, *,
                  executor=None, progress: bool = False) -> list[dict]:
    """:func:`scaling_item` for every (N, solver), the largest N first (the longest jobs
    start first when the sweep runs on workers); returned in (N, solver) order.

    Raises:
        ConfigError: An N that is not an even integer ≥ 4, or ``segments`` not in 1..6.
        InvalidChoiceError: An unknown solver.
    """
    ns = [int(v) for v in n_values]
    if not ns or any(v != float(n) or n < 4 or n % 2 for v, n in zip(n_values, ns)):
        raise ConfigError(f"nodes per segment must be even integers >= 4, got {list(n_values)}")
    for s in solvers:
        if s not in TRANSLATE_SOLVERS:
            raise InvalidChoiceError("solver", s, TRANSLATE_SOLVERS)
    if not 1 <= int(segments) <= 6:
        raise ConfigError(f"segments must be 1 to 6, got {segments!r}")
    items = [{"N": n, "solver": s, "segments": int(segments)}
             for n in sorted(ns, reverse=True) for s in solvers]
    rows = run_sweep(scaling_item, items, executor, progress=progress, desc="solve scaling")
    return sorted(rows, key=lambda r: (r["N"], list(solvers).index(r["solver"])))


def scaling_table(rows) -> dict:
    """Medians over the segments: ``{solver: {"N": [...], "time_s": [...], "iterations":
    [...], "solved": [...], "segments": [...]}}`` (times and iterations of solved segments)."""
    out = {}
    for r in rows:
        done = [s for s in r["segments"] if s["status"] == "solved"]
        d = out.setdefault(r["solver"], {k: [] for k in ("N", "time_s", "iterations", "solved",
                                                           "segments")})
        d["N"].append(r["N"])
        d["time_s"].append(float(np.median([s["time_s"] for s in done])) if done else None)
        d["iterations"].append(float(np.median([s["iterations"] for s in done])) if done
                               else None)
        d["solved"].append(len(done))
        d["segments"].append(len(r["segments"]))
    return out


__all__ = ["SCALING_N", "scaling_item", "scaling_table", "solve_scaling"]
