"""Initial guesses for one segment: a Bezier path between two configurations, or a fit to given
node configurations, both dynamically consistent (u = RNEA(q, q̇, q̈))."""

from __future__ import annotations

import numpy as np

from flipkit.model.robot import Robot
from flipkit.transcription.layout import Layout


def bezier_guess(layout: Layout, robot: Robot, q_start, q_end, T: float, qd_start=None) -> np.ndarray:
    """A dynamically consistent initial guess: a Bezier path from q_start to q_end.

    α_0 = q_start, α_1 = q_start + q̇_start T/M (matching the start velocity), α_{M−2..M} =
    q_end (arriving at rest), α_2..α_{M−3} blended linearly; q, q̇, q̈ at the nodes follow
    the polynomial exactly and u = RNEA(q, q̇, q̈), so only the Hermite–Simpson defects and
    path inequalities are off.
    """
    b, M = layout.bezier, layout.bezier.degree
    q0, q1 = np.asarray(q_start, float), np.asarray(q_end, float)
    v0 = np.zeros_like(q0) if qd_start is None else np.asarray(qd_start, float)
    alpha = np.empty((layout.nq, M + 1))
    alpha[:, 0] = q0
    alpha[:, 1] = q0 + v0 * T / M
    for k in range(2, M - 2):
        w = (k - 1) / (M - 2)
        alpha[:, k] = (1 - w) * alpha[:, 1] + w * q1
    alpha[:, M - 2:] = q1[:, None]
    t = layout.s * T
    q, qd, qdd = (b.evaluate(alpha, t, T, r) for r in range(3))
    u = np.array([robot.inverse_dynamics(*z) for z in zip(q, qd, qdd)])
    return layout.pack(q, qd, qdd, u, alpha, T)


def fit_guess(layout: Layout, robot: Robot, q_nodes, T: float, qd_start=None,
              rest_at_end: bool = False) -> np.ndarray:
    """An initial guess whose Bezier polynomial fits joint waypoints at the nodes.

    α_0 = q_0 and α_1 = q_0 + q̇_start T/M keep the start state exact (and α_{M−1} = α_M a
    rest at the end when asked); the other coefficients are least-squares fits to the
    waypoints (e.g. IK along a task-space path). q, q̇, q̈ then follow the polynomial and
    u = RNEA(q, q̇, q̈).
    """
    b, M = layout.bezier, layout.bezier.degree
    qn = np.asarray(q_nodes, float)
    v0 = np.zeros(layout.nq) if qd_start is None else np.asarray(qd_start, float)
    B = b.basis(layout.s)
    alpha = np.zeros((layout.nq, M + 1))
    alpha[:, 0], alpha[:, 1] = qn[0], qn[0] + v0 * T / M
    free = list(range(2, M + 1))
    Bf = B[:, free].copy()
    if rest_at_end:  # α_{M-1} = α_M: merge the two columns
        Bf[:, -2] += Bf[:, -1]
        Bf = Bf[:, :-1]
    rhs = qn - B[:, :2] @ alpha[:, :2].T
    sol = np.linalg.lstsq(Bf, rhs, rcond=None)[0].T
    if rest_at_end:
        sol = np.column_stack([sol, sol[:, -1]])
    alpha[:, 2:] = sol
    t = layout.s * T
    q, qd, qdd = (b.evaluate(alpha, t, T, r) for r in range(3))
    u = np.array([robot.inverse_dynamics(*z) for z in zip(q, qd, qdd)])
    return layout.pack(q, qd, qdd, u, alpha, T)
