"""Solve-time benchmarks against the paper's budgets: SQP (cvxpy/OSQP) beside IPOPT.

    python -m bench.bench translate [--full] [--jit] [--json OUT]
    python -m bench.bench flip [--locations N] [--batch K] [--atlas FILE]
                                             [--no-atlas] [--no-ipopt] [--baseline] [--cook]
                                             [--json OUT]

``python -m bench.bench_all`` runs the three side by side.
``translate``: the six segments between :data:`~flipkit.experiments.speed.TRANSLATE_KEY_POINTS` (paper Fig. 6), each
NLP solved by every solver from the same start point ``nlp.x0``: the SQP, FATROP,
exact-Hessian IPOPT and ``sqpmethod`` (:mod:`flipkit.solvers.exact`, on the NLP as a CasADi
OCP) and
IPOPT with L-BFGS through callbacks, all on the same scaled NLP — without the arm's clearance
rows, which have no symbolic form (``--full``: the planner's NLP with them, the SQP and
L-BFGS IPOPT only). ``flip``: the full
pickup-and-flip (five segments) at the first N Table I locations with the SQP from cold
starts, the SQP warm-started from the atlas (:mod:`flipkit.planning.planners.atlas`; the package's
by default) and IPOPT, then
a batch of the first K locations with the SQP, cold and from the atlas (``flipkit plan
batch``'s default), one after the other and on one worker process per CPU, beside the paper's budgets (Sec. I: < 20 s
per trajectory, 4–5 burgers within 90 s). With ``--baseline``, the end-effector-space + IK
baseline (:func:`flipkit.baseline.run_baseline`, each EE method, placo IK at 200 Hz) at the
same locations: its EE optimisation and IK times per subbehaviour beside the paper's (Sec. I:
EE optimisation < 1 s). With ``--cook``, the package's cook order
(:data:`flipkit.planning.kitchen.cook.EXAMPLE_ORDER`) scheduled with the SQP, its motions planned one
after another and then ahead on one worker process per CPU
(:mod:`flipkit.planning.kitchen.prefetch`): the planning clock (to the last plan in) beside the sum
of the motions' planning times. Times are wall-clock seconds of the solver calls
(IPOPT's include building its CasADi problem). Before timing, every NLP structure gets one
SQP iteration, and its hard and elastic QPs are compiled, so that cvxpy's one-off
canonicalisation (0.01–0.4 s per QP, once per process) is not timed.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import time
import warnings
from dataclasses import asdict
from pathlib import Path

import numpy as np

from bench.bench_replan import bench_replan, load_result, run_validation
from bench.iteration_notes import iteration_notes
from flipkit.baseline import EE_METHODS, CompiledProblems, run_baseline
from flipkit.behaviors.library import FLIP_NAMES, SUBBEHAVIORS
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.targets import turned_heading
from flipkit.behaviors.transcribe import transcribe
from flipkit.config import TABLE1_LOCATIONS, CellConfig
from flipkit.experiments.speed import (PAPER_EE_OPT_S, PAPER_FIVE_BURGERS_S,
                                       PAPER_PER_TRAJECTORY_S, TRANSLATE_KEY_POINTS,
                                       TRANSLATE_SOLVERS, translate_nlps, warm_up)
from flipkit.experiments.sweep import make_executor
from flipkit.model.casadi_dynamics import CasadiArm
from flipkit.planning.kitchen.cook import EXAMPLE_ORDER, check_cook, read_cook_csv, table_spots
from flipkit.planning.kitchen.motions import default_planners
from flipkit.planning.kitchen.prefetch import PrefetchPlanners
from flipkit.planning.kitchen.schedule import schedule_cook
from flipkit.planning.planners.atlas import Atlas, default_atlas
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.chain import solve_segment
from flipkit.planning.planners.planner import plan_batch, plan_flip
from flipkit.solvers.exact import ExactOptions, ExactSolver
from flipkit.solvers.names import EXACT_RESULT_NAMES, NLP_SOLVERS
from flipkit.transcription.ocp_graph import OcpGraph

def cpu_model() -> str:
    """The CPU's model name (Linux ``/proc/cpuinfo``; else ``platform.processor()``), and
    whether numpy's SIMD loops use AVX-512: the floating-point kernels, on which the last bits
    of a plan depend; ``?`` where unknown."""
    name = platform.processor() or "?"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                name = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        from numpy._core._multiarray_umath import __cpu_features__
        name += ", AVX-512" if __cpu_features__.get("AVX512_SKX") else ", no AVX-512"
    except ImportError:  # pragma: no cover - another numpy layout
        pass
    return name


def machine() -> str:
    """One line: CPU count, platform, CPU model, Python, BLAS/OpenMP thread setting, and the
    load average over the last minute (runnable processes: above the CPU count, the machine
    is shared and wall times stretch)."""
    load = f", load {os.getloadavg()[0]:.1f}" if hasattr(os, "getloadavg") else ""
    return (f"machine: {os.cpu_count()} CPUs, {platform.platform()}, {cpu_model()}"
            f", Python {platform.python_version()}, OMP_NUM_THREADS="
            f"{os.environ.get('OMP_NUM_THREADS', 'unset')}{load}")


def _med(values) -> float:
    values = [v for v in values if v is not None and np.isfinite(v)]
    return statistics.median(values) if values else float("nan")


def _exact_solvers(nlps, jit: bool) -> tuple[dict, dict, dict]:
    """Each exact-derivative peer with the graphs of ``nlps`` it needs
    (:meth:`ExactOptions.graph_options`), one solver built per distinct graph
    (:attr:`OcpGraph.key`: the translates differ only in their bounds).

    Returns:
        ``{(result name, k): (solver, graph of nlps[k])}``, build times (s) by what was
        built, and each peer's graph of ``nlps[0]``.
    """
    options, arm = ExactOptions(jit=jit, step_profile=True), CasadiArm(nlps[0].robot)
    solvers, build, first, graphs, built = {}, {}, {}, {}, {}
    for plugin, name in EXACT_RESULT_NAMES.items():
        spec = tuple(sorted(options.graph_options(plugin).items()))
        if spec not in graphs:
            t0 = time.perf_counter()
            graphs[spec] = [OcpGraph(nlp, arm, **dict(spec)) for nlp in nlps]
            build["graphs"] = build.get("graphs", 0.0) + time.perf_counter() - t0
        for k, g in enumerate(graphs[spec]):
            if g.key not in built:
                built[g.key] = ExactSolver(g.nlp, plugin, options, graph=g)
                build[name] = build.get(name, 0.0) + built[g.key].build_time_s
            solvers[(name, k)] = (built[g.key], g)
        first[name] = graphs[spec][0]
        built.clear()
    return solvers, build, first


def bench_translate(cell: CellConfig, full: bool = False, jit: bool = False) -> dict:
    """Solve the six translate segments with every solver; print the table; return rows.

    Args:
        cell: The cell.
        full: The planner's NLP with the arm's clearance rows (coal distances, no symbolic
            form): the SQP and L-BFGS IPOPT only. Default: the comparison NLP without them,
            solved by the SQP, FATROP, exact-Hessian IPOPT and L-BFGS IPOPT, all on the same
            scaled problem from the same start ``nlp.x0``.
        jit: Compile FATROP's and exact IPOPT's functions to C (CasADi JIT).
    """
    names = NLP_SOLVERS if full else tuple(TRANSLATE_SOLVERS)
    caches = PlannerCaches()  # the SQP's workspace, compiled by the warm-up
    nlps = translate_nlps(cell, SegmentOptions(arm_clearance=full), caches)
    print(machine())
    print(f"problem: translate NLP {'with' if full else 'without'} the arm's clearance rows"
          f"{'' if full else ' (no symbolic form: left out for every solver)'}; "
          f"{nlps[0].n} variables, {nlps[0].m} rows")
    print(f"warm-up: one SQP iteration on the translate structure (cvxpy compile): "
          f"{warm_up(nlps[:1], caches):.1f} s, not counted below")
    build = {}
    if not full:
        exact, build, first = _exact_solvers(nlps, jit)
        g = first["fatrop"]
        print("build, not counted below: SX graphs of the six NLPs and the solvers " + ", ".join(
            f"{k} {v:.1f} s" for k, v in build.items()) + f"{' (JIT-compiled)' if jit else ''}; "
            f"FATROP structure N={g.K}, nx={g.nx[0]}, nu={g.nu[0]}, ng={g.ng[1]}, objective "
            f"{g.obj_scale:g}·Σu²")
    print(f"{'seg':<6}{'solver':<14}{'time s':>8}{'it':>5}{'objective':>12}{'dJ vs SQP':>11}"
          f"{'status':>14}{'T s':>6}", flush=True)
    rows = []
    for k, nlp in enumerate(nlps):
        r = {"segment": f"{k + 1}->{(k + 1) % len(nlps) + 1}"}
        for name in names:
            profile, cpu = None, time.process_time()
            if name in EXACT_RESULT_NAMES.values():
                solver, graph = exact[(name, k)]
                res, profile = solver.solve(graph=graph), solver.last_profile
            else:
                res = solve_segment(nlp, name, caches=caches)
            r[name] = {"time_s": res.wall_time_s, "cpu_s": time.process_time() - cpu,
                       "iterations": res.iterations,
                       "objective": res.objective, "status": str(res.status),
                       "T_s": float(res.x[nlp.layout.T_index]),
                       "profile": None if profile is None else asdict(profile)}
        for name in names:
            d, s = r[name], r["sqp"]
            both = d["status"] == s["status"] == "solved"
            d["rel_objective_diff_vs_sqp"] = (
                (d["objective"] - s["objective"]) / abs(s["objective"]) if both else None)
            rel = d["rel_objective_diff_vs_sqp"]
            print(f"{r['segment']:<6}{TRANSLATE_SOLVERS[name]:<14}{d['time_s']:8.3f}"
                  f"{d['iterations']:5d}{d['objective']:12.6g}"
                  f"{(f'{rel:11.1e}' if rel is not None else '-'.rjust(11))}"
                  f"{d['status'][:13]:>14}{d['T_s']:6.2f}", flush=True)
        rows.append(r)
    med = {name: {key: _med([r[name][key] for r in rows])
                  for key in ("time_s", "cpu_s", "iterations", "T_s")} for name in names}
    for name in names:
        med[name]["max_abs_rel_objective_diff_vs_sqp"] = max(
            (abs(r[name]["rel_objective_diff_vs_sqp"]) for r in rows
             if r[name]["rel_objective_diff_vs_sqp"] is not None), default=float("nan"))
        med[name]["solved"] = sum(r[name]["status"] == "solved" for r in rows)
        med[name]["ms_per_iteration"] = 1e3 * _med(
            [r[name]["time_s"] / r[name]["iterations"] for r in rows if r[name]["iterations"]])
    print(f"{'median':<7}{'solver':<13}{'time s':>8}{'cpu s':>7}{'it':>5}{'ms/it':>7}"
          f"{'max |dJ|':>10}{'solved':>9}")
    for name in names:
        m = med[name]
        print(f"{'':<6}{TRANSLATE_SOLVERS[name]:<14}{m['time_s']:8.3f}{m['cpu_s']:7.3f}"
              f"{m['iterations']:5.0f}{m['ms_per_iteration']:7.1f}"
              f"{m['max_abs_rel_objective_diff_vs_sqp']:10.1e}{m['solved']:>7d}/{len(rows)}")
    ratio = sqp_ratio(med, len(rows))
    if ratio:
        print(f"SQP vs the best peer that solved all {len(rows)}: {ratio['best']} "
              f"{ratio['best_s']:.3f} s / SQP {ratio['sqp_s']:.3f} s = {ratio['ratio']:.2f}"
              f" (> 1: the SQP is faster); in CPU time {ratio['best_cpu']} "
              f"{ratio['ratio_cpu']:.2f}")
    print(f"T = executed duration (s), bounds {SUBBEHAVIORS['translate'].duration} s; dJ = (J − J_SQP)/J_SQP "
          "over the segments both solved, ms/it = median time per iteration, "
          "J = Σu² (every solver minimises the same scaled obj_scale·Σu²); times are the "
          "solver calls alone (FATROP's and exact IPOPT's without building their graphs)")
    for line in iteration_notes(rows, names, med, TRANSLATE_SOLVERS):
        print(line)
    return {"machine": machine(), "key_points": TRANSLATE_KEY_POINTS, "full": full, "jit": jit,
            "build_s": build, "rows": rows, "median": med, "sqp_ratio": ratio}


def sqp_ratio(med: dict, n: int) -> dict | None:
    """The best peer's median time over the SQP's (> 1: the SQP is faster), among the peers
    that solved all ``n`` segments, in wall time and in process CPU time (on a shared
    machine wall times stretch with the load, CPU times much less); ``None`` when no peer
    solved all or the SQP did not."""
    peers = [p for p in med if p != "sqp" and med[p]["solved"] == n]
    if not peers or med["sqp"]["solved"] != n:
        return None
    best = min(peers, key=lambda p: med[p]["time_s"])
    best_cpu = min(peers, key=lambda p: med[p]["cpu_s"])
    return {"best": best, "best_s": med[best]["time_s"], "sqp_s": med["sqp"]["time_s"],
            "ratio": med[best]["time_s"] / med["sqp"]["time_s"], "best_cpu": best_cpu,
            "ratio_cpu": med[best_cpu]["cpu_s"] / med["sqp"]["cpu_s"]}


def _flip_row(plan) -> dict:
    segs = plan.segments
    return {"status": plan.status, "failure": plan.failure, "wall_s": plan.wall_time_s,
            "solve_s": sum(s.solver.wall_time_s for s in segs),
            "iterations": sum(s.solver.iterations for s in segs),
            "objective": sum(s.solver.objective for s in segs),
            "T_s": sum(s.T for s in segs), "segments": len(segs)}


def _timed_flip(location, cell: CellConfig, kw: dict) -> dict:
    """:func:`_flip_row` of ``plan_flip(location)``, with ``cpu_s`` the process CPU time (s) of
    the call. A plan runs on one thread, so CPU ≈ wall on an idle machine, and wall > CPU
    says the machine was busy. (On a shared virtual machine identical solves can take
    longer from one minute to the next in CPU time as in wall time: compare runs made side
    by side, ``docs/history.md``.)"""
    t0 = time.process_time()
    plan = plan_flip(location, cell=cell, **kw)
    return {**_flip_row(plan), "cpu_s": time.process_time() - t0}


def bench_flip(cell: CellConfig, n_locations: int, n_batch: int, atlas=None,
               ipopt: bool = True, baseline: bool = False, cook: bool = False,
               turn: float = 0.0, cold: bool = True) -> dict:
    """Full pickup-and-flip at the first ``n_locations`` Table I locations, each scooped along
    its default heading turned by ``turn`` (rad), with the SQP from
    cold starts (if ``cold``), the SQP warm-started from ``atlas`` (if given) and IPOPT (if ``ipopt``),
    then a batch of the first ``n_batch`` with the SQP, cold and from ``atlas``, the EE + IK
    baseline's times at the same locations (if ``baseline``) and the package's cook order
    scheduled with and without prefetching (if ``cook``); print; return the rows."""
    caches = PlannerCaches()  # every plan of the benchmark, compiled once by the warm-up
    models, locs = caches.models(cell), TABLE1_LOCATIONS[:n_locations]
    q, qd, structures = models.bare.q_home, None, []
    for name in FLIP_NAMES:  # one NLP per structure, along the initial guesses
        nlp = transcribe(name, models, q, qd, location=TABLE1_LOCATIONS[1],
                         patterns=caches.patterns)
        structures.append(nlp)
        x = nlp.layout.nodes(nlp.x0)
        q, qd = x[-1, 0], x[-1, 1]
    methods = {"sqp": {"solver": "sqp", "caches": caches}} if cold or atlas is None else {}
    if atlas is not None:
        methods["sqp_atlas"] = {"solver": "sqp", "atlas": atlas, "caches": caches}
    if ipopt:
        methods["ipopt"] = {"solver": "ipopt", "caches": caches}
    print(machine())
    print(f"warm-up: one SQP iteration on each of the 5 segment structures (cvxpy compile): "
          f"{warm_up(structures, caches):.1f} s, not counted below")
    if atlas is not None:
        print(f"atlas: {len(atlas)} entries, a {atlas.meta['grid'][0]} x "
              f"{atlas.meta['grid'][1]} grid at {len(atlas.meta.get('turns', [0.0]))} headings")
    print(f"{'loc':<4}{'p^b (m)':<25}{'method':<11}{'solve s':>8}{'wall s':>8}{'cpu s':>7}"
          f"{'it':>6}{'status':>8}{'T s':>6}{'dJ vs SQP':>11} | paper budget", flush=True)
    rows = []
    for k, loc in enumerate(locs, 1):
        turned = {"heading": turned_heading(cell, loc, turn)} if turn else {}
        r = {"location": loc, **turned,
             **{n: _timed_flip(loc, cell, {**kw, **turned}) for n, kw in methods.items()}}
        rows.append(r)
        where = "(" + ", ".join(f"{v:.3f}" for v in loc) + ")"
        label = f"{k:<4}{where:<25}"
        for n in methods:
            d, s = r[n], r[next(iter(methods))]
            both = d["status"] == s["status"] == "solved"
            d["rel_objective_diff_vs_sqp"] = ((d["objective"] - s["objective"])
                                              / abs(s["objective"]) if both else float("nan"))
            print(f"{label}{n:<11}{d['solve_s']:8.2f}{d['wall_s']:8.2f}{d['cpu_s']:7.2f}"
                  f"{d['iterations']:6d}{d['status']:>8}{d['T_s']:6.2f}"
                  f"{d['rel_objective_diff_vs_sqp']:11.1e} | < {PAPER_PER_TRAJECTORY_S:.0f} s",
                  flush=True)
            if d["failure"]:
                print(f"    {n}: {d['failure']}", flush=True)
            label = " " * 29
    med = {n: {key: _med([r[n][key] for r in rows])
               for key in ("solve_s", "wall_s", "cpu_s", "iterations", "T_s")} for n in methods}
    for n in methods:
        worst = max((r[n]["wall_s"] for r in rows), default=float("nan"))
        med[n]["worst_wall_s"] = worst
        med[n]["solved"] = sum(r[n]["status"] == "solved" for r in rows)
        print(f"{'median':<29}{n:<11}{med[n]['solve_s']:8.2f}{med[n]['wall_s']:8.2f}"
              f"{med[n]['cpu_s']:7.2f}{med[n]['iterations']:6.0f}{med[n]['solved']:>5}/{len(rows)}"
              f"{med[n]['T_s']:6.2f}   worst wall {worst:.2f} s")
    print("solve s = solver time of the five segments, wall s = the whole plan_flip call (IK, "
          "build, solve, verify), cpu s = its process CPU time, T = executed duration of the "
          "plan (s), dJ = (ΣJ − ΣJ_SQP)/ΣJ_SQP over the five segments")
    out = {"machine": machine(), "turn_rad": turn, "rows": rows, "median": med}
    if n_batch:  # cold, then from the atlas (``flipkit plan batch``'s default)
        out["batch"] = _bench_batch(cell, n_batch, None, caches)
        if atlas is not None:
            out["batch_atlas"] = _bench_batch(cell, n_batch, atlas, caches)
    if baseline:
        out["baseline"] = _bench_baseline(cell, locs)
    if cook:
        out["cook"] = _bench_cook(cell, atlas, caches)
    return out


def _bench_baseline(cell: CellConfig, locations) -> dict:
    """The EE + IK baseline at ``locations`` with each EE method (placo IK, 200 Hz): the
    EE optimisation and IK wall times (s) of every subbehaviour it ran; print; return them."""
    out = {}
    print(f"{'EE + IK baseline':<29}{'EE s med':>9}{'EE s max':>9}{'IK s med':>9}"
          f"{'IK s max':>9}{'solved':>8} | paper budget", flush=True)
    for ee in EE_METHODS:
        problems = CompiledProblems()  # compiled by the first location, reused by the others
        results = [run_baseline(loc, cell, ee=ee, problems=problems) for loc in locations]
        ee_s = [s.ee_time_s for r in results for s in r.segments]
        ik_s = [s.ik_time_s for r in results for s in r.segments]
        solved = sum(r.status == "solved" for r in results)
        out[ee] = {"ee_s": ee_s, "ik_s": ik_s, "solved": solved,
                   "segments": [[s.subbehavior for s in r.segments] for r in results]}
        print(f"{'  EE ' + ee:<29}{_med(ee_s):9.3f}{max(ee_s, default=float('nan')):9.3f}"
              f"{_med(ik_s):9.3f}{max(ik_s, default=float('nan')):9.3f}"
              f"{solved:>5}/{len(results)} | EE < {PAPER_EE_OPT_S:.0f} s", flush=True)
    print("EE s, IK s = wall time of one subbehaviour's end-effector optimisation and of its "
          "IK (placo, 200 Hz), over every subbehaviour the baseline ran at these locations")
    return out


def _bench_cook(cell: CellConfig, atlas, caches: PlannerCaches) -> dict:
    """The package's cook order (flips and serves, SQP) scheduled with its motions planned one
    after another (with ``caches``) and ahead on one worker process per CPU (each motion's
    task compiling its own subproblems); print; return the record."""
    burgers, kinds = read_cook_csv(EXAMPLE_ORDER, cell), ("flip", "serve")
    q_home = cell.robot.q_home
    runs = {"serial": schedule_cook(burgers, default_planners(kinds, cell, "sqp", atlas, caches),
                                    q_home, kinds=kinds, cell=cell)}
    workers = os.cpu_count() or 1
    executor = make_executor(workers=workers)
    try:
        planners = PrefetchPlanners(check_cook(burgers, cell), kinds, q_home, table_spots(cell),
                                    executor, cell, "sqp", atlas)
        runs["prefetch"] = schedule_cook(burgers, planners, q_home, kinds=kinds, cell=cell)
    finally:
        executor.shutdown()
    out = {}
    for name, tl in runs.items():
        total = sum(m.planning_time_s for m in tl.motions)
        out[name] = {"planning_clock_s": tl.planning_time_s, "sum_planning_s": total,
                     "motions": len(tl.motions), "ok": tl.ok}
        print(f"cook {EXAMPLE_ORDER.name} ({len(burgers)} burgers, {len(tl.motions)} motions, "
              f"{'ok' if tl.ok else 'FAILED'}), {name}"
              f"{f' on {workers} worker processes' if name == 'prefetch' else ''}: planning "
              f"clock {tl.planning_time_s:.1f} s, sum of the motions' planning times "
              f"{total:.1f} s", flush=True)
    return {"workers": workers, **out}


def _bench_batch(cell: CellConfig, n_batch: int, atlas, caches: PlannerCaches) -> dict:
    """The first ``n_batch`` Table I burgers with :func:`plan_batch` (SQP, from ``atlas`` or
    cold), one after the other (with ``caches``, compiled) and on a started pool of one
    worker process per CPU (each worker's task compiles its own subproblems, counted); print
    a line; return its record."""
    kw = {"cell": cell, "solver": "sqp", "progress": False, "atlas": atlas}
    t0 = time.perf_counter()
    plans = plan_batch(TABLE1_LOCATIONS[:n_batch], caches=caches, **kw)
    wall = time.perf_counter() - t0
    batch = [_flip_row(p) for p in plans]
    workers = os.cpu_count() or 1
    executor = make_executor(workers=workers)
    try:  # a started pool, as a running cell keeps it: the workers' imports done
        t_warm = time.perf_counter()
        list(executor.map(_warm_worker, range(workers)))
        t_warm = time.perf_counter() - t_warm
        t0 = time.perf_counter()
        par = plan_batch(TABLE1_LOCATIONS[:n_batch], executor=executor, **kw)
        wall_par = time.perf_counter() - t0
    finally:
        executor.shutdown()
    same = all(np.allclose(a.segments[-1].q, b.segments[-1].q, atol=1e-4)
               for a, b in zip(plans, par) if len(a.segments) == len(b.segments))
    start = "cold" if atlas is None else "from the atlas"
    print(f"batch of {n_batch} (Table I 1..{n_batch}, SQP, {start}): "
          f"{sum(b['status'] == 'solved' for b in batch)}/{n_batch} solved, solve "
          f"{sum(b['solve_s'] for b in batch):.1f} s, wall {wall:.1f} s one after another; "
          f"{workers} worker processes: wall {wall_par:.1f} s "
          f"({sum(p.status == 'solved' for p in par)}/{n_batch} solved, same plans: {same}; "
          f"pool start-up {t_warm:.1f} s not counted) "
          f"(paper: {PAPER_FIVE_BURGERS_S:.0f} s for 4-5 burgers)", flush=True)
    return {"n": n_batch, "atlas": atlas is not None, "wall_s": wall, "plans": batch,
            "workers": workers, "wall_parallel_s": wall_par, "same_plans": same}


def _warm_worker(_) -> None:
    """Nothing: running it starts a pool worker and imports this module, and with it the
    planners (the subproblems a task compiles end with the task)."""


def plain_json(obj):
    """``obj`` with NaN as None and numpy numbers as floats (strict JSON)."""
    if isinstance(obj, dict):
        return {k: plain_json(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain_json(v) for v in obj]
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    return obj.item() if isinstance(obj, np.generic) else obj


def main(argv=None) -> int:
    """Command-line entry point (see the module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m bench.bench",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("which", choices=("translate", "flip", "replan"))
    parser.add_argument("--validate", metavar="FILE",
                        help="replan: the sensed places of this `flipkit validate --replan "
                             "--json` result (default: run Table I, 3 trials, position mode)")
    parser.add_argument("--contingencies", action="store_true",
                        help="replan: also prepare each plan's contingency flips and time the "
                             "re-plan that uses them")
    parser.add_argument("--locations", type=int, default=len(TABLE1_LOCATIONS), metavar="N",
                        help="flip: the first N Table I locations (default all ten)")
    parser.add_argument("--batch", type=int, default=5, metavar="K",
                        help="flip: batch of the first K locations with the SQP (0: none)")
    parser.add_argument("--full", action="store_true",
                        help="translate: the planner's NLP with the arm's clearance rows, SQP and "
                             "L-BFGS IPOPT only (default: the comparison NLP without them, four "
                             "solvers)")
    parser.add_argument("--jit", action="store_true",
                        help="translate: JIT-compile the exact-derivative peers' functions")
    parser.add_argument("--atlas", metavar="FILE",
                        help="flip: warm-start atlas for the SQP-with-atlas column (default: "
                             "the package's, when it serves the default options)")
    parser.add_argument("--no-atlas", action="store_true", help="flip: no atlas column")
    parser.add_argument("--no-ipopt", action="store_true", help="flip: no IPOPT column")
    parser.add_argument("--no-cold", action="store_true",
                        help="flip: no column of SQP plans from cold starts (with an atlas)")
    parser.add_argument("--baseline", action="store_true",
                        help="flip: also time the EE + IK baseline at the same locations")
    parser.add_argument("--cook", action="store_true",
                        help="flip: also schedule the package's cook order, serial and "
                             "prefetched, and compare the planning clocks")
    parser.add_argument("--turn", type=float, default=0.0, metavar="DEG",
                        help="flip: scoop each location along its default heading turned by "
                             "DEG degrees, stopping at the heading limit (+-60 deg of +x); the "
                             "batch and cook rows keep the default headings")
    parser.add_argument("--json", metavar="OUT", help="also write the results as JSON")
    args = parser.parse_args(argv)
    if not (math.isfinite(args.turn) and abs(args.turn) <= 60.0):
        parser.error("--turn must be a finite number of degrees in [-60, 60]")
    if not 1 <= args.locations <= len(TABLE1_LOCATIONS) or not 0 <= args.batch <= 5:
        parser.error(f"--locations must be 1..{len(TABLE1_LOCATIONS)} and --batch 0..5")
    warnings.filterwarnings("ignore", message="Solution may be inaccurate")
    cell = CellConfig()
    if args.which == "translate":
        result = bench_translate(cell, args.full, args.jit)
    elif args.which == "replan":
        print(machine())
        result = bench_replan(load_result(args.validate) if args.validate else run_validation(),
                              args.contingencies)
    else:
        atlas = None
        if not args.no_atlas:
            atlas = (Atlas.load(args.atlas, cell, SegmentOptions()) if args.atlas
                     else default_atlas(cell))
        result = bench_flip(cell, args.locations, args.batch, atlas, not args.no_ipopt,
                            args.baseline, args.cook, math.radians(args.turn),
                            not args.no_cold)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(plain_json(result), fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
