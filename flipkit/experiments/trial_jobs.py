"""The job of one simulated trial, shared by the flip trials (:mod:`flipkit.experiments.trials`)
and the serve trials (:mod:`flipkit.experiments.serve_trials`): the job dicts a sweep worker
receives, their cache key, the plan read back from its text, the re-plan's subproblems
compiled before the trial runs, and the spatula tracking errors merged over trials."""

from __future__ import annotations

import json
import tempfile
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

from flipkit.config import PhysicsConfig, with_parameter
from flipkit.config.physics import SERVO_FORMS, servo_lookahead
from flipkit.errors import FlipkitError, InvalidChoiceError
from flipkit.experiments.perturbations import Perturbations, check_seed
from flipkit.experiments.sweep import stable_hash
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.servo_command import DEFAULT_COMMAND
from flipkit.simulation.modes import FEEDFORWARD
from flipkit.simulation.scene import NOSLIP_ITERATIONS, SLEEP_TOLERANCE

TRACK_RATE_HZ = 1000.0  # PD controller and arm integration rate (Hz)
HOLD_S = 1.0  # s of simulation after the plan ends, for the flipped burger to land
# How a trial's perturbation is drawn from its seed, number and location
# (:func:`~flipkit.experiments.perturbations.trial_rng`); part of the cache key, so that a
# trial drawn another way is never served from the cache.
DRAWS = "SeedSequence([seed, trial, location in µm])"
# The safety system's model in the trials (part of the cache key): records made before it, or
# with another, are not served from the cache.
SAFETY_MODEL = "protective stop: joint speed, TCP speed, TCP force, momentum, power"
PLAN_KEYS = ("behavior", "status", "robot", "gravity", "grill_height", "spatula", "burger",
             "cone", "segments", "created_by")


def plan_from_text(text: str) -> Plan:
    """A plan from the text of a ``flipkit-plan`` file (already checked by Plan.load)."""
    doc = json.loads(text)
    return Plan(**{k: doc[k] for k in PLAN_KEYS})


def plan_text(plan: Plan) -> str:
    """The text of ``plan``'s ``flipkit-plan`` file (as :meth:`Plan.to_json` writes it)."""
    with tempfile.TemporaryDirectory(prefix="flipkit-plan-") as tmp:
        return plan.to_json(Path(tmp) / "plan.json").read_text()


def trial_jobs(plan_text: str, trials: int, seed: int, perturbations: Perturbations,
               rate_hz: float = TRACK_RATE_HZ, mode: str = FEEDFORWARD,
               replan: bool = False, physics: dict | None = None,
               command: str = DEFAULT_COMMAND, servo_form: str | None = None) -> list:
    """The trial jobs of one plan (``physics``: see :func:`flipkit.experiments.trials.run_trial`;
    ``servo_form``: the simulated servo's form, :data:`flipkit.config.physics.SERVO_FORMS`;
    each key is left out when empty, so the cache keys of nominal trials do not change)."""
    extra = {"physics": {k: float(v) for k, v in physics.items()}} if physics else {}
    if servo_form is not None and servo_form != PhysicsConfig().servo_form:
        if servo_form not in SERVO_FORMS:
            raise InvalidChoiceError("servo form", servo_form, SERVO_FORMS)
        extra["servo_form"] = servo_form
    seed = check_seed(seed)
    return [{"plan_text": plan_text, "trial": i, "seed": seed, "draws": DRAWS,
             "perturbations": asdict(perturbations), "rate_hz": float(rate_hz), "mode": mode,
             "replan": bool(replan), "command": command, **extra} for i in range(trials)]


def warm_replan(replan, plan: Plan, on_blade, caches: PlannerCaches, **kw) -> None:
    """Make one re-plan of ``plan`` with ``replan`` (``replan_flip`` or ``replan_serve``) for
    a burger at ``on_blade`` (x, y) (m, blade frame) in ``caches``, before the trial runs and
    untimed (``kw``: e.g. ``keep=False``, so that a flip is solved though its plan keeps its
    promise). The trial's own re-plan in ``caches`` then takes what a running cell's would,
    not cvxpy's one-off compile of its subproblems, and so does the arm's pause for it
    (:func:`~flipkit.simulation.execute.execute_plan`). A re-plan that fails has compiled
    what it reached; the trial's own says what is wrong."""
    try:
        replan(plan, on_blade, caches=caches, **kw)
    except FlipkitError:
        pass


def job_cell(cell, job: dict):
    """``cell`` with a trial job's simulated physics: its ``physics`` values
    (:func:`flipkit.config.with_parameter`) and its ``servo_form``."""
    for name, value in (job.get("physics") or {}).items():
        cell = with_parameter(cell, name, value)
    if job.get("servo_form"):
        cell = replace(cell, physics=replace(cell.physics, servo_form=job["servo_form"]))
    return cell


def servo_physics(lookahead_s: float | None) -> dict | None:
    """The trials' ``physics`` for a servo that smooths its commands with ``lookahead_s``
    (s, ``physics.servo_lookahead_s``, a parameter the cell knows: the commands are made for
    it; 0: no smoothing); ``None`` for the cell's default (``None`` or the default value),
    so that the trials' cache keys stay those of the nominal servo."""
    if lookahead_s is None:
        return None
    value = servo_lookahead(lookahead_s)
    return None if value == lookahead_of(None) else {"physics.servo_lookahead_s": value}


def lookahead_of(lookahead_s: float | None) -> float:
    """The lookahead (s) that trials with ``lookahead_s`` run (``None``: the default)."""
    return PhysicsConfig().servo_lookahead_s if lookahead_s is None else float(lookahead_s)


def trial_key(job: dict) -> dict:
    """Cache key of a trial job: the plan's digest instead of its text, the contingency
    record's (:mod:`flipkit.experiments.contingent`) instead of it, and the digest of the
    simulated cell's default physics, of the scene's numerical settings and the safety
    system's model (a changed model, such as the patty's strips or a burger that sleeps at
    rest, is not served from the cache)."""
    key = {**{k: v for k, v in job.items() if k != "plan_text"},
           "plan": stable_hash(job["plan_text"]),
           "simulated_physics": stable_hash(asdict(PhysicsConfig())),
           "scene": {"noslip_iterations": NOSLIP_ITERATIONS, "sleep_tolerance": SLEEP_TOLERANCE},
           "safety": SAFETY_MODEL}
    if "contingencies" in job:
        key["contingencies"] = stable_hash(job["contingencies"])
    return key


def trial_label(job: dict) -> str:
    """A trial job as messages name it: its plan's burger location (m), trial and seed, and
    the simulated physics it sets, if any."""
    x, y, z = json.loads(job["plan_text"])["burger"]["location"]
    physics = "".join(f" {k}={v:g}" for k, v in (job.get("physics") or {}).items())
    return f"location ({x:.3f}, {y:.3f}, {z:.3f}) trial {job['trial']} seed {job['seed']}{physics}"


def judged(judge, run, span, *args):
    """``judge(run, span, *args)``, or ``None`` when the run ended before the span began (the
    arm's safety system stopped it): a stage that never ran is not judged, it failed."""
    if run.t[-1] < span[0] - 1e-9:
        return None
    return judge(run, span, *args)


def stage_verdicts(verdicts: dict, first_failure, safety: dict | None, bounds: dict
                   ) -> tuple[dict, dict, dict | None]:
    """A trial's ``ok`` (cumulative), ``independent`` and ``failure`` from its judges.

    Args:
        verdicts: ``{stage: the judge's verdict (``.ok``) or None}`` in stage order; ``None``
            is a stage the run never reached (:func:`judged`), a failure.
        first_failure: ``() -> failure dict or None`` from the verdicts, called only when
            every stage was judged (a stopped run's failure is its protective stop).
        safety: The run's safety record. bounds: The run's ``{segment: (start, end)}`` (s):
            the first two stages end with their segments, the last once the plan has ended.
    """
    independent = {s: v is not None and v.ok for s, v in verdicts.items()}
    ok, so_far = {}, True
    for stage in verdicts:
        so_far = ok[stage] = so_far and independent[stage]
    stages = list(verdicts)
    ends = {s: bounds[s][1] for s in stages[:-1]}
    ends[stages[-1]] = max(b[1] for b in bounds.values())  # judged once it rests
    failure = first_failure() if None not in verdicts.values() else None
    return protective_stop(ok, independent, failure, safety, ends)


def protective_stop(ok: dict, independent: dict, failure: dict | None, safety: dict,
                    ends: dict) -> tuple[dict, dict, dict | None]:
    """A trial's verdicts after the arm's safety system (:mod:`flipkit.simulation.safety`):
    a protective stop fails every stage that had not ended when the arm stopped (at least
    the last), and is the trial's failure (reason ``protective_stop``, amount the value over its limit) unless
    a stage had already failed before it.

    Args:
        ok, independent: ``{stage: bool}``, cumulative and each judge on its own.
        failure: The judges' first failure, or ``None``. safety: The run's safety record.
        ends: ``{stage: time (s) the stage's judged span ends}``.
    """
    stop = safety.get("stop") if safety else None
    if stop is None:
        return ok, independent, failure
    # a stop after every stage's span (the arm holding at the end) still fails the last
    late = [s for s in ok if ends[s] > stop["time_s"]] or list(ok)[-1:]
    ok = {s: ok[s] and s not in late for s in ok}
    independent = {s: independent[s] and s not in late for s in independent}
    early = failure is not None and failure["stage"] not in late
    if not early and late:
        what = stop["quantity"] + (f" ({stop['joint']})" if stop.get("joint") else "")
        failure = {"stage": late[0], "reason": "protective_stop",
                   "amount": stop["value"] / stop["limit"],
                   "detail": f"{what} {stop['value']:.4g} over {stop['limit']:.4g} at "
                             f"t = {stop['time_s']:.3f} s"}
    return ok, independent, failure


def safety_summary(records: list) -> dict | None:
    """The safety system over trials (each a ``safety`` record of
    :meth:`~flipkit.simulation.safety.SafetyMonitor.record`, ``None`` for a trial without one):
    ``{"preset", "limits", "protective_stops": count, "peaks": {quantity: the worst},
    "stops": [{"trial", ...the stop}]}``; ``None`` without records."""
    rows = [(k, r) for k, r in enumerate(records) if r]
    if not rows:
        return None
    first = rows[0][1]
    peaks = {q: max(r["peaks"][q] for _, r in rows) for q in first["peaks"]}
    stops = [{"index": k, **r["stop"]} for k, r in rows if r["stop"]]
    return {"preset": first["preset"], "limits": dict(first["limits"]),
            "protective_stops": len(stops), "peaks": peaks, "stops": stops}


def format_safety(summary: dict | None) -> str:
    """One line for a report: the preset, the protective stops and the worst peaks."""
    if summary is None:
        return "safety system: no trials"
    p, lim = summary["peaks"], summary["limits"]
    return (f"safety system ({summary['preset']}): {summary['protective_stops']} protective "
            f"stops; worst joint speed {p['joint_speed']:.3f} of the published, TCP speed "
            f"{p['tcp_speed']:.2f} m/s (limit {lim['tcp_speed']:g}), TCP force "
            f"{p['tcp_force']:.1f} N ({lim['tcp_force']:g}), momentum {p['momentum']:.1f} "
            f"kg·m/s ({lim['momentum']:g}), power {p['power']:.1f} W ({lim['power']:g})")


def merge_tracking(errors: list) -> dict:
    """Per-segment {"max_m", "rms_m"} (m) over several
    :func:`flipkit.experiments.trials.track_plan` error dicts."""
    out = {}
    for name in dict.fromkeys(k for e in errors for k in e):
        rows = [e[name] for e in errors if name in e]
        n = sum(r["n"] for r in rows)
        out[name] = {"max_m": max(r["max_m"] for r in rows),
                     "rms_m": float(np.sqrt(sum(r["sum_sq_m2"] for r in rows) / n))}
    return out


__all__ = ["DRAWS", "HOLD_S", "PLAN_KEYS", "TRACK_RATE_HZ", "lookahead_of", "merge_tracking",
           "plan_from_text", "plan_text", "servo_physics", "trial_jobs", "trial_key", "trial_label",
           "warm_replan"]
