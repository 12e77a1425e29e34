"""Sense-plan-act trials whose re-plans come from contingency flips made ahead
(``flipkit validate --replan --contingencies``).

A cell prepares a plan's contingency flips once
(:class:`~flipkit.planning.planners.contingency.Contingencies`). It starts when the plan
starts: the arm goes to the burger and scoops, and the camera looks at the blade only when
the scoop has ended (:func:`sense_time`). Here they are prepared once per plan, in this
process, on the sweep's executor when one is given, with the time each one was ready; every
trial of that plan hands them to its re-plan. The arm holds at the sense for the re-plan's
wall time: a check, a contingency (and, if it was not ready when the camera looked, the
rest of its solve, waited for), or a solve where none lands the place.

Each contingency is checked by :func:`~flipkit.planning.plans.verify.verify_plan` after the
round trip through its file text, before any trial can receive it.
"""

from __future__ import annotations

from functools import partial

from flipkit.errors import FlipkitError
from flipkit.experiments.sweep import run_sweep, stable_hash
from flipkit.experiments.trial_jobs import plan_from_text, plan_text
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.contingency import Contingencies
from flipkit.planning.plans.verify import verify_plan
from flipkit.simulation.execute import SENSE_AFTER


def sense_time(plan) -> float:
    """Time (s) from a flip plan's start to its sense: the end of its scoop."""
    span = plan.segment_span(SENSE_AFTER[plan.behavior])
    if span is not None:
        return span[1]
    raise FlipkitError(f"a {plan.behavior} plan without a {SENSE_AFTER[plan.behavior]}")


def prepare(text: str, executor=None) -> dict:
    """The contingency record of the flip plan of file text ``text``, as trial jobs carry it:
    ``{"places": [[x, y] ...], "texts": [plan text ...], "ready_s": [s after the preparation
    began, each], "prepare_s": wall time (s), "sense_s": the plan's sense time (s),
    "failed": [[x, y] ...]}``.

    Raises:
        FlipkitError: A contingency that fails verification after its round trip.
    """
    plan = plan_from_text(text)
    made = Contingencies.prepare(plan, executor=executor)
    texts = []
    for place, flip in made.flips:
        texts.append(plan_text(flip))
        report = verify_plan(plan_from_text(texts[-1]))
        if not report.ok:
            raise FlipkitError(f"contingency at {place}: {report.summary()}")
    return {"places": [list(p) for p, _ in made.flips], "texts": texts,
            "ready_s": list(made.ready_s), "prepare_s": made.wall_time_s,
            "sense_s": sense_time(plan), "failed": [list(p) for p in made.failed]}


def attach(jobs: list, executor=None, cache_dir=None) -> tuple[list, dict]:
    """``jobs`` (trial jobs with ``replan``) with each plan's contingency record under
    ``"contingencies"``, prepared once per plan text; and ``{plan text: record}``.

    With ``cache_dir`` (:func:`flipkit.experiments.sweep.run_sweep`'s cache) a record
    prepared earlier for the same plan text is read back, so that the validations of one
    figure run (both controller modes) share each plan's preparation, as one cell would.
    """
    texts = list(dict.fromkeys(job["plan_text"] for job in jobs))
    made = run_sweep(partial(prepare, executor=executor), texts, None, cache_dir,
                     key_fn=lambda text: {"plan": stable_hash(text)}, progress=False,
                     name=f"{__name__}.prepare")
    records = dict(zip(texts, made))
    return [{**job, "contingencies": records[job["plan_text"]]} for job in jobs], records


def summary(record: dict) -> dict:
    """What a validate result records of a plan's contingencies: ``places``, ``failed``
    (m), ``ready_s``, ``prepare_s`` and ``sense_s`` (s)."""
    return {k: record[k] for k in ("places", "failed", "ready_s", "prepare_s", "sense_s")}


def replanner(plan, record: dict, caches: PlannerCaches | None = None) -> Contingencies:
    """The re-plan of a trial of ``plan`` from its job's contingency record, solving a place
    none covers with ``caches`` (default: new ones)."""
    flips = [(tuple(p), plan_from_text(t)) for p, t in zip(record["places"], record["texts"])]
    return Contingencies(plan, flips, [tuple(p) for p in record["failed"]],
                         float(record["prepare_s"]), [float(v) for v in record["ready_s"]],
                         float(record["sense_s"]),
                         PlannerCaches() if caches is None else caches)


__all__ = ["attach", "prepare", "replanner", "sense_time", "summary"]
