"""End-effector-space + inverse-kinematics baseline (the paper's reference [8] approach,
Sec. I): optimise the spatula trajectory of each subbehaviour in task space, track it with
inverse kinematics at a controller rate (:mod:`.analytic_track`: the UR10's closed form;
:mod:`.ik_track`: placo) and classify what goes wrong (:mod:`.classify`).

Two end-effector optimisations (``ee``):

* ``scp`` (default): position, orientation and duration free
  (:mod:`.ee_scp`, sequential convex programming over the rpy Bezier; the duration by a
  golden-section search within collocation's bounds the specs' ``duration``),
  with collocation's task-space endpoint constraints, friction cone and flip landing.
* ``fixed``: a single QP (:mod:`.ee_opt`): the orientation a fixed smoothstep profile to a
  fixed flip end orientation, the durations fixed at :data:`BASELINE_T` (s), longer than
  collocation's upper bounds.

Each subbehaviour's end-effector problem starts at the previous one's end state (position,
velocity, orientation, orientation rate); the IK continues from the previous IK
configuration, except after a failed subbehaviour, where it restarts from an exact
single-pose IK solution of the planned start pose (:func:`flipkit.model.ik.solve_pose`, see
:func:`_restart`) so that every subbehaviour is judged on its own rather than on the previous
one's lag.
"""

from __future__ import annotations

import time

import numpy as np

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors.models import Models
from flipkit.behaviors import targets as tg
from flipkit.config import CellConfig
from flipkit.errors import ConfigError, InvalidChoiceError, NoSolutionFound, UnreachableError
from flipkit.model.ik import solve_pose
from flipkit.model.orientation import rpy
from flipkit.baseline.classify import (CLASSES, REASONS, BaselineResult, SegmentVerdict,
                                      Thresholds, classify_plan, classify_segment)
from flipkit.baseline.ee_opt import EEState, EETrajectory, plan_segment
from flipkit.baseline.ee_scp import plan_segment_scp
from flipkit.baseline.problems import CompiledProblems

BASELINE_T = {"go_to_burger": 0.8, "scoop": 0.6, "pickup": 0.4, "flip": 0.6, "turn_back": 1.6}
from flipkit.baseline.ik_track import IKTrack, PlacoTracker  # noqa: E402
from flipkit.baseline.analytic_track import AnalyticTracker  # noqa: E402


IK_METHODS = ("placo", "analytic")
EE_METHODS = ("scp", "fixed")


def run_baseline(location, cell: CellConfig | None = None, q_start=None, rate: float = 200.0,
                 *, iterations: int = 3, velocity_limits: bool = True,
                 thresholds: Thresholds = Thresholds(), ik: str = "placo",
                 ee: str = "scp", problems: CompiledProblems | None = None) -> BaselineResult:
    """Plan pickup-and-flip at ``location`` with the end-effector-space + IK baseline.

    Args:
        location: Burger location p^b (m), on the grill.
        cell: Cell configuration (default: the paper's).
        q_start: Start configuration at rest (rad); default q_home, as the joint-space plan.
        rate: Sample and IK controller rate (Hz).
        iterations: placo solver iterations per sample.
        velocity_limits: Enforce joint velocity limits in the IK.
        thresholds: Failure thresholds of the classifier.
        ik: ``placo`` (differential IK with joint and velocity limits, warm-started) or
            ``analytic`` (the UR10's closed form, the branch continuous with the start;
            :mod:`.analytic_track`).
        ee: End-effector optimisation, one of :data:`EE_METHODS` (see the module docstring).
        problems: The end-effector problems compiled so far, solved in and added to (default:
            new ones, for this call alone); a sweep over locations passes one to compile
            each problem once.

    Returns:
        The per-subbehaviour verdicts (with EE and IK wall times), trajectories and tracks.

    Raises:
        UnreachableError: ``location`` is not on the grill.
        ConfigError: Bad ``q_start`` or ``rate``.
        InvalidChoiceError: ``ik`` or ``ee`` is not one of :data:`IK_METHODS`, :data:`EE_METHODS`.
    """
    if ik not in IK_METHODS:
        raise InvalidChoiceError("IK method", ik, IK_METHODS)
    if ee not in EE_METHODS:
        raise InvalidChoiceError("end-effector method", ee, EE_METHODS)
    cell = cell or CellConfig()
    if not (np.isfinite(rate) and rate > 0):
        raise ConfigError(f"IK rate must be a positive number of Hz, got {rate!r}")
    pb = tg.check_location(cell, location)
    models = Models(cell)
    robot = models.bare
    q = robot.q_home.copy() if q_start is None else np.asarray(q_start, dtype=float)
    if q.shape != (robot.nq,) or not np.all(np.isfinite(q)):
        raise ConfigError(f"q_start must be {robot.nq} finite joint angles (rad), got {q_start!r}")
    home_M = robot.placement(robot.q_home)
    home = tg.Pose(tuple(home_M.translation), tuple(rpy(home_M.rotation)))
    M0 = robot.placement(q)
    start = EEState(tuple(M0.translation), (0.0, 0.0, 0.0), tuple(rpy(M0.rotation)))
    tracker = (AnalyticTracker(robot) if ik == "analytic" else
               PlacoTracker(robot, iterations=iterations, velocity_limits=velocity_limits))
    result = BaselineResult(tuple(float(x) for x in pb), [])
    problems = CompiledProblems() if problems is None else problems
    for name in FLIP_NAMES:
        tic = time.perf_counter()
        try:
            if ee == "scp":
                traj = plan_segment_scp(name, cell, pb, start, home=home, rate=rate,
                                        problems=problems)
            else:
                traj = plan_segment(name, cell, pb, start, BASELINE_T[name], home=home, rate=rate,
                                    problems=problems)
        except NoSolutionFound as exc:
            result.segments.append(SegmentVerdict(
                name, "failed", "ee_infeasible", detail=f"end-effector QP: {exc.status}",
                ee_time_s=time.perf_counter() - tic))
            break
        track = tracker.track(traj, q)
        verdict = classify_segment(name, models.for_segment(name), track.t, track.q, traj.p,
                                   traj.R, thresholds=thresholds, ee_time_s=traj.solve_time_s,
                                   ik_time_s=track.time_s, branch=track.branch)
        result.segments.append(verdict)
        result.trajectories.append(traj)
        result.tracks.append(track)
        start = traj.end_state()
        q = track.q[-1] if verdict.status == "solved" else _restart(robot, traj, track.q)
    return result


def _restart(robot, traj: EETrajectory, q_track: np.ndarray) -> np.ndarray:
    """An exact IK solution of the end pose of ``traj`` after a failed subbehaviour.

    Seeds, in order: the last IK configuration; the segment's first configuration with the
    last joint (the roll about the blade axis) turned by the planned roll change; q_home.
    Falls back to the last IK configuration when none converges.
    """
    turned = q_track[0].copy()
    turned[-1] += traj.o[-1, 0] - traj.o[0, 0]
    for seed in (q_track[-1], turned, robot.q_home):
        try:
            return solve_pose(robot, traj.p[-1], traj.o[-1], q_guess=seed)
        except UnreachableError:
            continue
    return q_track[-1]


__all__ = ["run_baseline", "BaselineResult", "SegmentVerdict", "Thresholds", "REASONS",
           "classify_segment", "EEState", "EETrajectory", "plan_segment", "IKTrack",
           "PlacoTracker", "AnalyticTracker", "IK_METHODS", "EE_METHODS", "plan_segment_scp",
           "CLASSES", "classify_plan", "CompiledProblems"]
