"""Simulated execution of serve plans under perturbations: does the burger end on the table?

As :mod:`flipkit.experiments.trials` for flips: each trial executes the plan closed-loop in the
MuJoCo cell (:func:`flipkit.simulation.execute.execute_plan`) with the burger misplaced and the
physics perturbed (:class:`~flipkit.experiments.perturbations.Perturbations`, drawn from
:func:`~flipkit.experiments.perturbations.trial_rng` of the seed, the trial and the
location), then judges the scoop and pickup (paper Sec. V) and the serve
(:func:`flipkit.simulation.judges.judge_serve`: resting on the table, top face up, within
3 cm of the spot). A stage counts only if the previous ones succeeded. With
``replan`` the cell measures where the burger lies on the blade 0.5 s before the carry ends
and re-plans place and return home for it while the carry finishes
(:func:`flipkit.planning.planners.serve.replan_serve`,
:data:`flipkit.simulation.execute.SENSE_LEAD`).
"""

from __future__ import annotations

from dataclasses import asdict
from functools import partial
from pathlib import Path


from flipkit.config import PhysicsConfig, known_physics
from flipkit.errors import ConfigError
from flipkit.experiments.pauses import pause_summary
from flipkit.experiments.ratios import success_intervals
from flipkit.experiments.perturbations import Perturbations, check_trials, trial_rng
from flipkit.experiments.sweep import run_sweep
from flipkit.experiments.trial_jobs import (HOLD_S, TRACK_RATE_HZ, lookahead_of, merge_tracking,
                                            job_cell, judged, safety_summary, stage_verdicts,
                                            plan_from_text, servo_physics, trial_jobs,
                                            trial_key, trial_label, warm_replan)
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.servo_command import DEFAULT_COMMAND
from flipkit.planning.planners.serve import replan_serve, table_spot
from flipkit.planning.plans.verify import require_verified
from flipkit.simulation.execute import execute_plan
from flipkit.simulation.judges import judge_pickup, judge_scoop, judge_serve
from flipkit.simulation.modes import FEEDFORWARD

SERVE_STAGES = ("scoop", "pickup", "serve")


def run_serve_trial(job: dict) -> dict:
    """One simulated execution of a serve plan (the sweep worker; ``job`` as
    :func:`flipkit.experiments.trials.run_trial`, ``plan_text`` a solved serve plan).

    Returns:
        ``trial``, ``ok`` ({stage: bool}, cumulative), ``independent`` (each judge on its
        own), ``failure`` (first failed stage and why, or ``None``), ``perturbation``,
        ``tracking``, ``mode``, ``rest`` (final centre ``xy`` (m), ``distance`` from the
        spot (m), ``up_z``), ``replan`` (sensed position and failure, or ``None``).
    """
    plan = plan_from_text(job["plan_text"])
    draw = Perturbations(**job["perturbations"]).draw(
        trial_rng(job["seed"], job["trial"], plan.burger["location"]))
    cell = job_cell(plan.cell(), job)
    replan = None
    if job.get("replan", False):  # its re-plans share caches, compiled before it runs
        caches = PlannerCaches()
        warm_replan(replan_serve, plan, (0.0, 0.0), caches)
        replan = partial(replan_serve, caches=caches)
    mode = job.get("mode", FEEDFORWARD)
    ex = execute_plan(plan, mode, draw, cell=cell, hold=HOLD_S, rate_hz=job["rate_hz"],
                      replan=replan, command=job.get("command", DEFAULT_COMMAND),
                      servo=known_physics(plan.cell().physics, job.get("physics") or {}))
    run, bounds = ex.run, ex.bounds
    spot = table_spot(ex.plan)
    scoop, pickup = judged(judge_scoop, run, bounds["scoop"]), judged(judge_pickup, run,
                                                                      bounds["pickup"])
    serve = judge_serve(run, spot, cell.table)  # judged on the run's last state
    ok, independent, failure = stage_verdicts(
        {"scoop": scoop, "pickup": pickup, "serve": serve},
        lambda: _failure(scoop, pickup, serve), ex.safety, bounds)
    return {"trial": job["trial"], "ok": ok, "failure": failure, "independent": independent,
            "safety": ex.safety,
            "perturbation": draw, "tracking": ex.errors, "mode": mode,
            "rest": {"xy": [float(v) for v in run.burger_pos[-1, :2]],
                     "distance": serve.distance, "up_z": serve.up_z},
            "replan": {"sensed_on_blade": ex.sensed_on_blade, "failure": ex.replan_failure,
                       "time_s": ex.replan_time_s, "wait_s": ex.replan_wait_s}
            if replan is not None else None}


def _failure(scoop, pickup, serve) -> dict | None:
    """The first failed stage: stage, reason and the measured amount."""
    if not scoop.ok:
        return {"stage": "scoop", "reason": "overlap", "amount": scoop.overlap}
    if not pickup.ok:
        return {"stage": "pickup", "reason": "on_grill" if not pickup.off_grill
                else "off_spatula", "amount": pickup.clearance}
    if serve.ok:
        return None
    for reason, bad, amount in (("not_upright", not serve.upright, serve.up_z),
                                ("not_on_table", not serve.on_table, serve.distance),
                                ("on_blade", not serve.off_blade, serve.distance),
                                ("moving", not serve.at_rest, serve.distance)):
        if bad:
            return {"stage": "serve", "reason": reason, "amount": float(amount)}
    return {"stage": "serve", "reason": "missed_spot", "amount": serve.distance}


def validate_serve(path, trials: int, seed: int = 0, perturbations=Perturbations(), *,
                   executor=None, cache_dir=None, progress: bool = True,
                   rate_hz: float = TRACK_RATE_HZ, mode: str = FEEDFORWARD,
                   replan: bool = False, command: str = DEFAULT_COMMAND,
                   servo_lookahead_s: float | None = None, servo_form: str | None = None) -> dict:
    """Run ``trials`` simulated executions of the serve plan file ``path`` (``servo_lookahead_s``
    and ``servo_form`` as :func:`flipkit.experiments.trials.validate`).

    Returns:
        ``{"seed", "trials", "perturbations", "rate_hz", "mode", "replan", "locations":
        [{"location", "spot", "plan", "trials", "success", "independent", "failures",
        "tracking", "rests"}], "tracking", "summary"}`` — the layout of
        :func:`flipkit.experiments.trials.validate`, stages :data:`SERVE_STAGES`.

    Raises:
        FlipkitError: The file is missing, malformed, not a serve plan, not solved or fails
            :func:`~flipkit.planning.plans.verify.verify_plan`.
    """
    plan = Plan.load(path)
    if plan.behavior != "serve" or plan.status != "solved":
        raise ConfigError(f"{path}: a {plan.status} {plan.behavior} plan; needs a solved serve plan")
    require_verified(plan, path, ("serve",))  # nothing unverified is simulated
    check_trials(trials)
    jobs = trial_jobs(Path(path).read_text(), int(trials), seed, perturbations, rate_hz, mode,
                      replan, servo_physics(servo_lookahead_s), command=command,
                      servo_form=servo_form)
    results = run_sweep(run_serve_trial, jobs, executor, cache_dir, trial_key, progress,
                        desc="trials", label_fn=trial_label)
    entry = {"location": plan.burger["location"].tolist(),
             "spot": table_spot(plan).tolist(), "plan": {"status": plan.status,
                                                        "file": str(path)},
             "trials": int(trials),
             "safety": safety_summary([r.get("safety") for r in results]),
             "success": {s: sum(r["ok"][s] for r in results) for s in SERVE_STAGES},
             "independent": {s: sum(r["independent"][s] for r in results) for s in SERVE_STAGES},
             "failures": [{"trial": r["trial"], **r["failure"], "perturbation": r["perturbation"]}
                          for r in results if r["failure"]],
             "tracking": merge_tracking([r["tracking"] for r in results]),
             "rests": [{"trial": r["trial"], **r["rest"], "replan": r["replan"]}
                       for r in results]}
    return {"seed": int(seed), "trials": int(trials), "perturbations": asdict(perturbations),
            "rate_hz": float(rate_hz), "mode": mode, "replan": bool(replan), "command": command,
            "servo_lookahead_s": lookahead_of(servo_lookahead_s),
            "servo_form": servo_form or PhysicsConfig().servo_form,
            "locations": [entry], "tracking": entry["tracking"],
            "summary": {"locations": 1, "trials": int(trials), "success": entry["success"],
                        "interval_95": success_intervals(entry["success"], int(trials)),
                        "independent": entry["independent"],
                        "pause": pause_summary(entry["rests"]) if replan else None,
                        "safety": entry["safety"]}}


__all__ = ["SERVE_STAGES", "run_serve_trial", "validate_serve"]
