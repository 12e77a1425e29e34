"""One segment of a plan file: its solver statistics and its node arrays (``segments[k]``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.behaviors.targets import Pose
from flipkit.errors import ConfigError
from flipkit.planning.plans.json_fields import (check_array, check_choice, check_keys,
                                                check_nested, check_number, check_text,
                                                check_times)


def default_payload(name: str) -> list[str]:
    """The bodies a segment of behaviour ``name`` carries when nothing says otherwise: the
    spatula, and the burger where the subbehaviour carries it (``carries_burger``). Used for
    segments built in memory and for ``flipkit-plan/1`` files, which did not list them."""
    return ["spatula", "burger"] if SUBBEHAVIORS[name].carries_burger else ["spatula"]


def _holders(record: str) -> str:
    """The subbehaviours whose segments may carry ``record`` (their specs' ``records``)."""
    return " and ".join(n for n, s in SUBBEHAVIORS.items() if record in s.records) or "no"


SEGMENT_KEYS = ("name", "T", "t", "q", "qd", "qdd", "u", "alpha", "cone_nodes", "solver")
_PLACING_KEYS = ("spot", "on_blade", "heading", "pitch")
_LANDING_KEYS = ("target", "r_land", "point", "offset", "tilt_deg", "time_of_flight")


def _scenarios(rows) -> list[dict]:
    """The checked ``landing.scenarios`` records of a robust flip: for each place of the
    burger on the blade, its predicted landing (the keys of ``landing`` but ``target``)."""
    if not isinstance(rows, list):
        raise ConfigError("landing.scenarios: expected a list of landing records")
    out = []
    for k, row in enumerate(rows):
        f = check_keys(row, f"landing.scenarios[{k}]", ("burger_on_blade", *_LANDING_KEYS[1:]))
        out.append({"burger_on_blade": check_array(f"landing.scenarios[{k}].burger_on_blade",
                                                   f["burger_on_blade"], (2,)).tolist(),
                    "r_land": check_number(f"landing.scenarios[{k}].r_land", f["r_land"],
                                           positive=True),
                    "point": check_array(f"landing.scenarios[{k}].point", f["point"],
                                         (3,)).tolist(),
                    **{key: check_number(f"landing.scenarios[{k}].{key}", f[key])
                       for key in _LANDING_KEYS[3:]}})
    return out


@dataclass(frozen=True)
class SolverInfo:
    """Solver statistics of a segment: name, status, iterations, wall time (s), objective
    Σu² (N²·m²) and max scaled constraint violation."""

    name: str
    status: str
    iterations: int
    wall_time_s: float
    objective: float
    max_violation: float

    def __post_init__(self):
        check_text("name", self.name)
        check_text("status", self.status)
        it = self.iterations
        if isinstance(it, bool) or not isinstance(it, (int, np.integer)) or it < 0:
            raise ConfigError(f"iterations: expected a non-negative integer, got {it!r}")
        for key in ("wall_time_s", "objective", "max_violation"):
            object.__setattr__(self, key, check_number(key, getattr(self, key)))
        object.__setattr__(self, "iterations", int(self.iterations))


@dataclass
class Segment:
    """One collocation segment: N+1 nodes evenly spaced on [0, T].

    Attributes:
        name: Behaviour segment (``translate``, ``go_to_burger``, ... :data:`BEHAVIORS`).
        T: Duration (s). t: Node times (N+1,) (s).
        q, qd, qdd, u: Per node (N+1, nq): rad, rad/s, rad/s², N·m.
        alpha: Bezier coefficients (nq, M+1) (rad).
        cone_nodes: Nodes where the friction cone was enforced.
        solver: Solver statistics. goal: End pose of a ``translate`` segment (extension).
        release: Flip only: ``{"node": r, "time": t_r (s)}``, where the burger leaves the blade.
        landing: Flip only: the predicted landing — ``target`` (x, y) and ``r_land`` (m), the
            ``point`` (x, y, z) of the burger's centre at landing (m), its ``offset`` from the
            target (m), ``tilt_deg`` (angle of the top face's normal from +z, deg) and
            ``time_of_flight`` (s) (:func:`flipkit.model.flight.predict_landing`), and
            ``burger_on_blade`` (x, y) (m, blade frame), where the flight starts from.
        payload: Names of the ``robot.payload`` bodies the segment's dynamics carry
            (``["spatula"]``, ``["spatula", "burger"]``); default :func:`default_payload`.
        placing: Serve carry and place only: ``spot`` (x, y) on the table (m), ``on_blade``
            (x, y) (m, blade frame) where the burger was planned to sit, the blade's
            ``heading`` and ``pitch`` at the place's end (rad)
            (:func:`flipkit.planning.planners.serve.placing_record`).
    """

    name: str
    T: float
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    u: np.ndarray
    alpha: np.ndarray
    cone_nodes: list
    solver: SolverInfo
    goal: Pose | None = None
    release: dict | None = None
    landing: dict | None = None
    payload: list | None = None
    placing: dict | None = None

    def __post_init__(self):
        check_choice("name", self.name, tuple(SUBBEHAVIORS))
        self.T = check_number("T", self.T, positive=True)
        self.t = check_times("t", self.t)
        n = self.t.size
        self.q = check_array("q", self.q, (n, None))
        nq = self.q.shape[1]
        for key in ("qd", "qdd", "u"):
            setattr(self, key, check_array(key, getattr(self, key), (n, nq)))
        self.alpha = check_array("alpha", self.alpha, (nq, None))
        nodes = self.cone_nodes
        if not isinstance(nodes, (list, tuple, range, np.ndarray)) or not all(
                isinstance(i, (int, np.integer)) and not isinstance(i, bool) and 0 <= i < n
                for i in nodes):
            raise ConfigError(f"cone_nodes: expected node indices in 0..{n - 1}, got {nodes!r}")
        self.cone_nodes = sorted({int(i) for i in nodes})
        if isinstance(self.solver, dict):
            self.solver = check_nested("solver", SolverInfo, self.solver,
                                  SolverInfo.__dataclass_fields__)
        if not isinstance(self.solver, SolverInfo):
            raise ConfigError("solver: expected solver statistics")
        if isinstance(self.goal, dict):
            g = check_keys(self.goal, "goal", ("p", "o"))
            self.goal = Pose(*(tuple(check_array(f"goal.{k}", g[k], (3,))) for k in ("p", "o")))
        for key in ("goal", "release", "landing", "placing"):
            if getattr(self, key) is not None and key not in SUBBEHAVIORS[self.name].records:
                raise ConfigError(f"{key}: only {_holders(key)} segments have it")
        if self.release is not None:
            r = check_keys(self.release, "release", ("node", "time"))
            node = r["node"]
            if isinstance(node, bool) or not isinstance(node, (int, np.integer)) or not (
                    0 < node < n - 1):
                raise ConfigError(f"release.node: expected a node index in 1..{n - 2}, "
                                  f"got {node!r}")
            self.release = {"node": int(node), "time": check_number("release.time", r["time"])}
        if self.landing is not None:
            f = check_keys(self.landing, "landing", _LANDING_KEYS)
            self.landing = {
                "target": check_array("landing.target", f["target"], (2,)).tolist(),
                "r_land": check_number("landing.r_land", f["r_land"], positive=True),
                "point": check_array("landing.point", f["point"], (3,)).tolist(),
                **{k: check_number(f"landing.{k}", f[k]) for k in _LANDING_KEYS[3:]},
                "burger_on_blade": check_array("landing.burger_on_blade",
                                          self.landing.get("burger_on_blade", (0.0, 0.0)),
                                          (2,)).tolist(),
                **({"scenarios": _scenarios(self.landing["scenarios"])}
                   if self.landing.get("scenarios") else {})}
        if self.placing is not None:
            f = check_keys(self.placing, "placing", _PLACING_KEYS)
            self.placing = {**{k: check_array(f"placing.{k}", f[k], (2,)).tolist()
                               for k in _PLACING_KEYS[:2]},
                            **{k: check_number(f"placing.{k}", f[k]) for k in _PLACING_KEYS[2:]}}
        if self.payload is None:
            self.payload = default_payload(self.name)
        else:
            names = self.payload
            if (not isinstance(names, (list, tuple)) or not names
                    or not all(isinstance(b, str) for b in names) or len(set(names)) != len(names)):
                raise ConfigError(f"payload: expected a non-empty list of distinct body names, "
                                  f"got {names!r}")
            self.payload = list(names)
    @property
    def N(self) -> int:
        """Number of intervals (N + 1 nodes)."""
        return self.t.size - 1

    @classmethod
    def from_solution(cls, nlp, result, goal: Pose | None = None) -> "Segment":
        """The segment of a solved (or failed) NLP: its ``layout``, ``name``, ``cone_nodes``
        and a :class:`~flipkit.solvers.sqp.SolveResult`. The goal of a translate segment defaults to
        its ``end_pose``/``end_orientation`` constraint blocks."""
        L, x = nlp.layout, np.asarray(result.x, dtype=float)
        nodes, T = L.nodes(x), float(x[L.T_index])
        if goal is None and "goal" in SUBBEHAVIORS[nlp.name].records:
            blocks = {b.name: b for b in nlp.blocks}
            if "end_pose" in blocks and "end_orientation" in blocks:
                goal = Pose(tuple(blocks["end_pose"].lo[:3]),
                            tuple(blocks["end_orientation"].lo[:3]))
        info = SolverInfo(result.solver, result.status, result.iterations, result.wall_time_s,
                          result.objective, result.max_violation)
        release = landing = None
        block = next((b for b in nlp.blocks if b.name == "landing"), None)
        if block is not None:
            release, landing = block.record(nlp.robot, x)
            more = next((b for b in nlp.blocks if b.name == "landing_scenarios"), None)
            if more is not None:
                landing["scenarios"] = more.record(nlp.robot, x)
        return cls(nlp.name, T, L.s * T, nodes[:, 0], nodes[:, 1], nodes[:, 2], nodes[:, 3],
                   L.alpha(x), list(nlp.cone_nodes), info, goal, release, landing,
                   [body["name"] for body in nlp.robot.payload])

    def to_json(self) -> dict:
        """The segment as JSON values, keys in file order."""
        arrays = {k: getattr(self, k).tolist() for k in ("t", "q", "qd", "qdd", "u", "alpha")}
        out = {"name": self.name, "T": self.T, **arrays, "cone_nodes": list(self.cone_nodes),
               "solver": dict(vars(self.solver))}
        out["payload"] = list(self.payload)
        if self.goal is not None:
            out["goal"] = {k: [float(v) for v in getattr(self.goal, k)] for k in ("p", "o")}
        for key in ("release", "landing", "placing"):
            if getattr(self, key) is not None:
                out[key] = dict(getattr(self, key))
        return out
