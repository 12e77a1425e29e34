"""The plan file ``flipkit-plan/1`` (JSON): a planned trajectory with everything needed to
check or execute it without the objects that made it (DESIGN.md, "Plan file").

:class:`Plan` and :class:`Segment` mirror the file key for key. Constructors validate their
arguments and raise :class:`~flipkit.errors.ConfigError` naming the field;
:meth:`Plan.load` turns every problem (missing file, not JSON, wrong format, missing key,
wrong shape, non-finite number, unknown name) into a one-line
:class:`~flipkit.errors.PlanFileError` naming the file and the key path, e.g.
``plan.json: segments[2].q: expected shape (21, 6), got (20, 6)``.

The format is documented in ``docs/plan-format.md`` (JSON Schema beside it). Beyond
DESIGN.md's seed: ``segments[k].goal = {"p": [3], "o": [3]}`` — the end pose of a
``translate`` segment (optional) — and, on a flip segment, ``release`` (node, time) and the
predicted ``landing`` (target, r_land, point, offset, tilt_deg, time_of_flight), checked by
:mod:`flipkit.verify`.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import __version__
from .behaviors import BEHAVIORS, CARRIES_BURGER
from .config import BurgerConfig, CellConfig, GrillConfig, RobotConfig, SpatulaConfig
from .contact import CONE_FORMS
from .errors import ConfigError, PlanFileError
from .targets import SUBBEHAVIORS, Pose

FORMAT = "flipkit-plan/1"
PLAN_BEHAVIORS = ("translate", "flip")
PLAN_STATUSES = ("solved", "failed")
PAYLOAD_RTOL = 1e-9  # relative agreement of the recorded payload with the rebuilt model


def _array(name: str, value, shape: tuple) -> np.ndarray:
    """``value`` as a finite float array of ``shape`` (``None`` entries match any size)."""
    try:
        arr = np.array(value)
    except (TypeError, ValueError):  # ragged nesting
        arr = np.array(None)
    if arr.dtype.kind not in "iuf":
        raise ConfigError(f"{name}: expected an array of numbers")
    arr = arr.astype(float)
    if arr.ndim != len(shape) or any(s is not None and s != n for s, n in zip(shape, arr.shape)):
        want = ", ".join("n" if s is None else str(s) for s in shape)
        raise ConfigError(f"{name}: expected shape ({want}), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ConfigError(f"{name}: contains a non-finite number (NaN or inf)")
    return arr


def _number(name: str, value, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
        raise ConfigError(f"{name}: expected a number, got {value!r}")
    if not np.isfinite(value) or (positive and value <= 0):
        raise ConfigError(f"{name}: expected a {'positive ' if positive else ''}finite number, "
                          f"got {value!r}")
    return float(value)


def _choice(name: str, value, choices) -> str:
    if value not in choices:
        raise ConfigError(f"{name}: {value!r} is not one of {', '.join(map(repr, choices))}")
    return value


def _text(name: str, value) -> str:
    if not isinstance(value, str):
        raise ConfigError(f"{name}: expected a string, got {value!r}")
    return value


def _fields(obj, path: str, keys) -> dict:
    """The required ``keys`` of the JSON object ``obj`` at ``path``."""
    if not isinstance(obj, dict):
        raise ConfigError(f"{path or 'top level'}: expected a JSON object")
    for key in keys:
        if key not in obj:
            raise ConfigError(f"{path + '.' if path else ''}{key}: missing key")
    return {key: obj[key] for key in keys}


def _nested(path: str, build, obj, keys):
    """``build(**fields)`` with errors prefixed by ``path``."""
    kwargs = _fields(obj, path, keys)
    try:
        return build(**kwargs)
    except ConfigError as exc:
        raise ConfigError(f"{path}.{exc}") from None


def _dumps(obj, level: int = 0) -> str:
    """JSON text with one line per vector or matrix row (stable key order, no NaN)."""
    pad, end = " " * (level + 1), "\n" + " " * level
    if isinstance(obj, dict) and obj:
        return "{\n" + ",\n".join(f"{pad}{json.dumps(k)}: {_dumps(v, level + 1)}"
                                   for k, v in obj.items()) + end + "}"
    if isinstance(obj, list) and any(isinstance(v, (dict, list)) for v in obj):
        return "[\n" + ",\n".join(pad + _dumps(v, level + 1) for v in obj) + end + "]"
    return json.dumps(obj, allow_nan=False)


def _created_by() -> dict:
    from .figures import git_commit  # lazy: figures is a higher layer (only for the commit)

    return {"flipkit": __version__, "git": git_commit()}


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
        _text("name", self.name)
        _text("status", self.status)
        it = self.iterations
        if isinstance(it, bool) or not isinstance(it, (int, np.integer)) or it < 0:
            raise ConfigError(f"iterations: expected a non-negative integer, got {it!r}")
        for key in ("wall_time_s", "objective", "max_violation"):
            object.__setattr__(self, key, _number(key, getattr(self, key)))
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
            ``time_of_flight`` (s) (:func:`flipkit.flight.predict_landing`), and
            ``burger_on_blade`` (x, y) (m, blade frame), where the flight starts from.
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

    def __post_init__(self):
        _choice("name", self.name, BEHAVIORS)
        self.T = _number("T", self.T, positive=True)
        self.t = _array("t", self.t, (None,))
        n = self.t.size
        if n < 3 or n % 2 == 0:
            raise ConfigError(f"t: expected N+1 node times with N even >= 2, got {n}")
        self.q = _array("q", self.q, (n, None))
        nq = self.q.shape[1]
        for key in ("qd", "qdd", "u"):
            setattr(self, key, _array(key, getattr(self, key), (n, nq)))
        self.alpha = _array("alpha", self.alpha, (nq, None))
        nodes = self.cone_nodes
        if not isinstance(nodes, (list, tuple, range, np.ndarray)) or not all(
                isinstance(i, (int, np.integer)) and not isinstance(i, bool) and 0 <= i < n
                for i in nodes):
            raise ConfigError(f"cone_nodes: expected node indices in 0..{n - 1}, got {nodes!r}")
        self.cone_nodes = sorted({int(i) for i in nodes})
        if isinstance(self.solver, dict):
            self.solver = _nested("solver", SolverInfo, self.solver,
                                  SolverInfo.__dataclass_fields__)
        if not isinstance(self.solver, SolverInfo):
            raise ConfigError("solver: expected solver statistics")
        if isinstance(self.goal, dict):
            g = _fields(self.goal, "goal", ("p", "o"))
            self.goal = Pose(*(tuple(_array(f"goal.{k}", g[k], (3,))) for k in ("p", "o")))
        if self.goal is not None and self.name != "translate":
            raise ConfigError("goal: only translate segments have a goal pose")
        if (self.release is not None or self.landing is not None) and self.name != "flip":
            raise ConfigError("release, landing: only flip segments have them")
        if self.release is not None:
            r = _fields(self.release, "release", ("node", "time"))
            node = r["node"]
            if isinstance(node, bool) or not isinstance(node, (int, np.integer)) or not (
                    0 < node < n - 1):
                raise ConfigError(f"release.node: expected a node index in 1..{n - 2}, "
                                  f"got {node!r}")
            self.release = {"node": int(node), "time": _number("release.time", r["time"])}
        if self.landing is not None:
            f = _fields(self.landing, "landing", _LANDING_KEYS)
            self.landing = {
                "target": _array("landing.target", f["target"], (2,)).tolist(),
                "r_land": _number("landing.r_land", f["r_land"], positive=True),
                "point": _array("landing.point", f["point"], (3,)).tolist(),
                **{k: _number(f"landing.{k}", f[k]) for k in _LANDING_KEYS[3:]},
                "burger_on_blade": _array("landing.burger_on_blade",
                                          self.landing.get("burger_on_blade", (0.0, 0.0)),
                                          (2,)).tolist()}

    @property
    def N(self) -> int:
        """Number of intervals (N + 1 nodes)."""
        return self.t.size - 1

    @classmethod
    def from_solution(cls, nlp, result, goal: Pose | None = None) -> "Segment":
        """The segment of a solved (or failed) NLP: its ``layout``, ``name``, ``cone_nodes``
        and a :class:`~flipkit.sqp.SolveResult`. The goal of a translate segment defaults to
        its ``end_pose``/``end_orientation`` constraint blocks."""
        L, x = nlp.layout, np.asarray(result.x, dtype=float)
        nodes, T = L.nodes(x), float(x[L.T_index])
        if goal is None and nlp.name == "translate":
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
        return cls(nlp.name, T, L.s * T, nodes[:, 0], nodes[:, 1], nodes[:, 2], nodes[:, 3],
                   L.alpha(x), list(nlp.cone_nodes), info, goal, release, landing)

    def to_json(self) -> dict:
        """The segment as JSON values, keys in file order (``goal`` last, if any)."""
        arrays = {k: getattr(self, k).tolist() for k in ("t", "q", "qd", "qdd", "u", "alpha")}
        out = {"name": self.name, "T": self.T, **arrays, "cone_nodes": list(self.cone_nodes),
               "solver": dict(vars(self.solver))}
        if self.goal is not None:
            out["goal"] = {k: [float(v) for v in getattr(self.goal, k)] for k in ("p", "o")}
        for key in ("release", "landing"):
            if getattr(self, key) is not None:
                out[key] = dict(getattr(self, key))
        return out


_SEGMENT_KEYS = ("name", "T", "t", "q", "qd", "qdd", "u", "alpha", "cone_nodes", "solver")
_LANDING_KEYS = ("target", "r_land", "point", "offset", "tilt_deg", "time_of_flight")
_ROBOT_KEYS = ("urdf", "base_in_world", "tool_parent_frame", "spatula_in_parent", "payload",
               "q_home")
_BURGER_KEYS = ("location", "diameter", "thickness", "mass", "mu")


@dataclass
class Plan:
    """A plan file in memory; attribute names and nesting are the file's (DESIGN.md).

    Attributes:
        behavior: ``translate`` or ``flip``. status: ``solved`` or ``failed``.
        robot: ``urdf`` (path), ``base_in_world`` and ``spatula_in_parent`` (4x4, m),
            ``tool_parent_frame``, ``payload`` (bodies: mass kg, com m, inertia kg·m² in the
            spatula frame) and ``q_home`` (rad). The payload is that of the model carrying
            the burger; segments that do not carry it (CARRIES_BURGER) omit the burger body.
        gravity: (3,) m/s². grill_height: h_g (m). spatula: ``length``, ``width`` (m).
        burger: ``location`` p^b (3,) m or None, ``diameter``, ``thickness`` (m), ``mass``
            (kg), ``mu``. cone: Friction-cone form. segments: The :class:`Segment` list.
        created_by: ``{"flipkit": version, "git": commit or None}``. format: FORMAT.
    """

    behavior: str
    status: str
    robot: dict
    gravity: np.ndarray
    grill_height: float
    spatula: dict
    burger: dict
    cone: str
    segments: list
    created_by: dict = field(default_factory=_created_by)
    format: str = FORMAT

    def __post_init__(self):
        _choice("format", self.format, (FORMAT,))
        _choice("behavior", self.behavior, PLAN_BEHAVIORS)
        _choice("status", self.status, PLAN_STATUSES)
        _choice("cone", self.cone, CONE_FORMS)
        cb = _fields(self.created_by, "created_by", ("flipkit", "git"))
        _text("created_by.flipkit", cb["flipkit"])
        if cb["git"] is not None:
            _text("created_by.git", cb["git"])
        r = _fields(self.robot, "robot", _ROBOT_KEYS)
        for key in ("urdf", "tool_parent_frame"):
            _text(f"robot.{key}", r[key])
        for key, shape in (("base_in_world", (4, 4)), ("spatula_in_parent", (4, 4)),
                           ("q_home", (None,))):
            r[key] = _array(f"robot.{key}", r[key], shape)
        if not isinstance(r["payload"], list):
            raise ConfigError("robot.payload: expected a list of bodies")
        r["payload"] = [self._body(k, body) for k, body in enumerate(r["payload"])]
        self.robot = {**self.robot, **r}
        self.gravity = _array("gravity", self.gravity, (3,))
        self.grill_height = _number("grill_height", self.grill_height)
        self.spatula = {k: _number(f"spatula.{k}", v, positive=True)
                        for k, v in _fields(self.spatula, "spatula", ("length", "width")).items()}
        b = _fields(self.burger, "burger", _BURGER_KEYS)
        self.burger = {k: _number(f"burger.{k}", b[k], positive=True) for k in _BURGER_KEYS[1:]}
        self.burger["location"] = None if b["location"] is None else _array(
            "burger.location", b["location"], (3,))
        self._check_segments()

    @staticmethod
    def _body(k: int, body) -> dict:
        """A payload body as plain JSON values (name optional)."""
        where = f"robot.payload[{k}]"
        b = _fields(body, where, ("parent_frame", "mass", "com", "inertia"))
        out = {"name": _text(f"{where}.name", body["name"])} if "name" in body else {}
        return {**out, "parent_frame": _text(f"{where}.parent_frame", b["parent_frame"]),
                "mass": _number(f"{where}.mass", b["mass"], positive=True),
                "com": _array(f"{where}.com", b["com"], (3,)).tolist(),
                "inertia": _array(f"{where}.inertia", b["inertia"], (3, 3)).tolist()}

    def _check_segments(self) -> None:
        if not isinstance(self.segments, list) or not self.segments:
            raise ConfigError("segments: expected a non-empty list of segments")
        nq, names = self.robot["q_home"].size, []
        for k, seg in enumerate(self.segments):
            if isinstance(seg, dict):
                keys = _SEGMENT_KEYS + tuple(k for k in ("goal", "release", "landing")
                                             if k in seg)
                seg = self.segments[k] = _nested(f"segments[{k}]", Segment, seg, keys)
            if not isinstance(seg, Segment):
                raise ConfigError(f"segments[{k}]: expected a segment")
            if seg.q.shape[1] != nq:
                raise ConfigError(f"segments[{k}].q: {seg.q.shape[1]} joints, "
                                  f"robot.q_home has {nq}")
            names.append(seg.name)
        allowed = ("translate",) if self.behavior == "translate" else SUBBEHAVIORS
        order = [allowed.index(n) if n in allowed else -1 for n in names]
        if -1 in order or (self.behavior == "flip" and order != sorted(set(order))):
            raise ConfigError(f"segments: names {names} do not fit behavior {self.behavior!r} "
                              f"(expected {', '.join(allowed)}"
                              f"{' in this order' if len(allowed) > 1 else ''})")
        if self.behavior == "flip" and self.burger["location"] is None:
            raise ConfigError("burger.location: a flip plan needs the burger location")

    # ------------------------------------------------------------------ building
    @classmethod
    def from_segments(cls, behavior: str, cell: CellConfig, segments: list, *, location=None,
                      cone: str = "physical", status: str | None = None) -> "Plan":
        """A plan of ``segments`` planned in ``cell``; status ``solved`` if every segment's
        solver says so (check it with :func:`flipkit.verify.verify_plan` before writing)."""
        from .robot import Robot

        robot = Robot(cell, with_burger=True)
        if status is None:
            status = "solved" if all(s.solver.status == "solved" for s in segments) else "failed"
        return cls(behavior, status, {
            "urdf": robot.urdf, "base_in_world": np.asarray(cell.robot.base_in_world, float),
            "tool_parent_frame": cell.robot.tool_frame,
            "spatula_in_parent": robot.spatula_in_parent, "payload": robot.payload_json(),
            "q_home": robot.q_home},
            np.asarray(cell.gravity, float), cell.grill.height,
            {"length": cell.spatula.length, "width": cell.spatula.width},
            {"location": None if location is None else list(location),
             **{k: getattr(cell.burger, k) for k in _BURGER_KEYS[1:]}}, cone, list(segments))

    def cell(self) -> CellConfig:
        """The cell the plan was made in, rebuilt from the file (task-space limits, grill and
        table areas and the acceleration limit are not recorded: defaults are used).

        Raises:
            PlanFileError: The URDF is missing here, or the spatula cannot be rebuilt.
        """
        r, w = self.robot, self.spatula["width"]
        spatula = next((b for b in r["payload"] if b.get("name", "spatula") == "spatula"), None)
        if spatula is None:
            raise PlanFileError("robot.payload: no spatula body")
        m, Ixx = float(spatula["mass"]), float(np.asarray(spatula["inertia"])[0][0])
        thickness2 = 12 * Ixx / m - w**2  # thin box: I_xx = m (w² + t²) / 12
        try:
            return CellConfig(
                robot=RobotConfig(urdf=r["urdf"], tool_frame=r["tool_parent_frame"],
                                  base_in_world=tuple(map(tuple, r["base_in_world"])),
                                  q_home=tuple(r["q_home"])),
                spatula=SpatulaConfig(self.spatula["length"], w, np.sqrt(max(thickness2, 0.0)),
                                      float(r["spatula_in_parent"][2, 3]), m),
                burger=BurgerConfig(**{k: self.burger[k] for k in _BURGER_KEYS[1:]}),
                grill=GrillConfig(height=self.grill_height), gravity=tuple(self.gravity))
        except ConfigError as exc:
            raise PlanFileError(f"cannot rebuild the cell from the plan: {exc}") from None

    def robot_for(self, name: str, cell: CellConfig | None = None):
        """The dynamics model of segment ``name`` (burger on the blade per CARRIES_BURGER),
        checked against the recorded mount and payload.

        Raises:
            PlanFileError: The rebuilt model's spatula mount or payload differs from the file's.
        """
        from .robot import Robot

        robot = Robot(cell or self.cell(), with_burger=CARRIES_BURGER[name])
        if not np.allclose(robot.spatula_in_parent, self.robot["spatula_in_parent"], atol=1e-9):
            raise PlanFileError("robot.spatula_in_parent: not the flipkit spatula mount")
        recorded, mine = self.robot["payload"], robot.payload_json()
        if len(recorded) < len(mine) or (CARRIES_BURGER[name] and len(recorded) != len(mine)):
            raise PlanFileError(f"robot.payload: {len(recorded)} bodies, the model of segment "
                                f"{name!r} has {len(mine)}")
        for k, body in enumerate(mine):
            if not all(np.allclose(body[key], recorded[k][key], rtol=PAYLOAD_RTOL, atol=1e-12)
                       for key in ("mass", "com", "inertia")):
                raise PlanFileError(f"robot.payload[{k}]: does not match the {body['name']} "
                                    "rebuilt from the spatula and burger of the plan")
        return robot

    # ------------------------------------------------------------------ file
    def to_json(self, path) -> Path:
        """Write the plan to ``path`` (atomically) and return the path."""
        """Write the plan to ``path`` (atomically: a temporary file, then renamed).

        Raises:
            PlanFileError: The file cannot be written.
        """
        robot = {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                 for k, v in ((k, self.robot[k]) for k in _ROBOT_KEYS)}
        loc = self.burger["location"]
        doc = {"format": self.format, "behavior": self.behavior, "status": self.status,
               "created_by": dict(self.created_by), "robot": robot,
               "gravity": self.gravity.tolist(), "grill_height": self.grill_height,
               "spatula": dict(self.spatula),
               "burger": {"location": None if loc is None else loc.tolist(),
                          **{k: self.burger[k] for k in _BURGER_KEYS[1:]}},
               "cone": self.cone, "segments": [s.to_json() for s in self.segments]}
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        try:
            tmp.write_text(_dumps(doc) + "\n")
            os.replace(tmp, path)
        except OSError as exc:
            raise PlanFileError(f"{path}: cannot write plan file ({exc.strerror or exc})") from None
        return path

    @classmethod
    def load(cls, path) -> "Plan":
        """Read and validate a plan file.

        Raises:
            PlanFileError: Missing or unreadable file, not JSON, or not ``flipkit-plan/1``
                (the one-line message names the file and the offending key).
        """
        path = Path(path)
        try:
            doc = json.loads(path.read_text())
        except OSError as exc:
            raise PlanFileError(f"{path}: cannot read plan file ({exc.strerror or exc})") from None
        except (UnicodeDecodeError, ValueError) as exc:
            msg = str(exc).splitlines()[0]
            raise PlanFileError(f"{path}: not a JSON file ({msg})") from None
        try:
            if isinstance(doc, dict) and doc.get("format") != FORMAT:
                raise ConfigError(f"format: expected {FORMAT!r}, got {doc.get('format')!r}")
            keys = ("behavior", "status", "robot", "gravity", "grill_height", "spatula", "burger",
                    "cone", "segments", "created_by")
            return cls(**_fields(doc, "", keys))
        except ConfigError as exc:
            raise PlanFileError(f"{path}: {exc}") from None
