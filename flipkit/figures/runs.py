"""The computations behind the figures that need plans, simulations or sweeps.

* :func:`chain_translates` — the translate experiment of the paper's Fig. 6: one translate
  plan per pair of consecutive key points, chained (each starts where the last ended, at
  rest), gathered into one multi-segment translate :class:`~flipkit.planning.plans.plan_file.Plan`.
* :func:`track_plan` — simulated execution of a plan (as in the Table I trials of
  :mod:`flipkit.experiments.trials`) beside the plan's desired spatula position.
* :func:`nominal_trial` — one unperturbed Table I trial of a flip plan.
* :func:`flip_solve_times` / :func:`solve_time_sweep` — solve time of every subbehaviour of
  pickup-and-flip, per solver and location.
* :func:`plan_targets` — the Table I plans, once, for several validations.
* :func:`flip_execution` — one unperturbed execution (open loop or replanned) to render.
* :func:`ik_example` — the joint paths of the EE + IK baseline and of collocation at one
  location where the baseline fails (figure ``ik_failure``).
"""

from __future__ import annotations

import os
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from flipkit.baseline import run_baseline
from flipkit.baseline.classify import classify_plan
from flipkit.baseline.ee_opt import sample_times
from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.experiments.speed import warm_flip
from flipkit.experiments.compare_ik import EE, IK, RATE, plan_filename
from flipkit.experiments.perturbations import Perturbations
from flipkit.experiments.sweep import make_executor, run_sweep
from flipkit.experiments.trial_jobs import (HOLD_S, TRACK_RATE_HZ, plan_from_text, plan_text,
                                            trial_jobs)
from flipkit.experiments.trials import plan_location, run_trial
from flipkit.experiments.trials import track_plan as track_execution
from flipkit.figures.data import PlanSeries, plan_series, spatula_positions
from flipkit.model.robot import Robot
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.planner import plan_flip, plan_translate, replan_flip
from flipkit.simulation.execute import execute_plan
from flipkit.simulation.judges import judge_flip, judge_pickup, judge_scoop, landing_target


def chain_translates(points, *, solver: str = "ipopt", cell: CellConfig | None = None,
                     closed: bool = True):
    """Plan translate segments through ``points`` (m), each from the previous one's end.

    Args:
        points: Blade-centre key points (k, 3) (m), spatula flat, yaw 0.
        solver: ``"sqp"`` or ``"ipopt"``.
        cell: The cell (default :class:`~flipkit.config.CellConfig`).
        closed: Return to the first point at the end (k segments instead of k − 1).

    Returns:
        ``(plan, plans)``: one translate plan holding every segment in order (status
        ``solved`` only if every plan was solved and verified) and the individual plans
        (each with ``failure``, ``wall_time_s`` and ``report``).
    """
    cell = cell or CellConfig()
    pts = [tuple(float(v) for v in p) for p in points]
    if len(pts) < 2:
        raise ConfigError(f"need at least two key points, got {len(pts)}")
    goals = pts[1:] + (pts[:1] if closed else [])
    plans, q, caches = [], None, PlannerCaches()
    for goal in goals:
        plan = plan_translate(pts[0] if q is None else None, goal, q_start=q, cell=cell,
                              solver=solver, caches=caches)
        plans.append(plan)
        q = plan.segments[-1].q[-1]
    status = "solved" if all(p.status == "solved" for p in plans) else "failed"
    merged = Plan.from_segments("translate", cell, [p.segments[0] for p in plans],
                                status=status)
    return merged, plans


@dataclass
class Tracked:
    """A simulated execution of a plan beside the plan itself (same samples).

    Attributes:
        t: Controller sample times (s), from 0. p, p_des: Tracked and desired blade-centre
            positions (m), (n, 3). series: The plan's :class:`~flipkit.figures.data.PlanSeries`
            (segment ``boundaries`` and ``names``).
    """

    t: np.ndarray
    p: np.ndarray
    p_des: np.ndarray
    series: PlanSeries

    def segment_errors(self) -> list[dict]:
        """Per segment: ``name``, ``max_m`` and ``rms_m`` of |p − p_des| (m)."""
        err = np.linalg.norm(self.p - self.p_des, axis=1)
        b, out = self.series.boundaries, []
        for k, name in enumerate(self.series.names):
            sel = (self.t >= b[k] - 1e-9) & (self.t <= b[k + 1] + 1e-9)
            out.append({"name": name, "max_m": float(err[sel].max()),
                        "rms_m": float(np.sqrt(np.mean(err[sel] ** 2)))})
        return out


def track_plan(plan, rate_hz: float | None = None) -> Tracked:
    """Simulated execution of ``plan`` exactly as the Table I trials execute it
    (:func:`flipkit.experiments.trials.track_plan`: joint PD per segment with the plan's torques as
    feed-forward, the arm carrying the burger where the segment does, each segment starting
    from the previous one's tracked end), beside the desired spatula position.

    The desired position is the spatula position along the cubic Hermite spline through
    the nodes (q, q̇) — the controller's reference; the spline is local to each node
    interval, so one spline through all segments' nodes equals the per-segment ones.
    """
    series = plan_series(plan)
    t, p, _, _, _ = track_execution(plan, rate_hz=rate_hz or TRACK_RATE_HZ)
    q_des = CubicHermiteSpline(series.t, series.q, series.qd, axis=0)(t)
    robot = Robot(plan.cell())
    return Tracked(t, p, spatula_positions(robot, q_des), series)


def nominal_trial(plan) -> dict:
    """One Table I trial of a solved flip plan without perturbation (burger exactly at p^b,
    nominal grill height, μ and mass): :func:`flipkit.experiments.trials.run_trial`'s result
    (``ok`` per stage, ``failure``, ``tracking``)."""
    none = Perturbations(position_sigma=0.0, grill_offset=0.0, mu_scale=(1.0, 1.0),
                         mass_scale=(1.0, 1.0))
    return run_trial(trial_jobs(plan_text(plan), 1, 0, none, TRACK_RATE_HZ)[0])


# ------------------------------------------------------------------ solve times
def flip_solve_times(item) -> dict:
    """Plan pickup-and-flip at one location with one solver and report the solve times.

    Args:
        item: ``{"location": [x, y, z], "solver": "sqp" | "ipopt"}``.

    Returns:
        JSON values: ``location``, ``solver``, ``status``, ``failure``, ``wall_time_s`` (the
        whole call), ``warm_up_s`` (the SQP's compile before it, excluded from the solve
        times: every item compiles its own) and
        ``segments``: ``[{name, status, wall_time_s, iterations, T}]`` (solver wall time, s;
        executed duration T, s) for the segments attempted.
    """
    location, solver = [float(v) for v in item["location"]], str(item["solver"])
    cell, caches = CellConfig(), PlannerCaches()
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Solution may be inaccurate")
        warm = warm_flip(caches, cell, location) if solver == "sqp" else 0.0
        t0 = time.perf_counter()
        plan = plan_flip(location, cell=cell, solver=solver, caches=caches)
        wall = time.perf_counter() - t0
    return {"location": location, "solver": solver, "status": plan.status,
            "failure": plan.failure, "wall_time_s": wall, "warm_up_s": warm,
            "segments": [{"name": s.name, "status": s.solver.status,
                          "wall_time_s": s.solver.wall_time_s,
                          "iterations": s.solver.iterations, "T": s.T}
                         for s in plan.segments]}


def solve_workers(items: int | None = None) -> int:
    """Local worker processes of :func:`solve_time_sweep`: one per CPU (at most one per item),
    so that each solve has a core to itself when nothing else runs."""
    n = os.cpu_count() or 1
    return max(1, min(n, items)) if items is not None else n


def solve_time_sweep(locations, solvers=("sqp", "ipopt"), scheduler: str | None = None,
                     progress: bool = False, workers: int | None = None) -> list[dict]:
    """:func:`flip_solve_times` for every (location, solver), location-major.

    Locally the runs go to ``workers`` worker processes (default :func:`solve_workers`: one
    per CPU), one solve per process at a time, so that on an otherwise idle machine no two
    solves compete for a core and the times are those of one core (BLAS and OpenMP are
    single-threaded in the workers); ``workers=0`` runs them one after the other in this
    process. The slow solver's runs (IPOPT) are handed out first, so that the SQP's short
    ones fill the end. With a Dask ``scheduler`` address they are spread over its workers.
    """
    items = [{"location": [float(v) for v in loc], "solver": s}
             for loc in locations for s in solvers]
    order = sorted(range(len(items)), key=lambda i: items[i]["solver"] != "ipopt")
    workers = solve_workers(len(items)) if workers is None else int(workers)
    if scheduler:
        executor = make_executor(scheduler)
    else:
        executor = make_executor(None, workers=workers) if workers > 0 else None
    try:
        rows = run_sweep(flip_solve_times, [items[i] for i in order], executor,
                         progress=progress, desc="solve times")
    finally:
        if executor is not None:
            executor.shutdown()
    out = [None] * len(items)
    for i, row in zip(order, rows):
        out[i] = row
    return out


def solve_time_table(rows, names) -> dict:
    """Gather :func:`flip_solve_times` rows into the form of
    :func:`~flipkit.figures.draw.plot_solve_times`.

    Returns:
        ``times`` and ``failed``: ``{solver: {name: [s, ...]}}`` for the segments that were
        solved and those that were not (``"total"``: whole plans, solved ones only, in
        ``times``); ``solved``: ``{solver: [plans solved, plans]}``.
    """
    times, failed, solved = {}, {}, {}
    for r in rows:
        s = r["solver"]
        times.setdefault(s, {n: [] for n in names})
        failed.setdefault(s, {n: [] for n in names})
        solved.setdefault(s, [0, 0])
        solved[s][1] += 1
        for seg in r["segments"]:
            if seg["name"] in names:
                (times if seg["status"] == "solved" else failed)[s][seg["name"]].append(
                    seg["wall_time_s"])
        if r["status"] == "solved":
            solved[s][0] += 1
            if "total" in names:
                times[s]["total"].append(sum(seg["wall_time_s"] for seg in r["segments"]))
    return {"times": times, "failed": failed, "solved": solved}



# ------------------------------------------------------------------ Table I plans and runs
def plan_location_text(job: dict) -> dict:
    """Plan pickup-and-flip at one location as :func:`flipkit.experiments.trials.plan_location`
    does (a sweep worker) and return the plan file's text instead of its path.

    Args:
        job: ``{"location": [3] (m), "solver": str}``, optionally ``"cell"`` (as
            :func:`~flipkit.experiments.trials.plan_location`).

    Returns:
        ``{"status", "reason", "time_s" (s, planning wall time), "text" (the plan file's text,
        or None when planning failed)}``.
    """
    with tempfile.TemporaryDirectory(prefix="flipkit-plan-") as tmp:
        r = plan_location({**job, "plans_dir": tmp})
        text = Path(r["path"]).read_text() if r["path"] else None
    return {"status": r["status"], "reason": r["reason"], "time_s": r["time_s"], "text": text}


def plan_targets(locations, solver: str = "auto", executor=None, progress: bool = False,
                 cache_dir=None, cell: dict | None = None):
    """Plan pickup-and-flip at every location on the sweep and return the
    :func:`flipkit.experiments.trials.validate` targets ``[(location, plan_info, plan_text or
    None)]``, so that one set of plans serves several validations.

    With ``cache_dir`` (:func:`flipkit.experiments.sweep.run_sweep`'s cache, keyed by the
    location, the solver and ``cell``) a plan made earlier by the same code is read back, not
    planned again: the caller must give each code version its own directory
    (:func:`flipkit.figures.pipeline.sweep_cache`). ``cell``: ``{dotted name: value}``, plan
    for the default cell with those values (cold starts).
    """
    extra = {"cell": {k: float(v) for k, v in cell.items()}} if cell else {}
    jobs = [{"location": [float(v) for v in loc], "solver": solver, **extra}
            for loc in locations]
    infos = run_sweep(plan_location_text, jobs, executor, cache_dir, progress=progress,
                      desc="plans")
    return [(job["location"], {k: r[k] for k in ("status", "reason", "time_s")},
             r["text"] if r["status"] == "solved" else None) for job, r in zip(jobs, infos)]


def flip_execution(plan_text: str, mode: str = "feedforward", replan: bool = True):
    """One unperturbed execution of a plan file's text (the nominal cell), through the
    sense-plan-act pipeline with ``replan``: ``(execution, ok)``, ``ok`` = {stage: bool}
    (cumulative, the judges of Table I) — the run :mod:`flipkit.simulation.animate` renders."""
    replan_fn = replan_flip if replan else None
    ex = execute_plan(plan_from_text(plan_text), mode, None, hold=HOLD_S, replan=replan_fn)
    b = ex.bounds
    ok = {"scoop": judge_scoop(ex.run, b["scoop"]).ok}
    ok["pickup"] = ok["scoop"] and judge_pickup(ex.run, b["pickup"]).ok
    ok["flip"] = ok["pickup"] and judge_flip(ex.run, b["flip"], landing_target(ex.plan)).ok
    return ex, ok


# ------------------------------------------------------------------ EE + IK vs collocation
def example_location(entries):
    """The location shown beside the maps of ``ik_failure``: the first entry (in order) whose
    baseline fails with a joint path to show (kinematic, dynamic or time-scalable) while the
    collocation plan passes the judge; else the first whose baseline fails while collocation
    solves; else None."""
    def coll_ok(e, judged):
        c = e["collocation"]
        return c["status"] == "solved" and (not judged or (c.get("judge") or {}).get(
            "status", "solved") == "solved")

    for judged, classes in ((True, ("kinematic", "dynamic", "time_scalable")), (False, None)):
        for e in entries:
            b = e["ee_ik"]
            if b["status"] != "solved" and coll_ok(e, judged) and (
                    classes is None or b.get("class") in classes):
                return [float(v) for v in e["location"]]
    return None


def ik_example(location, plans_dir=None, solver: str = "auto") -> dict:
    """Both methods' joint paths at ``location`` (m), on one time axis each, at the judge's
    rate (:data:`flipkit.experiments.compare_ik.RATE`).

    The baseline is re-run as ``compare-ik`` runs it; the collocation plan is read from
    ``plans_dir`` (``compare-ik --plans``) when it holds one, else planned with ``solver``.

    Returns:
        ``{"location", "ee_ik": path, "collocation": path}``, each path ``{"t" (s), "q"
        (rad), "boundaries" (s), "names", "failed" (subbehaviour or None), "label"}``.
    """
    res = run_baseline(location, rate=RATE, ik=IK, ee=EE)
    ts, qs, edges, t0 = [], [], [0.0], 0.0
    for track in res.tracks:
        ts.append(t0 + track.t)
        qs.append(track.q)
        t0 += track.t[-1]
        edges.append(t0)
    f = res.failure
    ee = {"t": np.concatenate(ts), "q": np.vstack(qs), "boundaries": edges,
          "names": [tr.name for tr in res.trajectories], "failed": res.subbehavior,
          "label": (f"{f.subbehavior}: {f.reason.replace('_', ' ')}, {f.detail}" if f
                    else "solved")}
    path = Path(plans_dir) / plan_filename(location, solver) if plans_dir else None
    if path is not None and path.exists():
        plan = Plan.load(path)
    else:
        plan = plan_flip(location, solver=solver)
    ts, qs, edges, t0 = [], [], [0.0], 0.0
    for seg in plan.segments:
        t = sample_times(seg.T, RATE)
        ts.append(t0 + t)
        qs.append(CubicHermiteSpline(seg.t, seg.q, seg.qd, axis=0)(t))
        t0 += seg.T
        edges.append(t0)
    bad = next((v for v in classify_plan(plan, RATE) if v.status != "solved"), None)
    coll = {"t": np.concatenate(ts), "q": np.vstack(qs), "boundaries": edges,
            "names": [seg.name for seg in plan.segments],
            "failed": bad.subbehavior if bad else None,
            "label": (f"{plan.status}; judge: " + (f"{bad.subbehavior}: {bad.reason}"
                                                   if bad else "passes"))}
    return {"location": [float(v) for v in location], "ee_ik": ee, "collocation": coll}


__all__ = ["chain_translates", "Tracked", "track_plan", "nominal_trial", "flip_solve_times",
           "solve_workers", "solve_time_sweep", "solve_time_table", "plan_location_text",
           "plan_targets", "flip_execution", "example_location", "ik_example"]
