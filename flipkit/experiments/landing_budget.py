"""Where a flip's landing error comes from: the burger's place on the blade, or its flight.

A flip plan predicts its landing from the release state and the ballistic flight of a burger
lying where the scoop model said it would
(:func:`~flipkit.planning.plans.verify_flight.recompute_landing`, as ``flipkit verify``
does). Executed in MuJoCo, the burger first touches the grill somewhere else. This module
splits that error, ``total = touchdown − predicted``, into two parts that add up to it:

* ``place = predicted_at_place − predicted``: the burger lies elsewhere on the blade than
  the plan assumed when the pickup ends (the scoop model's error along the blade, and any
  sideways offset, which the model takes as none). The same flight is computed for the place
  the simulation gives.
* ``flight = touchdown − predicted_at_place``: the rest: the arm's tracking up to the
  release, how the contact lets go, and the burger's tilt at its first touch.

Run as ``python -m flipkit.experiments.landing_budget [--mode MODE ...]``: the Table I plans
from the package's atlas, each executed once in the nominal cell (no perturbation).
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

import numpy as np

from flipkit.config import TABLE1_LOCATIONS
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot
from flipkit.planning.planners.atlas import default_atlas
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.planner import plan_flip
from flipkit.planning.plans.verify_flight import recompute_landing
from flipkit.simulation.execute import execute_plan
from flipkit.simulation.modes import MODES


@dataclass(frozen=True)
class LandingBudget:
    """One execution's landing error and its two parts; positions (x, y) in m, world frame
    except ``planned_on_blade`` and ``on_blade`` (blade frame).

    Attributes:
        location: The burger's location p^b (m). mode: The execution mode.
        planned_on_blade: Where the plan assumed the burger lies on the blade.
        on_blade: Where it lies in the simulation when the pickup ends.
        predicted: The plan's landing (its release, its place on the blade).
        predicted_at_place: The same release and flight with the burger at ``on_blade``.
        touchdown: The burger's centre when it first touches the grill after the pickup.
    """

    location: tuple
    mode: str
    planned_on_blade: np.ndarray
    on_blade: np.ndarray
    predicted: np.ndarray
    predicted_at_place: np.ndarray
    touchdown: np.ndarray

    @property
    def total(self) -> np.ndarray:
        """Touchdown minus the plan's prediction (m)."""
        return self.touchdown - self.predicted

    @property
    def place(self) -> np.ndarray:
        """The part of :attr:`total` due to the burger's place on the blade (m)."""
        return self.predicted_at_place - self.predicted

    @property
    def flight(self) -> np.ndarray:
        """The rest of :attr:`total`: release and flight from the actual place (m)."""
        return self.touchdown - self.predicted_at_place


def landing_budget(plan, mode: str = "feedforward") -> LandingBudget:
    """Execute a solved flip ``plan`` once in its nominal cell and split its landing error.

    Raises:
        ConfigError: Not a solved flip plan, or the burger never left the grill at the
            pickup, or never came down on it again (no landing to split).
    """
    if plan.behavior != "flip" or plan.status != "solved":
        raise ConfigError(f"landing_budget needs a solved flip plan, got a {plan.status} "
                          f"{plan.behavior} plan")
    cell = plan.cell()
    flip = plan.segment("flip")
    ex = execute_plan(plan, mode)
    run = ex.run
    k = int(np.searchsorted(run.t, ex.bounds["pickup"][1] - 1e-9))
    if run.touch_grill[k]:
        raise ConfigError(f"the burger at {plan.burger['location']} still touches the grill "
                          "when the pickup ends: no flight to judge")
    on_blade = run.in_blade_frame()[k, :2]
    touch = np.flatnonzero(run.touch_grill[k:])
    if not touch.size:
        raise ConfigError(f"the burger at {plan.burger['location']} never came down on the "
                          "grill")
    robot = Robot(cell, with_burger=True)
    predicted = recompute_landing(robot, flip, cell)
    at_place = recompute_landing(robot, flip, cell, on_blade=on_blade)
    if predicted is None or at_place is None:
        raise ConfigError("the flip plan has no release to predict a landing from")
    return LandingBudget(tuple(float(v) for v in plan.burger["location"]), mode,
                         np.asarray(flip.landing["burger_on_blade"], float)[:2], on_blade,
                         predicted["point"][:2], at_place["point"][:2],
                         run.burger_pos[k + touch[0], :2].copy())


def summary(rows) -> dict:
    """Mean and root-mean-square (m, per axis x, y) of each part over ``rows``."""
    out = {}
    for part in ("total", "place", "flight"):
        a = np.array([getattr(r, part) for r in rows])
        out[part] = {"mean": a.mean(axis=0), "rms": np.sqrt((a ** 2).mean(axis=0))}
    return out


def main(argv=None) -> int:
    """Print the budget of the Table I plans (from the package's atlas) in each mode."""
    parser = argparse.ArgumentParser(prog="python -m flipkit.experiments.landing_budget",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--mode", nargs="+", choices=MODES, default=list(MODES))
    args = parser.parse_args(argv)
    atlas, plans, caches = default_atlas(), {}, PlannerCaches()
    for loc in dict.fromkeys(TABLE1_LOCATIONS):
        plans[loc] = plan_flip(loc, atlas=atlas, caches=caches)
    cm = lambda v: "(" + ", ".join(f"{100 * x:+.1f}" for x in v) + ")"  # noqa: E731
    print(f"{'location (m)':<24}{'mode':<13}{'on blade: plan':>15}{'sim':>15}"
          f"{'total (cm)':>15}{'place':>15}{'flight':>15}")
    for mode in args.mode:
        rows = [landing_budget(p, mode) for p in plans.values() if p.status == "solved"]
        for r in rows:
            print(f"{str(r.location):<24}{mode:<13}{cm(r.planned_on_blade):>15}"
                  f"{cm(r.on_blade):>15}{cm(r.total):>15}{cm(r.place):>15}{cm(r.flight):>15}")
        for part, s in summary(rows).items():
            print(f"{mode}: {part:<7} mean {cm(s['mean'])} cm, rms {cm(s['rms'])} cm")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
