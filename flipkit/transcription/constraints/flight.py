"""Release, flight and landing of the flip (flipkit's addition to eq. 26).

Design choice: the release is a fixed node r of the flip segment (default ⌈0.7 N⌉, so that
the burger is on the blade for 70 % of the flip, above the paper's 60 % success threshold).
Contact is imposed up to the release — the friction cone holds on nodes 0..r−1, so the
contact force presses the burger onto the blade, and the normal force is zero at node r
(:func:`flipkit.behaviors.flip.release_blocks`): the burger leaves the blade there, where its
flight starts — and separation after it: on nodes r+1..N the burger, flying ballistically
from its state at node r (:mod:`flipkit.model.flight`), stays on the carrying side of the
blade's plane (:class:`FlightClearance`). :class:`Landing` bounds where and how the burger comes
down. The release time is then t_r = r T / N, a variable through T.
"""

from __future__ import annotations

import math

import numpy as np

from flipkit.errors import ConfigError
from flipkit.model.flight import (FLIGHT_CLEARANCE, LANDING, TILT_MIN_DEG, gravity_magnitude,
                                  landing_parameters, predict_landing)
from flipkit.transcription.constraints.base import Block
from flipkit.transcription.constraints.registry import Check
from flipkit.transcription.layout import Evaluation

NO_SX = ("the burger's flight is a CasADi function called numerically "
         "(flipkit.model.flight); its rows are not part of the stage-wise graph")


def _release_inputs(ev, r: int):
    """(x_r = (p, v, δ, ω), R, ∂x_r/∂q_r, ∂x_r/∂q̇_r) at node r, computed once per
    evaluation point (Landing and FlightClearance share it)."""
    key = ("release", r)
    if key not in ev._states:
        ev._states[key] = _release_state(ev, r)
    return ev._states[key]


def _release_state(ev, r: int):
    q, qd = ev.node(r)[:2]
    st = ev.state(r)
    w, dw_dq = ev.robot.angular_velocity_jacobian(q, qd)
    nq = len(q)
    dq = np.vstack([st.dp_dq, st.dv_dq, st.Jw, dw_dq])
    dqd = np.vstack([np.zeros((3, nq)), st.dv_dqd, np.zeros((3, nq)), st.Jw])
    return np.concatenate([st.p, st.v, np.zeros(3), w]), st.R, dq, dqd


def _landing_rows(ev, r: int, pars):
    """Rows (landing distance, landed normal z) and their Jacobian entries, per
    :func:`~flipkit.model.flight.landing_parameters` vector of ``pars``, for a release at
    node r (pattern: each pair of rows dense in (q_r, q̇_r))."""
    x, R, dq, dqd = _release_inputs(ev, r)
    values, entries = [], []
    for par in pars:
        y, J = (np.asarray(a) for a in LANDING(x, R, par))
        values.append(y[:2, 0])
        entries.append(np.hstack([J[:2] @ dq, J[:2] @ dqd]).ravel())
    return np.concatenate(values), np.concatenate(entries)


def _predictions(ev, robot, r: int, pars) -> list[dict]:
    """:func:`~flipkit.model.flight.predict_landing` of the release at node r, per ``pars``."""
    st = ev.state(r)
    w, _ = robot.angular_velocity_jacobian(*ev.node(r)[:2])
    return [predict_landing(st.p, st.v, st.R, w, thickness=par[0], diameter=2 * par[7],
                            grill_height=par[2] - par[0] / 2, gravity=(0.0, 0.0, -par[1]),
                            target=par[3:5], on_blade=par[5:7]) for par in pars]


class Landing(Block):
    """Landing of the burger released at node r: within ``r_land`` of ``target`` (x, y) and
    upside down (top-face normal ≥ :data:`~flipkit.config.task.TILT_MIN_DEG` from +z).

    Rows: landing distance from the target (m) ≤ r_land; z of the landed top-face normal ≤
    cos(TILT_MIN_DEG).

    Args:
        layout: Variable layout. release: Release node r.
        target: Landing spot (x, y) (m). r_land: Allowed distance (m).
        thickness, diameter: Burger size (m). grill_height: h_g (m). gravity: (3,) m/s².
        on_blade: Where the burger's centre sits on the blade (x, y), blade frame (m).
    """

    def __init__(self, layout, release: int, target, r_land: float, *, thickness: float,
                 diameter: float, grill_height: float, gravity, on_blade=(0.0, 0.0)):
        super().__init__("landing", layout)
        if not (math.isfinite(r_land) and r_land > 0):
            raise ConfigError(f"r_land must be a positive distance (m), got {r_land!r}")
        if not 0 < release < layout.N:
            raise ConfigError(f"release node must be inside the segment, got {release}")
        self.release = int(release)
        self.on_blade = [float(v) for v in np.asarray(on_blade, float)[:2]]
        self.par = landing_parameters(thickness, grill_height, gravity, target, self.on_blade,
                                      diameter=diameter)
        self._add(0, 2, np.concatenate([layout.iq(release), layout.iqd(release)]))
        self.m = 2
        self._finish([-np.inf, -np.inf], [r_land, math.cos(math.radians(TILT_MIN_DEG))],
                     [1.0, 1.0])

    def record(self, robot, x) -> tuple[dict, dict]:
        """The plan file's ``release`` and ``landing`` records at the solution ``x``."""
        ev = Evaluation(self.layout, robot, np.asarray(x, float))
        r = self.release
        pred = _predictions(ev, robot, r, [self.par])[0]
        return ({"node": r, "time": float(self.layout.s[r] * ev.T)},
                {"target": [float(v) for v in self.par[3:5]], "r_land": float(self.hi[0]),
                 **pred, "burger_on_blade": list(self.on_blade)})

    check = Check(("landing",))
    no_symbolic_form = NO_SX

    def evaluate(self, ev):
        return _landing_rows(ev, self.release, [self.par])


class ScenarioLanding(Block):
    """The landing of the same release under other scenarios: the burger's centre elsewhere on
    the blade. Each scenario lands within ``r_land`` of ``target`` and upside down.

    A flip planned for one place of the burger on the blade lands where planned only if the
    burger lies there; the scoop leaves it within a spread (placement, friction). These rows
    make one joint trajectory land every scenario of that spread on the grill spot.

    Rows per scenario: landing distance from the target (m) ≤ r_land; z of the landed
    top-face normal ≤ cos(TILT_MIN_DEG).

    Args:
        layout: Variable layout. release: Release node r. target: Landing spot (x, y) (m).
        r_land: Allowed distance of every scenario's landing (m).
        scenarios: Places of the burger's centre on the blade (x, y), blade frame (m), K ≥ 1.
        thickness, diameter, grill_height, gravity: As :class:`Landing`.
    """

    def __init__(self, layout, release: int, target, r_land: float, scenarios, *,
                 thickness: float, diameter: float, grill_height: float, gravity):
        super().__init__("landing_scenarios", layout)
        pts = np.asarray(scenarios, float).reshape(-1, 2)
        if not (math.isfinite(r_land) and r_land > 0):
            raise ConfigError(f"r_land must be a positive distance (m), got {r_land!r}")
        if pts.shape[0] < 1 or not np.all(np.isfinite(pts)):
            raise ConfigError("landing scenarios must be finite (x, y) places on the blade")
        if not 0 < release < layout.N:
            raise ConfigError(f"release node must be inside the segment, got {release}")
        self.release = int(release)
        self.scenarios = [[float(a), float(b)] for a, b in pts]
        self.pars = [landing_parameters(thickness, grill_height, gravity, target, ob,
                                        diameter=diameter) for ob in self.scenarios]
        cols = np.concatenate([layout.iq(release), layout.iqd(release)])
        for k in range(len(self.scenarios)):
            self._add(2 * k, 2, cols)
        self.m = 2 * len(self.scenarios)
        cos_tilt = math.cos(math.radians(TILT_MIN_DEG))
        self._finish(-np.inf, np.tile([r_land, cos_tilt], len(self.scenarios)), 1.0)

    def record(self, robot, x) -> list[dict]:
        """The plan file's ``landing["scenarios"]`` at the solution ``x``."""
        ev = Evaluation(self.layout, robot, np.asarray(x, float))
        return [{"burger_on_blade": list(ob), "r_land": float(self.hi[0]), **pred}
                for ob, pred in zip(self.scenarios, _predictions(ev, robot, self.release,
                                                                 self.pars))]

    check = Check(("landing_scenarios",))
    no_symbolic_form = NO_SX

    def evaluate(self, ev):
        return _landing_rows(ev, self.release, self.pars)


class FlightClearance(Block):
    """After the release at node r, the blade plane at nodes r+1..N separates the blade from
    the flying burger by at least ``margin`` (m) (see :func:`~flipkit.model.flight.clearance_function`).
    The block keeps :data:`~flipkit.model.flight.FLIGHT_CLEARANCE` mapped over its nodes,
    so that one CasADi call evaluates every node.

    Args:
        layout: Variable layout. release: Release node r. margin: Clearance (m) per node
            after the release (scalar or N − r values).
        thickness, diameter: Burger size (m). gravity: (3,) m/s².
        on_blade: Where the burger's centre sits on the blade (x, y), blade frame (m).
    """

    def __init__(self, layout, release: int, margin, *, thickness: float, diameter: float,
                 gravity, on_blade=(0.0, 0.0)):
        super().__init__("flight_clearance", layout)
        self.release = int(release)
        self.nodes = list(range(self.release + 1, layout.N + 1))
        self._index = slice(self.release + 1, layout.N + 1)
        self.par = [thickness, diameter / 2, gravity_magnitude(gravity),
                    *np.asarray(on_blade, float)[:2]]
        r = self.release
        for k, i in enumerate(self.nodes):
            self._add(k, 1, np.concatenate([layout.iq(r), layout.iqd(r), layout.iq(i),
                                             [layout.T_index]]))
        self.m = len(self.nodes)
        self._finish(margin, np.inf, 1.0)
        self._mapped = FLIGHT_CLEARANCE.map(self.m) if self.m else None

    check = Check(("flight_clearance",))
    no_symbolic_form = NO_SX

    def evaluate(self, ev):
        L, r, n = self.layout, self.release, len(self.nodes)
        if not n:
            return np.zeros(0), np.zeros(0)
        x_r, R_r, dq_r, dqd_r = _release_inputs(ev, r)
        st = ev.states(self._index)
        ds = L.s[self.nodes] - L.s[r]
        X = np.zeros((19, n))  # one column per node: (x_r, τ, p_i, δ_i = 0)
        X[:12] = x_r[:, None]
        X[12] = ds * ev.T
        X[13:16] = st.p.T
        Ri = st.R.transpose(1, 0, 2).reshape(3, 3 * n)  # the nodes' rotations side by side
        d, J = self._mapped(X, R_r, Ri, self.par)  # every node in one call
        J = np.asarray(J).reshape(n, 19)
        dp, Jw = st.dp_dq, st.Jw  # (n, 3, nq)
        jac = np.concatenate([J[:, :12] @ dq_r, J[:, :12] @ dqd_r,
                              np.einsum("nk,nkj->nj", J[:, 13:16], dp)
                              + np.einsum("nk,nkj->nj", J[:, 16:19], Jw),
                              (J[:, 12] * ds)[:, None]], axis=1)
        return np.asarray(d).ravel(), jac.ravel()

