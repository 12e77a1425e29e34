"""Burger–spatula contact: specific contact force (eq. 5) and friction-cone forms.

The burger riding on the blade has acceleration a (the spatula's), so the force the blade
exerts on it, per unit burger mass, is w = a − g_vec (m/s²). In the spatula frame
f = Rᵀ w = (f_x, f_y, f_z): f_z = F_n/m is the normalised normal force and f_x, f_y the
normalised tangential forces of eq. (5). (The paper prints them expanded in o_x, o_y with
some terms missing; this is the exact expression.) At rest and flat, f = (0, 0, g).

Two cone forms, each a vector h(q, q̇, q̈) ≥ 0 with analytic Jacobians:

* ``physical`` (eq. 5): h = (f_z, μf_z − f_x, μf_z + f_x, μf_z − f_y, μf_z + f_y).
* ``paper`` (eq. 20): h = ⟨F_n, ŵ⟩ − cos μ, F_n = R e_z, ŵ = w/|w|. The paper normalises the
  acceleration a itself, which vanishes at rest and ignores gravity; with w the form is a
  circular cone of half-angle μ *radians* (not atan μ) about the normal.
"""

from __future__ import annotations

import numpy as np

from flipkit.errors import InvalidChoiceError
from flipkit.model.robot import SpatulaState, skew

CONE_FORMS = ("physical", "paper")


def specific_force(R: np.ndarray, a: np.ndarray, gravity) -> np.ndarray:
    """f = Rᵀ(a − g_vec): contact force on the burger per unit mass, spatula frame (m/s²)."""
    return np.asarray(R).T @ (np.asarray(a) - np.asarray(gravity))


def specific_force_jacobians(st: SpatulaState, gravity):
    """f and ∂f/∂(q, q̇, q̈) (3x6 each) from a :class:`SpatulaState` (of one node, or of a
    batch: every output then with the leading node axis)."""
    w = st.a - np.asarray(gravity)
    Rt = np.swapaxes(st.R, -1, -2)
    f = (Rt @ w[..., None])[..., 0]
    return f, Rt @ (st.da_dq + skew(w) @ st.Jw), Rt @ st.da_dqd, Rt @ st.da_dqdd


class ConeForm:
    """A friction-cone form: ``rows`` inequalities h ≥ 0 per node.

    Args:
        mu: Friction coefficient μ (> 0).
        gravity: Gravity vector (m/s²).
    """

    name = ""
    rows = 0
    labels: tuple[str, ...] = ()

    def __init__(self, mu: float, gravity=(0.0, 0.0, -9.81)):
        self.mu = float(mu)
        self.gravity = np.asarray(gravity, dtype=float)

    def values(self, st: SpatulaState) -> np.ndarray:
        """h at one node."""
        return self.jacobians(st)[0]

    def jacobians(self, st: SpatulaState):
        """h (rows,) and ∂h/∂q, ∂h/∂q̇, ∂h/∂q̈ (rows x nq) at one node; at a batch of nodes
        (:meth:`~flipkit.model.robot.SpatulaState.take`), each with a leading node axis."""
        raise NotImplementedError

    def margin(self, st: SpatulaState) -> float:
        """Smallest entry of h: positive inside the cone."""
        return float(np.min(self.values(st)))


class PhysicalCone(ConeForm):
    """Eq. (5): f_z ≥ 0, |f_x| ≤ μ f_z, |f_y| ≤ μ f_z (linear in f)."""

    name = "physical"
    rows = 5
    labels = ("f_z", "mu f_z - f_x", "mu f_z + f_x", "mu f_z - f_y", "mu f_z + f_y")

    def jacobians(self, st):
        f, df_dq, df_dqd, df_dqdd = specific_force_jacobians(st, self.gravity)
        mu = self.mu
        S = np.array([[0, 0, 1], [-1, 0, mu], [1, 0, mu], [0, -1, mu], [0, 1, mu]], dtype=float)
        return f @ S.T, S @ df_dq, S @ df_dqd, S @ df_dqdd


class PaperCone(ConeForm):
    """Eq. (20) with the contact force: ⟨F_n, w/|w|⟩ ≥ cos μ."""

    name = "paper"
    rows = 1
    labels = ("<F_n, w/|w|> - cos(mu)",)

    def jacobians(self, st):
        w = st.a - self.gravity
        nw = np.sqrt(w[..., None, :] @ w[..., :, None])[..., 0]  # |w|, shape (..., 1)
        what = w / nw
        n = st.R[..., :, 2]
        dn_dq = -skew(n) @ st.Jw
        P = (np.eye(3) - what[..., :, None] * what[..., None, :]) / nw[..., None]  # ∂ŵ/∂w
        g = n[..., None, :] @ P  # (..., 1, 3)
        h = (n[..., None, :] @ what[..., :, None])[..., 0] - np.cos(self.mu)
        return h, what[..., None, :] @ dn_dq + g @ st.da_dq, g @ st.da_dqd, g @ st.da_dqdd


def make_cone(form: str, mu: float, gravity=(0.0, 0.0, -9.81)) -> ConeForm:
    """The cone form named ``form`` (one of :data:`CONE_FORMS`)."""
    classes = {"physical": PhysicalCone, "paper": PaperCone}
    if form not in classes:
        raise InvalidChoiceError("cone form", form, CONE_FORMS)
    return classes[form](mu, gravity)
