"""The scoop's task frame: the world turned by the scoop heading ψ about the burger.

The paper's scoop runs along the world's +x (eqs. 22–26). A scoop heading ψ (rad) turns that
whole task about the vertical axis through the burger p^b: the go to burger, scoop, pickup and
flip are stated in a frame whose x axis points along (cos ψ, sin ψ, 0) and whose origin is
p^b's (x, y), so that their bounds and targets are the paper's, unchanged. Heights, and
anything seen in the blade's own frame (the friction cone), do not depend on ψ.

A :class:`TaskFrame` maps world quantities into that frame (``point``, ``vector``, a numeric
:class:`~flipkit.model.robot.SpatulaState` with its Jacobians) and task-frame poses back into
the world (``pose``); :func:`~flipkit.transcription.constraints.quantities.framed` does the
same for CasADi kinematics. ψ = 0 is the identity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np


def rz(psi: float) -> np.ndarray:
    """The rotation (3 × 3) by ``psi`` (rad) about the world's z axis."""
    c, s = math.cos(psi), math.sin(psi)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class TaskFrame:
    """The world turned by ``heading`` about the vertical through ``centre``.

    Args:
        heading: The scoop heading ψ (rad): the task frame's x axis in the world is
            (cos ψ, sin ψ, 0).
        centre: (x, y) (m) of the vertical axis it turns about (the burger's location).
    """

    heading: float = 0.0
    centre: tuple = (0.0, 0.0)
    _to_task: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "heading", float(self.heading))
        object.__setattr__(self, "centre", tuple(float(c) for c in np.asarray(self.centre)[:2]))
        object.__setattr__(self, "_to_task", rz(-self.heading))

    @property
    def identity(self) -> bool:
        """Whether the frame is the world's (ψ = 0)."""
        return self.heading == 0.0

    @property
    def _c(self) -> np.ndarray:
        return np.array([*self.centre, 0.0])

    def vector(self, v) -> np.ndarray:
        """World vector(s) (..., 3) in the task frame."""
        return np.asarray(v, float) @ self._to_task.T

    def point(self, p) -> np.ndarray:
        """World point(s) (..., 3) (m) in the task frame."""
        return self.vector(np.asarray(p, float) - self._c) + self._c

    def world_vector(self, v) -> np.ndarray:
        """Task-frame vector(s) (..., 3) in the world."""
        return np.asarray(v, float) @ self._to_task

    def world_point(self, p) -> np.ndarray:
        """Task-frame point(s) (..., 3) (m) in the world."""
        return self.world_vector(np.asarray(p, float) - self._c) + self._c

    def rotation(self, R) -> np.ndarray:
        """A world rotation (..., 3, 3) (frame → world) as frame → task frame."""
        return self._to_task @ np.asarray(R, float)

    def pose(self, p, o) -> tuple[tuple, tuple]:
        """A task-frame blade pose (position (m), rpy (rad)) in the world: the position turned
        about the centre, the yaw o_z increased by ψ (R = R_z R_y R_x, so R_z(ψ) R is the
        same roll and pitch with yaw o_z + ψ)."""
        pw = self.world_point(p)
        return tuple(float(v) for v in pw), (float(o[0]), float(o[1]), float(o[2]) + self.heading)

    def state(self, st):
        """A numeric :class:`~flipkit.model.robot.SpatulaState` (one node or a batch) in the
        task frame, Jacobians too."""
        if self.identity:
            return st
        A = self._to_task
        return replace(st, p=self.point(st.p), R=A @ st.R, v=self.vector(st.v),
                       a=self.vector(st.a), dp_dq=A @ st.dp_dq, Jw=A @ st.Jw,
                       dv_dq=A @ st.dv_dq, dv_dqd=A @ st.dv_dqd, da_dq=A @ st.da_dq,
                       da_dqd=A @ st.da_dqd, da_dqdd=A @ st.da_dqdd)


WORLD = TaskFrame()
