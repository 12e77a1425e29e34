"""Subbehaviours as data: a :class:`Subbehavior` is one declarative spec of a collocation
segment, a :class:`Behavior` an ordered list of them.

A spec states what differs between segments: the duration bounds, whether the spatula
carries the burger, the floor under the blade, which of the arm's shapes may touch the cell,
the path constraints, the end pose and the end condition, the friction-cone nodes and the
initial guess; what ``verify`` checks of a solved segment (the same end pose and cone hooks,
read through a :class:`~flipkit.behaviors.probe.Probe`, and its own independent ``checks``);
the records its segments carry; and the role the planners, the simulation and the atlas ask
for it by. Everything common to every segment (dynamics, Hermite–Simpson, Bezier
outputs, task-space limits, the arm's clearance, the start state) is added by
:func:`flipkit.behaviors.transcribe.transcribe`. ``docs/adding-a-behaviour.md`` walks
through the serve as the worked example.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.model.task_frame import WORLD, TaskFrame

END_CONDITIONS = ("rest", "home", "moving")  # at rest; at q_home at rest; moving (braking room)
# What a segment is asked for by: where it comes down (approach), slides under the burger
# (scoop), lifts it (lift), releases it into flight (release), carries it to the table
# (carry), places it (place), goes home (home), reaches a goal pose (goal).
ROLES = ("approach", "scoop", "lift", "release", "carry", "place", "home", "goal")
RECORDS = ("goal", "release", "landing", "placing")  # optional records of a solved segment
ATLAS_ANCHORS = ("shift", "blend")
TASK_FIELDS = {"location": "the burger location", "goal": "a goal pose",
               "spot": "the table spot"}


@dataclass(frozen=True)
class Task:
    """What a segment is planned for (every field optional; a spec says which it needs).

    Attributes:
        location: Burger location p^b (m) on the grill.
        goal: End pose (:class:`~flipkit.behaviors.targets.Pose`) of a translate.
        land: Flip: landing spot (x, y) (m); ``None``: where the burger was picked up.
        on_blade: Where the burger's centre sits on the blade (x, y) (m, blade frame);
            ``None``: not known yet (the scoop's outcome decides it; the blade centre until then).
        spot: Serve: the table spot (x, y) (m).
        scenarios: Flip: other places (x, y) (m, blade frame) the burger may lie on the blade,
            each to land within ``r_scenario`` of the spot.
        approach_height: Height (m) above the grill that the blade's edges keep on a
            segment that comes down to the grill (``Subbehavior.approach``) until its
            descent, e.g. above other burgers lying on the grill; ``None``: the segment's
            own floor.
        heading: The scoop heading ψ (rad): the go to burger, scoop, pickup and flip run
            along (cos ψ, sin ψ) (:mod:`flipkit.model.task_frame`); 0 is the paper's +x.
    """

    location: object = None
    goal: object = None
    land: object = None
    on_blade: object = None
    spot: object = None
    scenarios: tuple = ()
    approach_height: object = None
    heading: float = 0.0

    def frame(self) -> TaskFrame:
        """The scoop heading's :class:`~flipkit.model.task_frame.TaskFrame` about the burger
        (the world's for a task without a location)."""
        if self.location is None:
            return WORLD
        return TaskFrame(self.heading, np.asarray(self.location, float)[:2])

    def blade_point(self) -> np.ndarray:
        """(x, y) (m) of the burger on the blade that the constraints use."""
        return np.zeros(2) if self.on_blade is None else np.asarray(self.on_blade, float)[:2]

    def with_(self, **changes) -> "Task":
        return replace(self, **changes)


@dataclass(frozen=True)
class Context:
    """What a spec's hooks see while its segment is transcribed.

    Attributes:
        spec: The subbehaviour. layout: The segment's :class:`~flipkit.transcription.layout.Layout`.
        robot: Its dynamics model (bare or loaded). cell: The cell.
        q_start, qd_start: Start state (rad, rad/s). task: The task. options: Transcription
            options (:class:`~flipkit.behaviors.options.SegmentOptions`).
        location: The checked burger location (m), or ``None`` where the spec needs none.
    """

    spec: "Subbehavior"
    layout: object
    robot: object
    cell: CellConfig
    q_start: np.ndarray
    qd_start: np.ndarray
    task: Task
    options: object
    location: np.ndarray | None = None


def _none(ctx: Context):
    return None


def _no_blocks(ctx: Context) -> list:
    return []


def _no_nodes(ctx: Context) -> list:
    return []


def _no_exemption(node: int, N: int) -> frozenset:
    return frozenset()


@dataclass(frozen=True)
class Subbehavior:
    """One segment kind, declared.

    Attributes:
        name: Its name in plans and messages.
        duration: (T_min, T_max) (s). The cost Σu² drives T to T_max, so the chain of a
            behaviour executes in about the sum of its upper bounds.
        carries_burger: The spatula carries the burger (the loaded dynamics model).
        free_motion: It neither carries nor pushes the burger (the go to burger's slide
            meets one at most at its foot as it ends, where the scoop starts), so the arm's
            torque limits alone bound its joint accelerations
            (``RobotConfig.free_accel_limit``), not the planner's bound
            (``RobotConfig.accel_limit``).
        end: One of :data:`END_CONDITIONS`: ``rest``, ``home`` (q_home at rest) or
            ``moving`` (the next segment must have room to brake).
        needs: :class:`Task` fields it cannot do without (:data:`TASK_FIELDS`).
        floor: ``floor(cell, N) -> (N+1,)``: lowest height (m) of the blade's edges per node.
        approach: It comes down to the grill only at its end (the go to burger's descent
            and slide, :mod:`flipkit.behaviors.approach`): ``task.approach_height`` raises
            its floor on the nodes before the descent.
        pressed: The blade centre may go below the grill by the scoop's press.
        exempt: ``exempt(node, N) -> frozenset`` of (shape, box) pairs not held to the
            space margin at ``node`` (the tool end where it works on the grill or table).
        path: ``path(ctx) -> [Block]``: the path constraints of its own.
        end_pose: ``end_pose(ctx) -> Pose | None``: the pose its last node must reach.
        cone: ``cone(ctx) -> [node]``: nodes where the friction cone holds.
        cone_on_blade: The cone is evaluated at the burger's point on the blade
            (``task.on_blade``), not at the blade centre.
        guess: ``guess(ctx, T, pose) -> x0``: the initial guess at T = T_max.
        end_allowance: Extra distance (m) from the cell at its last node.
        coast_into: Name of the segment that follows it moving: its last state, coasting for
            one node interval of that segment at its longest, keeps the margin too.
        after_solve: ``after_solve(segment, task, models, options) -> Task``: the task of the
            segments after it, given its solution (the scoop predicts the burger's place).
        record: ``record(segment, task, models)``: adds records to its solved segment.
        role: One of :data:`ROLES`, or ``None``: what a planner, the simulation or the atlas
            asks for it by (:meth:`Behavior.step`), never by its name.
        records: The optional records (:data:`RECORDS`) its segments may carry; a plan's
            segment with another is refused.
        checks: ``check(probe)`` for each independent check ``verify`` runs on it beyond its
            end pose (``end_pose``), end condition (``end``) and cone (``cone``), recomputed
            from the plan's arrays (:mod:`flipkit.behaviors.checks`).
        atlas_anchor: How an atlas seeds it: ``None``, the interpolated solution itself;
            ``shift``, neighbours' joint paths moved to its actual start; ``blend``, that
            offset faded out to its end (:func:`~flipkit.planning.planners.atlas.anchored_guess`).
    """

    name: str
    duration: tuple[float, float]
    carries_burger: bool
    end: str
    guess: Callable
    free_motion: bool = False
    needs: tuple[str, ...] = ()
    floor: Callable | None = None
    approach: bool = False
    pressed: bool = False
    exempt: Callable = _no_exemption
    path: Callable = _no_blocks
    end_pose: Callable = _none
    cone: Callable = _no_nodes
    cone_on_blade: bool = False
    end_allowance: float = 0.0
    coast_into: str | None = None
    after_solve: Callable | None = None
    record: Callable | None = None
    role: str | None = None
    records: tuple[str, ...] = ()
    checks: tuple[Callable, ...] = ()
    atlas_anchor: str | None = None
    doc: str = field(default="", compare=False)

    def __post_init__(self):
        lo, hi = self.duration
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
            raise ConfigError(f"{self.name}: duration bounds must be 0 < T_min < T_max (s), "
                              f"got {self.duration!r}")
        if self.end not in END_CONDITIONS:
            raise ConfigError(f"{self.name}: end must be one of {', '.join(END_CONDITIONS)}, "
                              f"got {self.end!r}")
        if self.free_motion and self.carries_burger:
            raise ConfigError(f"{self.name}: a free motion cannot carry the burger")
        for attr, value, valid in (("role", self.role, ROLES),
                                   ("atlas_anchor", self.atlas_anchor, ATLAS_ANCHORS)):
            if value is not None and value not in valid:
                raise ConfigError(f"{self.name}: {attr} must be one of {', '.join(valid)}, "
                                  f"got {value!r}")
        if set(self.records) - set(RECORDS):
            raise ConfigError(f"{self.name}: records must be among {', '.join(RECORDS)}, "
                              f"got {self.records!r}")
        unknown = set(self.needs) - set(TASK_FIELDS)
        if unknown:
            raise ConfigError(f"{self.name}: needs unknown task fields {sorted(unknown)}; "
                              f"valid: {', '.join(TASK_FIELDS)}")

    @property
    def at_rest(self) -> bool:
        """Whether the segment ends at rest."""
        return self.end in ("rest", "home")

    def check(self, task: Task) -> None:
        """Raise :class:`~flipkit.errors.ConfigError` if ``task`` lacks a field it needs."""
        for name in self.needs:
            if getattr(task, name) is None:
                raise ConfigError(f"{self.name} needs {TASK_FIELDS[name]}")


@dataclass(frozen=True)
class Behavior:
    """A behaviour: its subbehaviours in order, each from the previous one's final state.

    Attributes:
        name: ``translate``, ``flip``, ``serve``.
        steps: The specs in order.
        stretch: A segment infeasible within its duration bound is planned once more with
            the bound stretched (:data:`~flipkit.behaviors.options.T_STRETCH`).
        open_ended: A plan of it chains any number (at least one) of its steps, not each
            once in order.
        sensed: Role of the step at whose end the cell senses where the burger lies on the
            blade, or ``None``.
        replanned: Role of the first step a re-plan for the sensed burger solves again (the
            steps before it are kept), or ``None``.
    """

    name: str
    steps: tuple[Subbehavior, ...]
    stretch: bool = True
    open_ended: bool = False
    sensed: str | None = None
    replanned: str | None = None

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.steps)

    def step(self, role: str) -> Subbehavior:
        """Its first step of ``role``.

        Raises:
            ConfigError: It has none.
        """
        found = next((s for s in self.steps if s.role == role), None)
        if found is None:
            raise ConfigError(f"behaviour {self.name} has no {role} step; roles: "
                              f"{', '.join(str(s.role) for s in self.steps)}")
        return found

    def before(self, role: str) -> tuple[str, ...]:
        """Names of its steps before its step of ``role``."""
        names = self.names
        return names[:names.index(self.step(role).name)]

    def since(self, role: str) -> tuple[str, ...]:
        """Names of its steps from its step of ``role`` on."""
        names = self.names
        return names[names.index(self.step(role).name):]

    def kept(self) -> tuple[str, ...]:
        """Names of the steps a re-plan keeps: those before its ``replanned`` step."""
        return self.before(self.replanned)
