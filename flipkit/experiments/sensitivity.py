"""One-at-a-time sensitivity of the simulated Table I trials to the physical parameters.

Each parameter of :data:`flipkit.config.PHYSICAL_RANGES` is set to the low and to the high
end of its plausible range, everything else nominal, in the simulated cell. The plans and
the replans keep the nominal model, as a real cell's planner would not know the true value,
except for what the cell knows (:data:`flipkit.config.KNOWN_PARAMETERS`: its blade's
geometry, which no plan depends on, and its servo rate, for which the position commands are
made, :func:`flipkit.config.known_physics`); the Table I trials (:func:`flipkit.experiments.trials.run_trial`, by default the package's
sense-plan-act pipeline in feed-forward mode) run over the given plans at each setting, and
the scoop, pickup and flip successes are counted (cumulative, as in Table I). The nominal
cell runs on the same draws for reference. All trials are one sweep
(:func:`flipkit.experiments.sweep.run_sweep`), so they spread over the executor and are cached;
a setting equal to the plan's nominal cell (a range's end at the nominal value, e.g. the UR
CB-series servo rate) runs the nominal jobs, so its trials are simulated once.
"""

from __future__ import annotations

from flipkit.config import PHYSICAL_RANGES, with_parameter
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.experiments.perturbations import Perturbations
from flipkit.experiments.sweep import run_sweep
from flipkit.experiments.trial_jobs import (TRACK_RATE_HZ, plan_from_text, trial_jobs, trial_key,
                                            trial_label)
from flipkit.experiments.trials import STAGES, run_trial
from flipkit.simulation.modes import FEEDFORWARD

ENDS = ("low", "high")


def settings(parameters=None) -> list[tuple]:
    """The (parameter, end, value) settings of a study, in :data:`PHYSICAL_RANGES` order.

    Args:
        parameters: Dotted names (keys of :data:`PHYSICAL_RANGES`); default all of them.

    Raises:
        InvalidChoiceError: An unknown parameter name.
    """
    names = list(PHYSICAL_RANGES) if parameters is None else list(dict.fromkeys(parameters))
    for name in names:
        if name not in PHYSICAL_RANGES:
            raise InvalidChoiceError("physical parameter", name, PHYSICAL_RANGES)
    return [(name, end, float(PHYSICAL_RANGES[name][k])) for name in names
            for k, end in enumerate(ENDS)]


def _counts(results: list) -> dict:
    return {"trials": len(results),
            "success": {s: int(sum(r["ok"][s] for r in results)) for s in STAGES},
            "failures": [{"trial": r["trial"], "stage": r["failure"]["stage"],
                          "reason": r["failure"]["reason"]} for r in results if r["failure"]]}


def run_sensitivity(plan_texts, trials: int = 2, parameters=None, seed: int = 0, *,
                    mode: str = FEEDFORWARD, replan: bool = True,
                    perturbations: Perturbations = Perturbations(),
                    rate_hz: float = TRACK_RATE_HZ, nominal: bool = True, executor=None,
                    cache_dir=None, progress: bool = False, replanned=None,
                    servo_form: str | None = None) -> dict:
    """Run the Table I trials of every plan at both ends of every parameter's range.

    Args:
        plan_texts: Texts of solved flip plan files (e.g. the Table I plans).
        trials: Trials per plan and setting (trial i draws its perturbation from
            :func:`~flipkit.experiments.perturbations.trial_rng` ``(seed, i, location)``:
            every setting sees the same draws).
        parameters: Dotted names of :data:`PHYSICAL_RANGES` to move; default all.
        seed, mode, replan, perturbations, rate_hz: As :func:`flipkit.experiments.trials.validate`.
        nominal: Also run the nominal cell (``result["nominal"]``).
        executor, cache_dir, progress: See :func:`flipkit.experiments.sweep.run_sweep`.
        replanned: ``{(name, end): plan texts}``: for a parameter the cell knows and plans for
            (:data:`flipkit.config.PLANNED_PARAMETERS`), the plans made for that setting's
            value (their cell has it); they run instead of ``plan_texts`` there.
        servo_form: The simulated servo's form (:data:`flipkit.config.physics.SERVO_FORMS`)
            at every setting; ``None``: the cell's default. UR publishes no form: a study
            runs once per form.

    Returns:
        ``{"plans", "trials", "seed", "mode", "replan", "nominal": counts or None,
        "parameters": {name: {"low": counts, "high": counts}}}``; ``counts`` is
        ``{"value" (the parameter's value, SI), "trials" (plans × trials), "success":
        {stage: count}, "failures": [{"trial", "stage", "reason"}]}`` (the nominal counts
        without ``value``).

    Raises:
        ConfigError: No plan, or ``trials`` not a positive integer.
        InvalidChoiceError: An unknown parameter name.
    """
    plan_texts = [t for t in plan_texts if t is not None]
    if not plan_texts:
        raise ConfigError("the sensitivity study needs at least one solved plan")
    if isinstance(trials, bool) or not isinstance(trials, int) or trials < 1:
        raise ConfigError(f"trials must be a positive integer, got {trials!r}")
    cases = ([(None, None, None)] if nominal else []) + settings(parameters)
    replanned = replanned or {}
    cells = {}  # each plan's cell, read once
    jobs, owner = [], []
    for k, (name, end, value) in enumerate(cases):
        texts = [t for t in replanned.get((name, end), plan_texts) if t is not None]
        for text in texts:
            cell = cells.get(text) or cells.setdefault(text, plan_from_text(text).cell())
            # a setting that leaves the plan's cell as it is (a range's end at the nominal
            # value) simulates the nominal cell: the nominal job, computed (and cached) once
            same = name is None or with_parameter(cell, name, value) == cell
            new = trial_jobs(text, trials, seed, perturbations, rate_hz, mode, replan,
                             None if same else {name: value}, servo_form=servo_form)
            jobs, owner = jobs + new, owner + [k] * len(new)
    results = run_sweep(run_trial, jobs, executor, cache_dir, trial_key, progress,
                        desc="sensitivity", dedupe=True, label_fn=trial_label)
    out = {"plans": len(plan_texts), "trials": int(trials), "seed": int(seed), "mode": mode,
           "replan": bool(replan), "servo_form": servo_form, "nominal": None,
           "parameters": {}}
    for k, (name, end, value) in enumerate(cases):
        counts = _counts([r for o, r in zip(owner, results) if o == k])
        if name is None:
            out["nominal"] = counts
        else:
            out["parameters"].setdefault(name, {})[end] = {"value": value, **counts}
    return out


def worst(result: dict, stage: str = "flip") -> dict:
    """The (parameter, end) with the fewest ``stage`` successes (ties: fewer successes of
    the earlier stages first, then :data:`PHYSICAL_RANGES` order).

    Returns:
        ``{"parameter", "end", "value", "success" ({stage: count}), "trials"}``.
    """
    if stage not in STAGES:
        raise InvalidChoiceError("stage", stage, STAGES)
    order = STAGES[:STAGES.index(stage) + 1][::-1]
    rows = [(name, end, c) for name, ends in result["parameters"].items()
            for end, c in ends.items()]
    if not rows:
        raise ConfigError("the sensitivity result has no parameter settings")
    name, end, c = min(rows, key=lambda r: tuple(r[2]["success"][s] for s in order))
    return {"parameter": name, "end": end, "value": c["value"], "success": dict(c["success"]),
            "trials": c["trials"]}


__all__ = ["ENDS", "settings", "run_sensitivity", "worst"]
