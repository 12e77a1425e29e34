"""Joint-space collocation against the end-effector-space + IK baseline, location by location.

The paper's motivating claim (Sec. I) is that planning in end-effector space and tracking with
inverse kinematics fails where joint-space collocation succeeds. :func:`compare_ik` runs both
on each burger location — :func:`flipkit.planning.planners.planner.plan_flip` (its plan re-checked by
:func:`flipkit.planning.plans.verify.verify_plan`) and :func:`flipkit.baseline.run_baseline` — on the sweep
executor, and summarises success fractions, the baseline's failure reasons and classes, and
the median wall time per subbehaviour of each method.

Each location's task compiles both methods' subproblems before it times them
(:func:`~flipkit.experiments.speed.warm_flip`,
:func:`~flipkit.baseline.ee_scp.compile_subproblems`), into caches of its own: the times are
planning with compiled subproblems, as a running cell's are, whichever worker ran what before.

One judge for both (:mod:`flipkit.baseline.classify`): the baseline's joint path (closed-form
IK, the branch continuous with the start, :data:`RATE` Hz) and the collocation plan resampled at
the same rate (cubic Hermite between nodes) face the same checks and thresholds; the
collocation plan's verdict is recorded under ``judge`` beside its solver status.
"""

from __future__ import annotations

import math
import statistics
import time
from collections import Counter
from pathlib import Path

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors import targets as tg
from flipkit.baseline import CompiledProblems, run_baseline
from flipkit.baseline.classify import FAILURE_CLASSES, REASONS, classify_plan
from flipkit.baseline.ee_scp import compile_subproblems
from flipkit.config import LOCATION_SETS, CellConfig
from flipkit.errors import FlipkitError, InvalidChoiceError, UnreachableError
from flipkit.experiments.speed import warm_flip
from flipkit.experiments.sweep import run_sweep
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.planner import plan_flip
from flipkit.planning.plans.verify import verify_plan
from flipkit.solvers.names import SOLVERS

METHODS = ("collocation", "ee_ik")
_PRIVATE = "_segment_time_s"  # per-segment solve times, used by the summary only
RATE = 500.0  # Hz: the judge's sample rate for both methods, a UR e-Series servo rate
IK = "analytic"  # the baseline's IK: the UR10's closed form (flipkit.model.ur_ik)
EE = "scp"  # the baseline's EE optimisation: position, orientation, duration free


def _number(x) -> float | None:
    """``x`` as a float, or ``None`` when it is missing or not finite (JSON has no NaN)."""
    return None if x is None or not math.isfinite(x) else float(x)


def plan_filename(location, solver: str) -> str:
    """File name of the plan of ``location`` (m) made by ``solver``."""
    return "plan_" + "_".join(f"{v:+.3f}" for v in location) + f"_{solver}.json"


def location_label(job: dict) -> str:
    """A planning job (``location`` m, ``solver``) as messages name it."""
    x, y, z = job["location"]
    return f"location ({x:.3f}, {y:.3f}, {z:.3f}) solver {job['solver']}"


def _collocation(location, solver: str, plans_dir) -> dict:
    caches, t0 = PlannerCaches(), time.perf_counter()
    try:
        if solver != "ipopt":  # the SQP's subproblems compiled before the clock starts
            warm_flip(caches, CellConfig(), location)
            t0 = time.perf_counter()
        plan = plan_flip(location, solver=solver, caches=caches)
    except FlipkitError as exc:
        return {"status": "failed", "reason": str(exc), "time_s": time.perf_counter() - t0,
                _PRIVATE: {}}
    status, reason, report = plan.status, plan.failure, verify_plan(plan)
    if status == "solved" and not report.ok:
        status, reason = "failed", f"verify: {report.summary()}"
    if plans_dir is not None:
        plan.to_json(Path(plans_dir) / plan_filename(location, solver))
    return {"status": status, "reason": reason, "time_s": float(plan.wall_time_s),
            "judge": _judge(plan) if status == "solved" else None,
            _PRIVATE: {s.name: float(s.solver.wall_time_s) for s in plan.segments}}


def _judge(plan) -> dict:
    """The baseline's judge on the collocation plan at :data:`RATE` (first failing segment)."""
    verdicts = classify_plan(plan, RATE)
    bad = next((v for v in verdicts if v.status != "solved"), None)
    if bad is None:
        return {"status": "solved", "reason": None, "class": None, "subbehavior": None,
                "amount": None}
    return {"status": "failed", "reason": bad.reason, "class": bad.failure_class,
            "subbehavior": bad.subbehavior, "amount": _number(bad.amount)}


def _ee_ik(location) -> dict:
    problems = CompiledProblems()  # compiled before the baseline's clock starts
    compile_subproblems(CellConfig(), location, problems)
    res = run_baseline(location, rate=RATE, ik=IK, ee=EE, problems=problems)
    failure = res.failure
    return {"status": res.status, "reason": res.reason,
            "class": failure.failure_class if failure else None,
            "subbehavior": res.subbehavior, "amount": _number(res.amount),
            "time_scaling": _number(failure.time_scaling) if failure else None,
            "time_s": float(sum(v["ee"] + v["ik"] for v in res.time_s.values())),
            "time_breakdown_s": res.time_s,
            "durations_s": {t.name: float(t.T) for t in res.trajectories},
            "segments": [{"subbehavior": v.subbehavior, "status": v.status, "reason": v.reason,
                          "class": v.failure_class, "amount": _number(v.amount)}
                         for v in res.segments]}


def worst_class(ee_ik: dict) -> str:
    """The worst class over a baseline record's subbehaviours (each judged on its own, the IK
    restarting after a failure): ``ee`` > ``kinematic`` > ``dynamic`` > ``time_scalable`` >
    ``solved``; the first failure's class when the record lists no segments."""
    order = ("solved", "time_scalable", "dynamic", "kinematic", "ee")
    classes = [s["class"] or "solved" for s in ee_ik.get("segments") or []]
    if not classes:
        return ee_ik.get("class") or "solved"
    return max(classes, key=order.index)


def compare_location(job: dict) -> dict:
    """Both methods at one location (the sweep worker).

    Args:
        job: ``{"location": [x, y, z] (m), "solver": "sqp" | "ipopt", "plans_dir": str or
            None}``; with a directory the collocation plan is written there
            (:func:`plan_filename`).

    Returns:
        ``{"location", "collocation": {status, reason, time_s (s, the whole planning call),
        judge: {status, reason, class, subbehavior, amount} or None, ...}, "ee_ik": {status,
        reason, class, subbehavior, amount, time_scaling, time_s (s, EE + IK of every
        subbehaviour run), time_breakdown_s: {subbehaviour: {"ee": s, "ik": s}}, durations_s:
        {subbehaviour: T (s), the baseline's chosen duration}, segments: [{subbehavior,
        status, reason, class, amount}, ...] (every subbehaviour run)}}``.
    """
    loc = [float(v) for v in job["location"]]
    return {"location": loc, "collocation": _collocation(loc, job["solver"], job["plans_dir"]),
            "ee_ik": _ee_ik(loc)}


def _median(values) -> float | None:
    values = [v for v in values if v is not None]
    return float(statistics.median(values)) if values else None


def summarize(records: list) -> dict:
    """Success fraction per method, failure counts and median wall times (s) per subbehaviour.

    ``ik_failure_classes`` counts the class of each failed baseline's first failure,
    ``ik_worst_classes`` the worst class over its subbehaviours (:func:`worst_class`).

    ``collocation_failures`` counts the subbehaviour where each failed plan stopped (the
    prefix of its reason; ``other`` when there is none).
    """
    n = len(records)
    frac = {m: sum(r[m]["status"] == "solved" for r in records) / n if n else None
            for m in METHODS}
    reasons = Counter(r["ee_ik"]["reason"] for r in records if r["ee_ik"]["status"] != "solved")
    classes = Counter(r["ee_ik"]["class"] for r in records if r["ee_ik"]["status"] != "solved")
    worst = Counter(worst_class(r["ee_ik"]) for r in records)
    judged = Counter((r["collocation"].get("judge") or {}).get("class") or "solved"
                     for r in records if r["collocation"]["status"] == "solved")
    stops = Counter()
    for r in records:
        c = r["collocation"]
        if c["status"] != "solved":
            head = (c["reason"] or "").split(":")[0]
            stops[head if head in FLIP_NAMES else "other"] += 1
    coll = {s: _median(r["collocation"][_PRIVATE].get(s) for r in records)
            for s in FLIP_NAMES}
    coll["total"] = _median(r["collocation"]["time_s"] for r in records)
    ee = {s: {part: _median(r["ee_ik"]["time_breakdown_s"].get(s, {}).get(part)
                            for r in records)
              for part in ("ee", "ik")} for s in FLIP_NAMES}
    return {"locations": n, "success_fraction": frac,
            "ik_failure_reasons": {k: reasons.get(k, 0) for k in REASONS},
            "ik_failure_classes": {k: classes.get(k, 0) for k in FAILURE_CLASSES},
            "ik_worst_classes": {k: worst.get(k, 0) for k in ("solved",) + FAILURE_CLASSES},
            "collocation_judge": {k: judged.get(k, 0) for k in ("solved",) + FAILURE_CLASSES},
            "ik_failure_subbehaviors": {s: sum(r["ee_ik"]["subbehavior"] == s for r in records)
                                        for s in FLIP_NAMES},
            "collocation_failures": dict(sorted(stops.items())),
            "median_time_s": {"collocation": coll, "ee_ik": ee}}


def check_locations(locations, cell: CellConfig | None = None) -> list[list[float]]:
    """``locations`` (m) as lists of floats, each checked to lie on ``cell``'s grill.

    Raises:
        UnreachableError: A location off the grill (named by its index, from 1).
    """
    cell, locs = cell or CellConfig(), []
    for k, loc in enumerate(locations, 1):
        try:
            locs.append([float(v) for v in tg.check_location(cell, loc)])
        except UnreachableError as exc:
            raise UnreachableError(f"location {k}: {exc}") from None
    return locs


def compare_ik(locations, solver: str = "sqp", executor=None, cache_dir=None, plans_dir=None,
               progress: bool = True, cell: CellConfig | None = None) -> dict:
    """Run both methods at every location and summarise.

    Args:
        locations: Burger locations p^b (m), on the grill.
        solver: Collocation solver, ``"sqp"`` or ``"ipopt"``.
        executor: Sweep executor (:func:`flipkit.experiments.sweep.make_executor`); ``None`` runs here.
        cache_dir: Sweep cache directory, or ``None``.
        plans_dir: Directory to write the collocation plans to, or ``None``.
        progress: Show a progress bar.
        cell: Only used to check the locations (the methods plan in the default cell).

    Returns:
        ``{"locations": [{"location", "collocation": {status, reason, time_s, judge},
        "ee_ik": {status, reason, class, subbehavior, amount, time_scaling, time_s,
        time_breakdown_s}}, ...], "summary": summarize(...)}``.

    Raises:
        UnreachableError: A location off the grill (named by its index, from 1).
        InvalidChoiceError: Unknown solver.
    """
    if solver not in SOLVERS:
        raise InvalidChoiceError("solver", solver, SOLVERS)
    locs = check_locations(locations, cell)
    if plans_dir is not None:
        Path(plans_dir).mkdir(parents=True, exist_ok=True)
        plans_dir = str(Path(plans_dir).resolve())
    jobs = [{"location": loc, "solver": solver, "plans_dir": plans_dir, "judge_rate": RATE,
             "ik": IK, "ee": EE} for loc in locs]  # judge and IK in the job: caches of other setups miss
    records = run_sweep(compare_location, jobs, executor, cache_dir, progress=progress,
                        desc="compare-ik", label_fn=location_label)
    entries = [{"location": r["location"],
                "collocation": {k: r["collocation"][k]
                                for k in ("status", "reason", "time_s", "judge")},
                "ee_ik": r["ee_ik"]} for r in records]
    return {"locations": entries, "summary": summarize(records)}


def format_summary(summary: dict) -> str:
    """A few lines of text: success fractions, baseline failure reasons, median times (s)."""
    f, t = summary["success_fraction"], summary["median_time_s"]
    lines = [f"{summary['locations']} locations: collocation {f['collocation']:.0%} solved, "
             f"EE+IK {f['ee_ik']:.0%} solved"]
    bad = {k: v for k, v in summary["ik_failure_reasons"].items() if v}
    lines.append("EE+IK failures: " + (", ".join(f"{k} {v}" for k, v in bad.items()) or "none"))
    cls = {k: v for k, v in summary["ik_failure_classes"].items() if v}
    lines.append("  by class: " + (", ".join(f"{k} {v}" for k, v in cls.items()) or "none"))
    lines.append("collocation plans under the same judge: " + ", ".join(
        f"{k} {v}" for k, v in summary["collocation_judge"].items() if v))
    fmt = lambda v: "-" if v is None else f"{v:.3f}"  # noqa: E731
    for s in FLIP_NAMES:
        lines.append(f"  {s:<13} collocation {fmt(t['collocation'][s]):>7} s   EE "
                     f"{fmt(t['ee_ik'][s]['ee']):>7} s + IK {fmt(t['ee_ik'][s]['ik']):>7} s")
    return "\n".join(lines)


__all__ = ["compare_location", "compare_ik", "summarize", "format_summary",
           "worst_class", "location_label", "plan_filename", "check_locations"]
