"""A plan as a motion on one clock, sampled for the viewer: the arm's joints and the burger.

The joints are the plan's cubic Hermite interpolant (:func:`flipkit.planning.plans.export.evaluate`,
the one the controller follows). The burger's pose is the plan's own account of it:

* before the first segment that carries it (``payload`` names ``burger``): at rest on the
  grill at ``burger.location``;
* while a segment carries it: on the carrying face of the blade, its centre half a thickness
  above the blade at the recorded ``burger_on_blade`` (a flip) or ``placing.on_blade`` (a
  serve), turning with the blade;
* after a flip's release: the ballistic flight of
  :func:`flipkit.planning.plans.verify_flight.recompute_landing` (the prediction ``flipkit
  verify`` checks), then at rest where it landed, upside down;
* after a serve's place: at rest at the table spot (the tilt and the slide off the blade are
  not drawn: the burger moves there when the place ends).

The scoop is not drawn either: the burger stays on the grill until the pickup starts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.errors import ConfigError
from flipkit.planning.plans.export import evaluate
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify_flight import recompute_landing

FPS = 50.0  # frames/s of the sampled motion (default)
FPS_RANGE = (1.0, 200.0)  # frames/s accepted
ARC_POINTS = 40  # points of the drawn flight arc


@dataclass(frozen=True)
class Landing:
    """Where the plan predicts the burger comes to rest.

    Attributes:
        target: The spot it must reach (x, y, z) (m): the flip's ``landing.target`` on the
            grill, or the serve's table spot.
        radius: The flip's ``r_land`` (m) about the target; 0 for a serve.
        point: The predicted centre at landing or rest (x, y, z) (m).
        arc: (k, 3) points of the ballistic flight (m), release to landing; empty for a serve.
    """

    target: np.ndarray
    radius: float
    point: np.ndarray
    arc: np.ndarray


@dataclass(frozen=True)
class Motion:
    """The sampled motion.

    Attributes:
        fps: Frames per second; frame k is at t = k / fps (s).
        t: (n,) frame times (s), from 0 to at least the end of the plan and of the flight.
        q: (n, nq) joint positions (rad). burger: (n, 4, 4) burger poses in the world (m),
            None for a plan without a burger. landing: None without a flip or serve.
        segments: (name, start, end) of every segment (s).
    """

    fps: float
    t: np.ndarray
    q: np.ndarray
    burger: np.ndarray | None
    landing: Landing | None
    segments: list


def _pose(R, p) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


def plan_motion(plan: Plan, fps: float = FPS) -> Motion:
    """Sample ``plan`` at ``fps`` (frames/s): joints, burger poses and the predicted landing.

    Raises:
        ConfigError: ``fps`` outside :data:`FPS_RANGE`.
        PlanFileError: The plan's model cannot be rebuilt (as :meth:`Plan.cell`).
    """
    if not (isinstance(fps, (int, float)) and math.isfinite(fps)
            and FPS_RANGE[0] <= fps <= FPS_RANGE[1]):
        raise ConfigError(f"fps must be a number in [{FPS_RANGE[0]:g}, {FPS_RANGE[1]:g}] "
                          f"frames/s, got {fps!r}")
    cell = plan.cell()
    robot = plan.robot_for(plan.segments[0], cell)
    ends = np.cumsum([s.T for s in plan.segments])
    starts = ends - [s.T for s in plan.segments]
    h, g = cell.burger.thickness, np.asarray(cell.gravity, float)
    flight = landing = placed = None
    for k, seg in enumerate(plan.segments):
        if seg.release and seg.landing:
            fl = recompute_landing(robot, seg, cell)
            if fl is not None:
                flight = (starts[k] + seg.t[seg.release["node"]], fl)
                tau = np.linspace(0.0, fl["time_of_flight"], ARC_POINTS)
                arc = fl["c0"] + np.outer(tau, fl["v0"]) + 0.5 * np.outer(tau**2, g)
                x, y = seg.landing["target"]
                landing = Landing(np.array([x, y, cell.grill.height]), seg.landing["r_land"],
                                  np.asarray(seg.landing["point"], float), arc)
        if seg.placing and SUBBEHAVIORS[seg.name].role == "place":
            x, y = seg.placing["spot"]
            spot = np.array([x, y, cell.table.height + h / 2])
            landing = Landing(spot - [0, 0, h / 2], 0.0, spot, np.zeros((0, 3)))
            placed = _pose(Rotation.from_euler("z", seg.placing["heading"]).as_matrix(), spot)
    end = max(ends[-1], flight[0] + flight[1]["time_of_flight"] if flight else 0.0)
    t = np.arange(math.ceil(end * fps - 1e-9) + 1) / fps
    q = evaluate(plan, t)[0]
    burger = _burger_poses(plan, cell, robot, t, q, (starts, ends), flight, placed)
    return Motion(float(fps), t, q, burger, landing,
                  [(s.name, float(a), float(b)) for s, a, b in zip(plan.segments, starts, ends)])


def _on_blade(plan: Plan) -> np.ndarray:
    """Where the burger's centre sits on the blade (x, y) (m), as the plan records it."""
    for seg in plan.segments:
        if seg.landing and "burger_on_blade" in seg.landing:
            return np.asarray(seg.landing["burger_on_blade"], float)
        if seg.placing:
            return np.asarray(seg.placing["on_blade"], float)
    return np.zeros(2)


def _burger_poses(plan, cell, robot, t, q, bounds, flight, placed):
    """(n, 4, 4) burger poses at the frame times ``t`` (s) of the joints ``q`` (rad), or None:
    module docstring. ``bounds``: the segments' (starts, ends) (s); ``flight``: (release
    time s, :func:`recompute_landing`'s prediction) or None; ``placed``: the burger's pose at
    rest on the table after a serve, or None."""
    starts, ends = bounds
    carried = [k for k, s in enumerate(plan.segments) if "burger" in s.payload]
    location = plan.burger["location"]
    if not carried and location is None:
        return None
    h = cell.burger.thickness
    rest = _pose(np.eye(3), np.asarray(location, float) + [0, 0, h / 2]) if location is not None else None
    offset = _pose(np.eye(3), [*_on_blade(plan), h / 2])
    seg_of = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(starts) - 1)
    out = np.empty((t.size, 4, 4))
    for i, (ti, qi, k) in enumerate(zip(t, q, seg_of)):
        if flight is not None and ti >= flight[0]:
            fl = flight[1]
            tau = min(ti - flight[0], fl["time_of_flight"])
            c = fl["c0"] + fl["v0"] * tau + 0.5 * np.asarray(cell.gravity) * tau**2
            out[i] = _pose(fl["attitude"](tau), c)
        elif carried and k in carried and ti <= ends[carried[-1]]:
            out[i] = robot.placement(qi).homogeneous @ offset
        elif carried and k > carried[-1] and placed is not None:
            out[i] = placed
        else:
            out[i] = rest if rest is not None else robot.placement(qi).homogeneous @ offset
    return out

