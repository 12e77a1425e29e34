"""What a spec's hooks and checks see of a solved segment when a plan is verified.

A :class:`Probe` is the verifier's counterpart of :class:`~flipkit.behaviors.spec.Context`:
it carries the attributes the spec's ``end_pose`` and ``cone`` hooks read (``layout``,
``cell``, ``task``, ``location``, ``options``), rebuilt from the plan's record (the burger's
location, the segment's goal, placing and release records), so the verifier asks the same
hook that the transcription asked for the pose and the nodes; and what a spec's independent
``checks`` need: the blade's states at the nodes (pinocchio, from the plan's arrays), the
robot model and the tolerance, and :meth:`Probe.add` to report a row.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from flipkit.behaviors.spec import Subbehavior, Task
from flipkit.transcription.layout import Layout


@dataclass(frozen=True)
class RecordedOptions:
    """The transcription options a hook reads, as the segment records them.

    Attributes:
        landing: The segment records a release (the flip's release, flight and landing).
        release: Its release node (0 without one).
    """

    landing: bool = False
    release: int = 0

    def release_node(self) -> int:
        """The recorded release node."""
        return self.release


@dataclass
class Probe:
    """A solved segment seen by ``verify``: what the spec's hooks and checks read.

    Attributes:
        spec: The segment's subbehaviour. seg: The segment (its arrays and records).
        layout: The segment's :class:`~flipkit.transcription.layout.Layout` (N, nodes).
        cell: The cell the plan runs in. task: The task rebuilt from the plan's record.
        location: The plan's burger location (m), or ``None``.
        options: :class:`RecordedOptions`. robot: The segment's dynamics model.
        states: The blade centre's kinematic state at every node (``robot.states``).
        tol: The verification tolerance (scaled units).
        report: ``report(group, violation, tolerance, node)``: adds a row for the segment.
    """

    spec: Subbehavior
    seg: object
    layout: Layout
    cell: object
    task: Task
    location: np.ndarray | None
    options: RecordedOptions
    robot: object
    states: list
    tol: float
    report: Callable

    def add(self, group: str, violation, node: int | None = None, tolerance=None) -> None:
        """One row of ``group`` (violation ≥ 0, 0 when satisfied), at ``tol`` by default."""
        self.report(group, violation, self.tol if tolerance is None else tolerance, node)

    def point(self, i: int, r_local) -> np.ndarray:
        """World position (m) of the blade point ``r_local`` (spatula frame) at node ``i``."""
        st = self.states[i]
        return st.p + st.R @ np.asarray(r_local, float)

    def tip(self, i: int) -> np.ndarray:
        """World position (m) of the blade tip at node ``i``."""
        return self.point(i, (self.cell.spatula.length / 2, 0.0, 0.0))

    def has_task(self) -> bool:
        """Whether the record holds every task field the spec needs."""
        return all(getattr(self.task, name) is not None for name in self.spec.needs)


def outside(x, lo, hi) -> np.ndarray:
    """Distance of x outside the box [lo, hi] (0 inside)."""
    return np.maximum(np.maximum(np.asarray(lo) - x, x - np.asarray(hi)), 0.0)


def angle(a, b) -> np.ndarray:
    """|a − b| wrapped to [0, π] (rad)."""
    return np.abs((np.asarray(a) - np.asarray(b) + np.pi) % (2 * np.pi) - np.pi)
