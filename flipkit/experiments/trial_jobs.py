"""The job of one simulated trial, shared by the flip trials (:mod:`flipkit.experiments.trials`)
and the serve trials (:mod:`flipkit.experiments.serve_trials`): the job dicts a sweep worker
receives, their cache key, the plan read back from its text, and the spatula tracking errors
merged over trials."""

from __future__ import annotations

import json
import tempfile
from dataclasses import asdict
from pathlib import Path

import numpy as np

from flipkit.config import PhysicsConfig
from flipkit.config.physics import servo_lookahead
from flipkit.experiments.perturbations import Perturbations, check_seed
from flipkit.experiments.sweep import stable_hash
from flipkit.planning.plans.plan_file import Plan
from flipkit.simulation.modes import FEEDFORWARD
from flipkit.simulation.scene import NOSLIP_ITERATIONS, SLEEP_TOLERANCE

TRACK_RATE_HZ = 1000.0  # PD controller and arm integration rate (Hz)
HOLD_S = 1.0  # s of simulation after the plan ends, for the flipped burger to land
# How a trial's perturbation is drawn from its seed, number and location
# (:func:`~flipkit.experiments.perturbations.trial_rng`); part of the cache key, so that a
# trial drawn another way is never served from the cache.
DRAWS = "SeedSequence([seed, trial, location in µm])"
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
               command: str = "compensated") -> list:
    """The trial jobs of one plan (``physics``: see :func:`flipkit.experiments.trials.run_trial`;
    the key is left out when empty, so the cache keys of nominal trials do not change)."""
    extra = {"physics": {k: float(v) for k, v in physics.items()}} if physics else {}
    seed = check_seed(seed)
    return [{"plan_text": plan_text, "trial": i, "seed": seed, "draws": DRAWS,
             "perturbations": asdict(perturbations), "rate_hz": float(rate_hz), "mode": mode,
             "replan": bool(replan), "command": command, **extra} for i in range(trials)]


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
    simulated cell's default physics and of the scene's numerical settings (a changed model,
    such as the patty's strips or a burger that sleeps at rest, is not served from the
    cache)."""
    key = {**{k: v for k, v in job.items() if k != "plan_text"},
           "plan": stable_hash(job["plan_text"]),
           "simulated_physics": stable_hash(asdict(PhysicsConfig())),
           "scene": {"noslip_iterations": NOSLIP_ITERATIONS, "sleep_tolerance": SLEEP_TOLERANCE}}
    if "contingencies" in job:
        key["contingencies"] = stable_hash(job["contingencies"])
    return key


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
           "plan_from_text", "plan_text", "servo_physics", "trial_jobs", "trial_key"]
