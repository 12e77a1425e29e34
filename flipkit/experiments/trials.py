"""Simulated execution of pickup-and-flip plans under perturbations (the paper's Table I trials).

One trial (:func:`run_trial`): the plan is executed closed-loop in the MuJoCo cell
(:func:`flipkit.simulation.execute.execute_plan`): the arm with its spatula is simulated with the
burger lying on the grill, misplaced and with perturbed physics (:class:`Perturbations`,
drawn from :func:`~flipkit.experiments.perturbations.trial_rng` of the seed, the trial and the
location), the blade colliding with the grill and the burger; the joint controller is the
job's ``mode`` (``"feedforward"``: plan torques plus PD; ``"position"``: the robot's own PD
position control on servo-rate, delayed desired states). The paper's judges (Sec. V) decide
scoop, pickup and flip. A stage counts only if the previous ones succeeded, as in Table I.

:func:`track_plan` (the older pinocchio-only tracking, whose poses drove the blade of
:class:`flipkit.simulation.prescribed_blade.BurgerSim`) is kept for the figures that use it.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import asdict
from functools import partial
from pathlib import Path

import numpy as np

from flipkit.behaviors import targets as tg
from flipkit.simulation.judges import (FLIP_CONTACT_FRACTION, LANDING_TOL, SCOOP_OVERLAP,
                                      judge_flip, judge_pickup, judge_scoop, landing_target)
from flipkit.config import CellConfig, known_physics, with_parameter
from flipkit.config.task import HEADING_LIMIT
from flipkit.errors import ConfigError, FlipkitError, InvalidChoiceError, UnreachableError
from flipkit.experiments.contingent import attach, replanner, summary as contingency_summary
from flipkit.experiments.compare_ik import location_label, plan_filename
from flipkit.experiments.pauses import pause_summary
from flipkit.experiments.ratios import success_intervals
from flipkit.experiments.perturbations import (Perturbations, check_seed, check_trials,
                                              trial_rng)
from flipkit.experiments.serve_trials import validate_serve
from flipkit.experiments.slides import slide_summary
from flipkit.experiments.sweep import run_sweep
from flipkit.experiments.trial_jobs import (HOLD_S, TRACK_RATE_HZ, lookahead_of, merge_tracking,
                                            job_cell, judged, safety_summary, stage_verdicts,
                                            plan_from_text, servo_physics, trial_jobs,
                                            trial_key, trial_label, warm_replan)
from flipkit.model.robot import Robot
from flipkit.planning.planners.atlas import default_atlas
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.servo_command import DEFAULT_COMMAND
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.planner import plan_flip, replan_flip
from flipkit.planning.plans.verify import require_verified
from flipkit.simulation.execute import execute_plan
from flipkit.simulation.modes import FEEDFORWARD, MODES
from flipkit.simulation.tracking import track
from flipkit.solvers.names import SOLVERS

STAGES = ("scoop", "pickup", "flip")


def track_plan(plan: Plan, plant_cell: CellConfig | None = None, rate_hz=TRACK_RATE_HZ):
    """Track every segment of ``plan`` with the PD controller, the plan's u as feed-forward.

    Args:
        plan: A flip plan. plant_cell: The real cell (burger mass); default the plan's.
        rate_hz: Controller rate (Hz).

    Returns:
        ``(t, p, R, bounds, errors)``: tracked spatula poses on one clock from 0 (s, m,
        N×3×3), ``{segment: (t_start, t_end)}`` (s) and ``{segment: {"max_m", "sum_sq_m2",
        "n"}}``, the spatula position tracking error (m) of each segment.
    """
    cell = plan.cell()
    plant_cell = plant_cell or cell
    plants = {w: Robot(plant_cell, with_burger=w) for w in (False, True)}
    ts, ps, rs, bounds, errors, start, q0 = [], [], [], {}, {}, 0.0, None
    for seg in plan.segments:
        res = track(plan.robot_for(seg, cell), seg.t, seg.q, seg.qd, u_ff=seg.u,
                    rate_hz=rate_hz, mismatch=plants["burger" in seg.payload], q0=q0)
        q0, e = res.q[-1], res.position_error
        errors[seg.name] = {"max_m": float(e.max()), "sum_sq_m2": float(np.sum(e**2)),
                            "n": int(e.size)}
        t = start + res.t
        keep = t > ts[-1][-1] + 1e-9 if ts else np.ones(t.size, bool)
        ts.append(t[keep]), ps.append(res.p[keep]), rs.append(res.R[keep])
        bounds[seg.name] = (start, start + seg.T)
        start += seg.T
    return np.concatenate(ts), np.concatenate(ps), np.concatenate(rs), bounds, errors


def _failure(scoop, pickup, flip, run) -> dict | None:
    """The first failed stage: stage, reason and the measured amount (units in the reason)."""
    if not scoop.ok:
        return {"stage": "scoop", "reason": "overlap" if scoop.overlap < SCOOP_OVERLAP
                else "under_blade", "amount": scoop.overlap}
    if not pickup.ok:
        if not pickup.off_grill:
            return {"stage": "pickup", "reason": "on_grill", "amount": pickup.clearance}
        return {"stage": "pickup", "reason": "off_spatula", "amount": pickup.gap}
    if flip.ok:
        return None
    if flip.contact_fraction < FLIP_CONTACT_FRACTION:
        return {"stage": "flip", "reason": "contact", "amount": flip.contact_fraction}
    if not flip.upside_down:
        return {"stage": "flip", "reason": "not_flipped", "amount": flip.up_z}
    if not flip.on_grill:
        return {"stage": "flip", "reason": "not_on_grill",
                "amount": float(run.burger_pos[-1, 2] - run.grill_height)}
    miss = float(np.max(np.abs(flip.offset)))
    return {"stage": "flip", "reason": "missed_spot" if miss > LANDING_TOL else "other",
            "amount": miss}


def run_trial(job: dict) -> dict:
    """One simulated execution (the sweep worker).

    Args:
        job: ``plan_text`` (a solved flip plan file's text), ``trial`` (index), ``seed``,
            ``perturbations`` (:class:`Perturbations` fields), ``rate_hz`` (joint controller
            rate, Hz), ``mode`` (:data:`flipkit.simulation.modes.MODES`; default ``"feedforward"``),
            ``command`` (position mode's command stream,
            :data:`flipkit.planning.plans.servo_command.COMMANDS`; default ``"compensated"``),
            optionally ``replan`` (bool, see :func:`validate`), ``contingencies`` (the
            plan's contingency record, :func:`flipkit.experiments.contingent.prepare`: the
            re-plan hands them out) and ``physics``
            (``{dotted name: value}``, keys of :data:`flipkit.config.PHYSICAL_RANGES`: the
            simulated cell's parameters set by :func:`flipkit.config.with_parameter`; the plan
            and any replan keep the nominal model, and the position commands use the values
            the cell knows, :data:`flipkit.config.KNOWN_PARAMETERS`, through
            :func:`flipkit.config.known_physics`).

    Returns:
        ``trial``, ``ok`` ({stage: bool}, cumulative), ``independent`` ({stage: bool}, each
        judge on its own, whatever the earlier stages did), ``failure`` (first failed stage:
        ``stage``, ``reason``, ``amount`` — scoop overlap fraction, pickup clearance above
        the grill (``on_grill``) or gap above the blade (``off_spatula``) m, flip contact
        fraction / up-axis z / height m / landing offset m — or ``None``),
        ``perturbation`` (the draw), ``tracking`` (spatula position error per segment, see
        :func:`track_plan`) and ``mode``.
    """
    plan = plan_from_text(job["plan_text"])
    mode = job.get("mode", FEEDFORWARD)
    draw = Perturbations(**job["perturbations"]).draw(
        trial_rng(job["seed"], job["trial"], plan.burger["location"]))
    cell = job_cell(plan.cell(), job)
    replan = None
    if job.get("replan", False):  # this trial's re-plans share caches, compiled before it runs
        caches = PlannerCaches()
        warm_replan(replan_flip, plan, plan.step("release").landing.get(
            "burger_on_blade", (0.0, 0.0))[:2], caches, keep=False)
        replan = (replanner(plan, job["contingencies"], caches) if "contingencies" in job
                  else partial(replan_flip, caches=caches))
    command = job.get("command", DEFAULT_COMMAND)
    servo = known_physics(plan.cell().physics, job.get("physics") or {})
    ex = execute_plan(plan, mode, draw, cell=cell, hold=HOLD_S, rate_hz=job["rate_hz"],
                      replan=replan, command=command, servo=servo)
    run, bounds, errors = ex.run, ex.bounds, ex.errors
    touch_xy, touch_tilt = _touchdown(run, bounds["flip"][0])
    scoop, pickup = judged(judge_scoop, run, bounds["scoop"]), judged(judge_pickup, run,
                                                                      bounds["pickup"])
    flip = judged(judge_flip, run, bounds["flip"], landing_target(ex.plan))
    ok, independent, failure = stage_verdicts(
        {"scoop": scoop, "pickup": pickup, "flip": flip},
        lambda: _failure(scoop, pickup, flip, run), ex.safety, bounds)
    return {"trial": job["trial"], "ok": ok, "failure": failure, "independent": independent,
            "safety": ex.safety,
            "perturbation": draw, "tracking": errors, "mode": mode, "command": command,
            "landing_xy": [float(v) for v in run.burger_pos[-1, :2]],
            "touchdown_xy": touch_xy, "touchdown_tilt_deg": touch_tilt,
            "predicted_landing_xy": _predicted(ex.plan),
            "replan": {"sensed_on_blade": ex.sensed_on_blade, "failure": ex.replan_failure,
                       "time_s": ex.replan_time_s, "wait_s": ex.replan_wait_s}
            if replan is not None else None, "physics": dict(job.get("physics") or {})}


def _touchdown(run, flip_start: float) -> tuple[list | None, float | None]:
    """At the burger's first contact with the grill after the flip's start: its centre (x, y)
    (m), and the angle (deg) between its top face's normal and straight down (the patty's
    middle strip, whose pose is the burger's; 0 for a burger that lands flat and upside
    down); ``(None, None)`` if it never touches."""
    k = run.touchdown(flip_start)
    if k is None:
        return None, None
    tilt = float(np.degrees(np.arccos(np.clip(-run.burger_rot[k][2, 2], -1.0, 1.0))))
    return [float(v) for v in run.burger_pos[k, :2]], tilt


def _predicted(plan) -> list | None:
    """The plan's predicted landing point (x, y) (m), or ``None`` without one."""
    flip = plan.segment("flip")
    return None if flip is None or not flip.landing else [float(v) for v in flip.landing["point"][:2]]


def location_entry(location, trials: int, results: list, plan_info: dict) -> dict:
    """The output of one location from its trial results (empty when the plan failed: every
    trial then fails at stage ``plan``).

    ``success`` counts cumulative stages (a pickup counts only after a successful scoop, as
    in the paper's Table I); ``independent`` counts each judge's passes on its own;
    ``landings`` lists each trial's final burger position (x, y) (m), whether it flipped, the
    executed plan's predicted landing, where the burger first touched the grill after the
    flip's start (``touchdown_xy``) and how far from flat (``touchdown_tilt_deg``) and, with
    ``replan``, what was sensed.
    """
    if not results:
        fails = [{"trial": i, "stage": "plan", "reason": plan_info.get("reason"),
                  "amount": None} for i in range(trials)]
        return {"location": list(location), "plan": plan_info, "trials": trials,
                "success": dict.fromkeys(STAGES, 0), "independent": dict.fromkeys(STAGES, 0),
                "failures": fails, "tracking": {}, "landings": []}
    return {"location": list(location), "plan": plan_info, "trials": trials,
            "safety": safety_summary([r.get("safety") for r in results]),
            "success": {s: sum(r["ok"][s] for r in results) for s in STAGES},
            "independent": {s: sum(r["independent"][s] for r in results) for s in STAGES},
            "failures": [{"trial": r["trial"], **r["failure"], "perturbation": r["perturbation"]}
                         for r in results if r["failure"]],
            "tracking": merge_tracking([r["tracking"] for r in results]),
            "landings": [{"trial": r["trial"], "flipped": r["ok"]["flip"],
                          "xy": r.get("landing_xy"), "predicted_xy": r.get("predicted_landing_xy"),
                          "touchdown_xy": r.get("touchdown_xy"),
                          "touchdown_tilt_deg": r.get("touchdown_tilt_deg"),
                          "replan": r.get("replan")} for r in results]}


def plan_location(job: dict) -> dict:
    """Plan pickup-and-flip at one location as `flipkit plan flip` does (from the package's
    atlas when it serves) and write the plan file (a sweep worker).

    Args:
        job: ``{"location": [3] (m), "solver": str, "plans_dir": str}``, optionally
            ``"cell": {dotted name: value}`` (keys of :data:`flipkit.config.PHYSICAL_RANGES`):
            plan for the default cell with those values, from cold starts (the package's
            atlas serves the default cell only); ``"atlas": False``: from cold starts.
            ``"heading"``: the scoop heading (rad; default the location's own).

    Returns:
        ``{"status", "reason", "time_s" (s, planning wall time: in a task of its own, as a
        new ``flipkit plan flip`` process, it includes compiling the SQP's subproblems),
        "path" (plan file or None)}``.
    """
    cell = CellConfig()
    for name, value in job.get("cell", {}).items():
        cell = with_parameter(cell, name, value)
    atlas = default_atlas() if not job.get("cell") and job.get("atlas", True) else None
    try:
        plan = plan_flip(job["location"], solver=job["solver"], cell=cell, atlas=atlas,
                         heading=job.get("heading"))
    except FlipkitError as exc:
        return {"status": "failed", "reason": str(exc), "time_s": None, "path": None}
    made_by = job["solver"] if job.get("atlas", True) else f"{job['solver']}-cold"
    if "heading" in job:
        made_by += f"-heading{math.degrees(job['heading']):+.1f}"
    path = plan.to_json(Path(job["plans_dir"]) / plan_filename(job["location"], made_by))
    return {"status": plan.status, "reason": plan.failure, "time_s": float(plan.wall_time_s),
            "path": str(path)}


def validate(targets, trials: int, seed: int = 0, perturbations: Perturbations = Perturbations(),
             executor=None, cache_dir=None, progress: bool = True,
             rate_hz: float = TRACK_RATE_HZ, mode: str = FEEDFORWARD,
             replan: bool = False, command: str = DEFAULT_COMMAND,
             contingencies: bool = False, servo_lookahead_s: float | None = None,
             servo_form: str | None = None) -> dict:
    """Run ``trials`` simulated executions of each plan, all on one sweep.

    Args:
        targets: ``[(location, plan_info, plan_text or None), ...]``: the burger location
            (m), a dict describing the plan (recorded as is) and the text of its solved plan
            file (``None``: no plan, every trial fails at stage ``plan``).
        trials: Trials per location (≥ 1). seed: Trial i draws from
            :func:`~flipkit.experiments.perturbations.trial_rng` ``(seed, i,
            location)``; seeds ≥ 0.
        perturbations: See :class:`Perturbations`. rate_hz: Joint controller rate (Hz).
        mode: Joint controller, one of :data:`flipkit.simulation.modes.MODES`.
        replan: Sense, plan, act: after the scoop, measure where the burger lies on the blade
            and re-plan pickup, flip and turn back for it (:func:`flipkit.planning.planners.planner.replan_flip`);
            ``False`` runs the plans open loop.
        command: Position mode's command stream (:data:`flipkit.planning.plans.servo_command.COMMANDS`).
        contingencies: With ``replan``: each plan's contingency flips are prepared once (on
            ``executor``; read back from ``cache_dir`` when made there before) and the
            re-plans hand them out (:mod:`flipkit.experiments.contingent`).
        executor, cache_dir, progress: See :func:`flipkit.experiments.sweep.run_sweep`.
        servo_lookahead_s: Position mode's servo smooths its commands with this lookahead
            (s, ``physics.servo_lookahead_s``; the commands are made for it); 0: it does not;
            ``None``: the cell's default (0.1 s, servoj's default).
        servo_form: Position mode's servo (:data:`flipkit.config.physics.SERVO_FORMS`);
            ``None``: the cell's default (``physics.servo_form``).

    Returns:
        ``{"seed", "trials", "perturbations", "rate_hz", "mode", "locations": [location_entry ...],
        "tracking": {segment: {"max_m", "rms_m"}} over every trial, "summary": {"locations",
        "trials", "success": {stage: count}, "interval_95": {stage: [low, high]} (the 95 %
        Wilson interval of each ratio, :func:`flipkit.experiments.ratios.success_intervals`),
        "independent": {stage: count}, "safety": the arm's safety system over every trial
        (:func:`flipkit.experiments.trial_jobs.safety_summary`: protective stops and the peaks
        of joint speed ratio, TCP speed, TCP force, momentum and power), "pause": the
        arm's pauses at the sense (:func:`flipkit.experiments.pauses.pause_summary`; ``None``
        open loop), "slide": how far the burgers slid after they touched the grill
        (:func:`flipkit.experiments.slides.slide_summary`)}}``.
    """
    if mode not in MODES:
        raise InvalidChoiceError("execution mode", mode, MODES)
    check_trials(trials)
    physics = servo_physics(servo_lookahead_s)
    jobs, owner = [], []
    for k, (_, _, text) in enumerate(targets):
        if text is not None:
            new = trial_jobs(text, int(trials), seed, perturbations, rate_hz, mode, replan,
                             physics, command=command, servo_form=servo_form)
            jobs, owner = jobs + new, owner + [k] * len(new)
    records = {}
    if contingencies and replan:
        jobs, records = attach(jobs, executor, cache_dir)
    results = run_sweep(run_trial, jobs, executor, cache_dir, trial_key, progress, desc="trials",
                        label_fn=trial_label)
    per = [[r for k2, r in zip(owner, results) if k2 == k] for k in range(len(targets))]
    entries = [location_entry(loc, int(trials), per[k], info)
               for k, (loc, info, _) in enumerate(targets)]
    for entry, (_, _, text) in zip(entries, targets):
        if text in records:
            entry["contingencies"] = contingency_summary(records[text])
    landings = [land for e in entries for land in e["landings"]]
    success = {s: sum(e["success"][s] for e in entries) for s in STAGES}
    return {"seed": int(seed), "trials": int(trials), "perturbations": asdict(perturbations),
            "rate_hz": float(rate_hz), "mode": mode, "replan": bool(replan), "command": command,
            "servo_lookahead_s": lookahead_of(servo_lookahead_s),
            "servo_form": servo_form or CellConfig().physics.servo_form,
            "contingencies": bool(contingencies and replan),
            "locations": entries,
            "tracking": merge_tracking([r["tracking"] for r in results]),
            "summary": {"locations": len(entries), "trials": len(entries) * int(trials),
                        "success": success,
                        "interval_95": success_intervals(success, len(entries) * int(trials)),
                        "independent": {s: sum(e["independent"][s] for e in entries)
                                        for s in STAGES},
                        "pause": pause_summary(landings) if replan else None,
                        "slide": slide_summary(landings),
                        "safety": safety_summary([r.get("safety") for r in results])}}


def validate_plan_file(path, trials: int, seed: int = 0, **kwargs) -> dict:
    """:func:`validate` of one plan file (a serve plan: :func:`~flipkit.experiments.serve_trials.validate_serve`);
    raises FlipkitError (one line) if it is missing, malformed, not a flip or serve plan, not
    solved or fails :func:`~flipkit.planning.plans.verify.verify_plan`. ``kwargs`` as :func:`validate`."""
    check_trials(trials)
    check_seed(seed)
    plan = Plan.load(path)
    if plan.behavior == "serve":  # the serve judge (flipkit.experiments.serve_trials)
        return validate_serve(path, trials, seed, **kwargs)
    if plan.behavior != "flip":
        raise FlipkitError(f"{path}: a {plan.behavior} plan; validate needs a flip or serve plan")
    if plan.status != "solved":
        raise FlipkitError(f"{path}: plan status is {plan.status!r}; validate needs a solved plan")
    require_verified(plan, path, ("flip",))  # nothing unverified is simulated
    info = {"status": plan.status, "file": str(path)}
    return validate([(plan.burger["location"].tolist(), info, Path(path).read_text())], trials,
                    seed, **kwargs)


def validate_locations(locations, trials: int, solver: str = "auto", seed: int = 0, *,
                       executor=None, cache_dir=None, plans_dir=None, progress: bool = True,
                       atlas: bool = True, heading: float | None = None,
                       turn: float | None = None, **kwargs) -> dict:
    """Plan every location (on the sweep, cached), then :func:`validate` the plans.

    Args:
        locations: Burger locations (m). solver: ``"sqp"`` or ``"ipopt"``.
        atlas: Warm-start from the package's atlas where it serves (as ``flipkit plan flip``
            does); ``False``: from cold starts.
        heading: The scoop heading (rad) of every plan
            (:func:`~flipkit.behaviors.targets.check_heading`); ``None``: each location's
            default (radial from the base).
        turn: Instead of ``heading``: each location's default heading turned by ``turn``
            (rad), stopping at the heading limit (:func:`~flipkit.behaviors.targets.turned_heading`).
        plans_dir: Where to keep the plan files; default ``cache_dir/plans``, or a temporary
            directory without a cache.
        trials, seed, executor, cache_dir, progress, kwargs: As :func:`validate`.
    """
    if not isinstance(solver, str) or solver not in SOLVERS:
        raise InvalidChoiceError("solver", solver, SOLVERS)
    check_trials(trials)
    check_seed(seed)  # before any planning
    if heading is not None and turn is not None:
        raise ConfigError("give a heading or a turn of the default heading, not both")
    turned = {} if heading is None else {"heading": float(tg.check_heading(heading))}
    if turn is not None and not (np.isfinite(turn) and abs(turn) <= 2 * HEADING_LIMIT):
        raise ConfigError(f"turn must be finite and within +-{2 * HEADING_LIMIT:.3f} rad, "
                          f"got {turn!r}")
    if isinstance(locations, (str, bytes, dict)) or not hasattr(locations, "__iter__"):
        raise ConfigError(f"locations: expected a sequence of burger locations (x, y, z) (m), "
                          f"got {type(locations).__name__}")
    cell, locs = CellConfig(), []
    for k, loc in enumerate(locations, 1):
        try:
            locs.append([float(v) for v in tg.check_location(cell, loc)])
        except UnreachableError as exc:
            raise UnreachableError(f"location {k}: {exc}") from None
    with tempfile.TemporaryDirectory(prefix="flipkit-plans-") as tmp:
        where = Path(plans_dir or (Path(cache_dir) / "plans" if cache_dir else tmp)).resolve()
        where.mkdir(parents=True, exist_ok=True)
        cold = {} if atlas else {"atlas": False}  # the key only when set: cache keys keep
        jobs = [{"location": loc, "solver": solver, "plans_dir": str(where), **cold, **turned,
                 **({} if turn is None else
                    {"heading": tg.turned_heading(cell, loc, turn)})}
                for loc in locs]
        infos = run_sweep(plan_location, jobs, executor, cache_dir, progress=progress,
                          desc="plans", label_fn=location_label)
        stale = [i for i, r in enumerate(infos) if r["path"] and not Path(r["path"]).is_file()]
        for i, r in zip(stale, run_sweep(plan_location, [jobs[i] for i in stale], executor,
                                         None, progress=False, label_fn=location_label)):
            infos[i] = r  # a cached result whose plan file was deleted: plan again
        targets = [(loc, {k: r[k] for k in ("status", "reason", "time_s")},
                    Path(r["path"]).read_text() if r["status"] == "solved" else None)
                   for loc, r in zip(locs, infos)]
    return validate(targets, trials, seed, executor=executor, cache_dir=cache_dir,
                    progress=progress, **kwargs)


__all__ = ["HOLD_S", "Perturbations", "STAGES", "TRACK_RATE_HZ", "location_entry",
           "merge_tracking", "plan_from_text", "plan_location", "run_trial", "track_plan",
           "trial_jobs", "trial_key", "validate", "validate_locations", "validate_plan_file"]
