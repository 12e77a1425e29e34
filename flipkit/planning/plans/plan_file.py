"""The plan file ``flipkit-plan/2`` (JSON): a planned trajectory with everything needed to
check or execute it without the objects that made it (``docs/plan-format.md``).

:class:`Plan` and :class:`Segment` mirror the file key for key. Constructors validate their
arguments and raise :class:`~flipkit.errors.ConfigError` naming the field;
:meth:`Plan.load` turns every problem (missing file, not JSON, wrong format, missing key,
wrong shape, non-finite number, unknown name) into a one-line
:class:`~flipkit.errors.PlanFileError` naming the file and the key path, e.g.
``plan.json: segments[2].q: expected shape (21, 6), got (20, 6)``.

The format is documented in ``docs/plan-format.md`` (JSON Schema beside it). Among its
fields: ``segments[k].goal = {"p": [3], "o": [3]}`` — the end pose of a
``translate`` segment (optional) — and, on a flip segment, ``release`` (node, time) and the
predicted ``landing`` (target, r_land, point, offset, tilt_deg, time_of_flight), checked by
:mod:`flipkit.planning.plans.verify`.
"""

from __future__ import annotations

import json
from importlib import resources
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from flipkit.behaviors.library import BEHAVIORS, SUBBEHAVIORS
from flipkit import __version__
from flipkit.config import BurgerConfig, CellConfig, GrillConfig, RobotConfig, SpatulaConfig
from flipkit.model.contact import CONE_FORMS
from flipkit.errors import ConfigError, PlanFileError
from flipkit.fileio import OutputPathError, write_text
from flipkit.planning.plans.json_fields import (check_array, check_choice, check_keys, check_nested,
                                          check_number, check_text, dumps)
from flipkit.planning.plans.segment import SEGMENT_KEYS, Segment, default_payload
from flipkit.planning.plans.cell_record import cell_geometry, geometry_configs
from flipkit.provenance import git_commit
from flipkit.config.urdf import check_urdf_text, portable_urdf, resolve_urdf, urdf_sha256

from flipkit.planning.plans.plan_doc import FORMAT, FORMATS, plan_path, read_plan_doc  # noqa: E402
from flipkit.model.robot import Robot
PLAN_STATUSES = ("solved", "failed")
PAYLOAD_RTOL = 1e-9  # relative agreement of the recorded payload with the rebuilt model



SCHEMA_FILE = "plan-format.schema.json"  # in flipkit/data (package data)


def check_schema(doc) -> None:
    """Validate a plan document against the documented JSON Schema (read from the package's
    data and made into a validator for each check: a fraction of a millisecond).

    Raises:
        ConfigError: The first violation, one line: the key path and what is wrong.
    """
    import jsonschema  # slow to import: a refusal before any plan is read does without it

    schema = json.loads(resources.files("flipkit").joinpath("data", SCHEMA_FILE).read_text())
    validator = jsonschema.Draft202012Validator(schema)
    error = next(iter(sorted(validator.iter_errors(doc), key=lambda e: e.path)), None)
    if error is not None:
        where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in error.path)
        message = " ".join(error.message.split())
        raise ConfigError(f"{where.lstrip('.') or 'top level'}: {message[:200]} (JSON Schema)")


def _created_by() -> dict:
    return {"flipkit": __version__, "git": git_commit()}


_ROBOT_KEYS = ("urdf", "base_in_world", "tool_parent_frame", "spatula_in_parent", "payload",
               "q_home")
_BURGER_KEYS = ("location", "diameter", "thickness", "mass", "mu")
ARM_KEYS = ("profile", "speed_margin", "safety_preset")


def arm_record(record) -> dict:
    """The plan's ``robot.arm`` record checked: ``{"profile", "speed_margin",
    "safety_preset"}`` (:class:`~flipkit.config.RobotConfig`'s fields); a file written
    without it gets the defaults, against which ``flipkit verify`` then checks it."""
    if record is None:
        rc = RobotConfig.__dataclass_fields__
        return {k: rc[k].default for k in ARM_KEYS}
    if not isinstance(record, dict) or sorted(record) != sorted(ARM_KEYS):
        got = sorted(record) if isinstance(record, dict) else type(record).__name__
        raise ConfigError(f"robot.arm: expected the keys {', '.join(ARM_KEYS)}, got {got}")
    for key in ("profile", "safety_preset"):
        if not isinstance(record[key], str):
            raise ConfigError(f"robot.arm.{key}: expected a name, got {record[key]!r}")
    try:
        RobotConfig(**record, urdf=None)  # the profile, preset and margin checked there
    except ConfigError as exc:
        raise ConfigError(f"robot.arm: {exc}") from None
    return dict(record)


def segment_span(segments, name: str) -> tuple[float, float] | None:
    """(start, end) (s, from the first segment's start) of the first of ``segments`` named
    ``name``, chained end to start, or ``None`` if none is."""
    t = 0.0
    for seg in segments:
        if seg.name == name:
            return t, t + float(seg.T)
        t += float(seg.T)
    return None


@dataclass
class Plan:
    """A plan file in memory; attribute names and nesting are the file's (``docs/plan-format.md``).

    Attributes:
        behavior: ``translate``, ``flip`` or ``serve``. status: ``solved`` or ``failed``.
        robot: ``urdf`` (portable name ``example-robot-data:<path>`` or absolute path, see
            :mod:`flipkit.config.urdf`), ``urdf_sha256`` (of its bytes; None in a
            ``flipkit-plan/1`` file), ``base_in_world`` and ``spatula_in_parent`` (4x4, m),
            ``tool_parent_frame``, ``payload`` (bodies: mass kg, com m, inertia kg·m² in the
            spatula frame) and ``q_home`` (rad). The payload lists every body any segment
            carries; each segment names the ones its dynamics carry (``Segment.payload``).
        gravity: (3,) m/s². grill_height: h_g (m). spatula: ``length``, ``width`` (m).
        burger: ``location`` p^b (3,) m or None, ``diameter``, ``thickness`` (m), ``mass``
            (kg), ``mu``, ``heading``: the scoop heading (rad; 0, the world's +x, in a file
            written without it). cone: Friction-cone form. segments: The :class:`Segment` list.
        created_by: ``{"flipkit": version, "git": commit or None}``. format: the file's
            format (one of :data:`FORMATS`; written as :data:`FORMAT`).
        report: The planner's :class:`~flipkit.planning.plans.verify_report.VerificationReport`
            of the plan. failure: One line, why the plan failed (``None`` when solved).
            wall_time_s: Planning time (s), from the planner's start to the verified plan.
            These three are set by the planner and are not part of the file: ``None`` on a
            plan read from one or made by :func:`dataclasses.replace`.
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
    cell_geometry: dict | None = None
    report: object = field(default=None, init=False, repr=False, compare=False)
    failure: str | None = field(default=None, init=False, compare=False)
    wall_time_s: float | None = field(default=None, init=False, compare=False)

    def __post_init__(self):
        check_choice("format", self.format, FORMATS)
        check_choice("behavior", self.behavior, tuple(BEHAVIORS))
        check_choice("status", self.status, PLAN_STATUSES)
        check_choice("cone", self.cone, CONE_FORMS)
        cb = check_keys(self.created_by, "created_by", ("flipkit", "git"))
        check_text("created_by.flipkit", cb["flipkit"])
        if cb["git"] is not None:
            check_text("created_by.git", cb["git"])
        r = check_keys(self.robot, "robot", _ROBOT_KEYS)
        for key in ("urdf", "tool_parent_frame"):
            check_text(f"robot.{key}", r[key])
        for key, shape in (("base_in_world", (4, 4)), ("spatula_in_parent", (4, 4)),
                           ("q_home", (None,))):
            r[key] = check_array(f"robot.{key}", r[key], shape)
        if not isinstance(r["payload"], list):
            raise ConfigError("robot.payload: expected a list of bodies")
        r["payload"] = [self._body(k, body) for k, body in enumerate(r["payload"])]
        sha = self.robot.get("urdf_sha256")
        if sha is None and self.format != FORMATS[0]:
            raise ConfigError("robot.urdf_sha256: missing key")
        if sha is not None and not (isinstance(sha, str) and len(sha) == 64
                                    and all(c in "0123456789abcdef" for c in sha)):
            raise ConfigError(f"robot.urdf_sha256: expected 64 lowercase hex digits, got {sha!r}")
        r["urdf_sha256"] = sha
        r["arm"] = arm_record(self.robot.get("arm"))
        self.robot = {**self.robot, **r}
        self.gravity = check_array("gravity", self.gravity, (3,))
        self.grill_height = check_number("grill_height", self.grill_height)
        if self.cell_geometry is not None:
            grill = geometry_configs(self.cell_geometry)["grill"]
            if abs(grill.height - float(self.grill_height)) > 1e-12:
                raise ConfigError(f"cell_geometry.grill.height: {grill.height} differs from "
                                  f"grill_height {self.grill_height}")
        self.spatula = {k: check_number(f"spatula.{k}", v, positive=True)
                        for k, v in check_keys(self.spatula, "spatula", ("length", "width")).items()}
        raw_burger = self.burger
        b = check_keys(raw_burger, "burger", _BURGER_KEYS)
        self.burger = {k: check_number(f"burger.{k}", b[k], positive=True) for k in _BURGER_KEYS[1:]}
        self.burger["location"] = None if b["location"] is None else check_array(
            "burger.location", b["location"], (3,))
        heading = raw_burger.get("heading", 0.0) if isinstance(raw_burger, dict) else 0.0
        self.burger["heading"] = check_number("burger.heading", heading)
        self._check_segments()

    @staticmethod
    def _body(k: int, body) -> dict:
        """A payload body as plain JSON values (name optional)."""
        where = f"robot.payload[{k}]"
        b = check_keys(body, where, ("parent_frame", "mass", "com", "inertia"))
        # flipkit-plan/1 left names optional: the spatula first, the burger second
        name = body["name"] if "name" in body else ("spatula", "burger")[min(k, 1)]
        return {"name": check_text(f"{where}.name", name), "parent_frame": check_text(f"{where}.parent_frame", b["parent_frame"]),
                "mass": check_number(f"{where}.mass", b["mass"], positive=True),
                "com": check_array(f"{where}.com", b["com"], (3,)).tolist(),
                "inertia": check_array(f"{where}.inertia", b["inertia"], (3, 3)).tolist()}

    def _check_segments(self) -> None:
        if not isinstance(self.segments, list) or not self.segments:
            raise ConfigError("segments: expected a non-empty list of segments")
        nq, names = self.robot["q_home"].size, []
        for k, seg in enumerate(self.segments):
            if isinstance(seg, dict):
                if "payload" not in seg and self.format != FORMATS[0]:  # /1: by behaviour
                    raise ConfigError(f"segments[{k}].payload: missing key")
                keys = SEGMENT_KEYS + tuple(k for k in ("goal", "release", "landing", "payload",
                                                        "placing")
                                             if k in seg)
                seg = self.segments[k] = check_nested(f"segments[{k}]", Segment, seg, keys)
            if not isinstance(seg, Segment):
                raise ConfigError(f"segments[{k}]: expected a segment")
            bodies = [b["name"] for b in self.robot["payload"]]
            unknown = [b for b in seg.payload if b not in bodies]
            if unknown:
                raise ConfigError(f"segments[{k}].payload: {unknown} not in robot.payload "
                                  f"({', '.join(bodies)})")
            if seg.q.shape[1] != nq:
                raise ConfigError(f"segments[{k}].q: {seg.q.shape[1]} joints, "
                                  f"robot.q_home has {nq}")
            names.append(seg.name)
        behavior = BEHAVIORS[self.behavior]
        allowed = behavior.names
        order = [allowed.index(n) if n in allowed else -1 for n in names]
        if -1 in order or (not behavior.open_ended and order != sorted(set(order))):
            raise ConfigError(f"segments: names {names} do not fit behavior {self.behavior!r} "
                              f"(expected {', '.join(allowed)}"
                              f"{' in this order' if len(allowed) > 1 else ''})")
        if any("location" in s.needs for s in behavior.steps) and self.burger["location"] is None:
            raise ConfigError(f"burger.location: a {self.behavior} plan needs the burger location")

    # ------------------------------------------------------------------ building
    @classmethod
    def from_segments(cls, behavior: str, cell: CellConfig, segments: list, *, location=None,
                      heading: float = 0.0, cone: str = "physical",
                      status: str | None = None) -> "Plan":
        """A plan of ``segments`` planned in ``cell``; status ``solved`` if every segment's
        solver says so (check it with :func:`flipkit.planning.plans.verify.verify_plan` before writing)."""
        robot = Robot(cell, with_burger=True)
        if status is None:
            status = "solved" if all(s.solver.status == "solved" for s in segments) else "failed"
        return cls(behavior, status, {
            "urdf": portable_urdf(robot.urdf), "urdf_sha256": urdf_sha256(robot.urdf),
            "base_in_world": np.asarray(cell.robot.base_in_world, float),
            "tool_parent_frame": cell.robot.tool_frame,
            "spatula_in_parent": robot.spatula_in_parent, "payload": robot.payload_json(),
            "q_home": robot.q_home, "arm": arm_record({
                "profile": cell.robot.profile, "speed_margin": cell.robot.speed_margin,
                "safety_preset": cell.robot.safety_preset})},
            np.asarray(cell.gravity, float), cell.grill.height,
            {"length": cell.spatula.length, "width": cell.spatula.width},
            {"location": None if location is None else list(location),
             **{k: getattr(cell.burger, k) for k in _BURGER_KEYS[1:]}, "heading": float(heading)},
            cone, list(segments),
            cell_geometry=cell_geometry(cell))

    def cell(self) -> CellConfig:
        """The cell the plan was made in, rebuilt from the file: its grill and table, task-space
        limits, space limits and acceleration bound from ``cell_geometry`` (a file written
        without it gets today's defaults for them, :mod:`flipkit.planning.plans.cell_record`).

        Raises:
            PlanFileError: The URDF is missing here, differs from the one the plan recorded
                (sha256), or the spatula cannot be rebuilt.
        """
        r, w = self.robot, self.spatula["width"]
        try:
            path = resolve_urdf(r["urdf"])
            check_urdf_text(path)
        except ConfigError as exc:
            raise PlanFileError(f"robot.urdf: {exc}") from None
        if r.get("urdf_sha256") is not None and urdf_sha256(path) != r["urdf_sha256"]:
            raise PlanFileError(f"robot.urdf: {path} is not the URDF the plan was made with "
                                "(its sha256 differs from robot.urdf_sha256); give the plan's "
                                "URDF or plan again")
        spatula = next((b for b in r["payload"] if b.get("name", "spatula") == "spatula"), None)
        if spatula is None:
            raise PlanFileError("robot.payload: no spatula body")
        m, Ixx = float(spatula["mass"]), float(np.asarray(spatula["inertia"])[0][0])
        thickness2 = 12 * Ixx / m - w**2  # thin box: I_xx = m (w² + t²) / 12
        try:
            geo = {} if self.cell_geometry is None else geometry_configs(self.cell_geometry)
            accel = {} if not geo else {k: geo.pop(k) for k in ("accel_limit",
                                                                 "free_accel_limit")}
            if geo:  # grill_height is the plan's h_g (the record agreed with it when read)
                geo["grill"] = GrillConfig(self.grill_height, geo["grill"].x_range,
                                           geo["grill"].y_range)
            return CellConfig(
                robot=RobotConfig(urdf=r["urdf"], tool_frame=r["tool_parent_frame"],
                                  base_in_world=tuple(map(tuple, r["base_in_world"])),
                                  q_home=tuple(r["q_home"]), **r["arm"], **accel),
                spatula=SpatulaConfig(self.spatula["length"], w, np.sqrt(max(thickness2, 0.0)),
                                      float(r["spatula_in_parent"][2, 3]), m),
                burger=BurgerConfig(**{k: self.burger[k] for k in _BURGER_KEYS[1:]}),
                gravity=tuple(self.gravity), **{"grill": GrillConfig(height=self.grill_height),
                                                **geo})
        except ConfigError as exc:
            raise PlanFileError(f"cannot rebuild the cell from the plan: {exc}") from None

    def segment(self, name: str):
        """The plan's first :class:`Segment` named ``name``, or ``None`` if it has none."""
        return next((s for s in self.segments if s.name == name), None)

    def step(self, role: str):
        """The plan's first segment of its behaviour's step of ``role``
        (:meth:`~flipkit.behaviors.spec.Behavior.step`), or ``None`` if it has none.

        Raises:
            ConfigError: Its behaviour has no step of that role.
        """
        return self.segment(BEHAVIORS[self.behavior].step(role).name)

    def step_span(self, role: str) -> tuple[float, float] | None:
        """(start, end) (s, from the plan's start) of its segment of ``role``
        (:meth:`step`), or ``None`` if it has none."""
        return self.segment_span(BEHAVIORS[self.behavior].step(role).name)

    @property
    def duration(self) -> float:
        """Its executed duration (s): the sum of its segments'."""
        return float(sum(seg.T for seg in self.segments))

    def segment_span(self, name: str) -> tuple[float, float] | None:
        """(start, end) (s, from the plan's start) of its first segment named ``name``, or
        ``None`` if it has none (:func:`segment_span`)."""
        return segment_span(self.segments, name)

    def robot_for(self, segment, cell: CellConfig | None = None):
        """The dynamics model of ``segment`` (a :class:`Segment` of this plan, or a name: its
        first segment of that name, or a behaviour the plan lacks, which carries what that
        behaviour carries), with the bodies its ``payload`` names, checked against the
        recorded mount and bodies.

        Raises:
            PlanFileError: No such segment, or the rebuilt model's spatula mount or a body
                differs from the file's.
        """
        if isinstance(segment, str):
            seg = self.segment(segment)
            if seg is None and segment not in SUBBEHAVIORS:
                raise PlanFileError(f"segments: no segment {segment!r} in this plan "
                                    f"({', '.join(s.name for s in self.segments)})")
            payload = seg.payload if seg is not None else default_payload(segment)
            name = segment
        else:
            payload, name = segment.payload, segment.name
        cell = cell or self.cell()
        try:
            robot = Robot(cell, with_burger="burger" in payload)
        except (ValueError, RuntimeError, KeyError, IndexError) as exc:  # pinocchio's parser
            reason = " ".join(str(exc).split())[:160]
            raise PlanFileError(f"robot.urdf: {self.robot['urdf']} cannot be built into the arm's "
                                f"model ({type(exc).__name__}: {reason})") from None
        if not np.allclose(robot.spatula_in_parent, self.robot["spatula_in_parent"], atol=1e-9):
            raise PlanFileError("robot.spatula_in_parent: not the flipkit spatula mount")
        recorded = {b["name"]: (k, b) for k, b in enumerate(self.robot["payload"])}
        mine = robot.payload_json()
        if sorted(b["name"] for b in mine) != sorted(payload):
            raise PlanFileError(f"segment {name!r}: payload {payload}, but flipkit's model "
                                f"carries {[b['name'] for b in mine]}")
        for body in mine:
            if body["name"] not in recorded:
                raise PlanFileError(f"robot.payload: no {body['name']!r} body for segment "
                                    f"{name!r}")
            k, rec = recorded[body["name"]]
            if not all(np.allclose(body[key], rec[key], rtol=PAYLOAD_RTOL, atol=1e-12)
                       for key in ("mass", "com", "inertia")):
                raise PlanFileError(f"robot.payload[{k}]: does not match the {body['name']} "
                                    "rebuilt from the spatula and burger of the plan")
        return robot

    # ------------------------------------------------------------------ file
    def to_json(self, path) -> Path:
        """Write the plan to ``path`` as :data:`FORMAT` (atomically: a temporary file, then
        renamed) and return the path.

        Raises:
            PlanFileError: The file cannot be written.
        """
        robot = {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                 for k, v in ((k, self.robot[k]) for k in _ROBOT_KEYS)}
        sha = self.robot.get("urdf_sha256")
        if sha is None:  # read from a flipkit-plan/1 file: record the URDF found here
            try:
                sha = urdf_sha256(resolve_urdf(self.robot["urdf"]))
            except ConfigError as exc:
                raise PlanFileError(f"robot.urdf: {exc}") from None
        robot = {"urdf": robot["urdf"], "urdf_sha256": sha,
                 **{k: v for k, v in robot.items() if k != "urdf"},
                 "arm": dict(self.robot["arm"])}
        loc = self.burger["location"]
        doc = {"format": FORMAT, "behavior": self.behavior, "status": self.status,
               "created_by": dict(self.created_by), "robot": robot,
               "gravity": self.gravity.tolist(), "grill_height": self.grill_height,
               "spatula": dict(self.spatula),
               "burger": {"location": None if loc is None else loc.tolist(),
                          **{k: self.burger[k] for k in _BURGER_KEYS[1:]},
                          "heading": self.burger["heading"]},
               "cone": self.cone, "segments": [s.to_json() for s in self.segments]}
        if self.cell_geometry is not None:
            doc["cell_geometry"] = self.cell_geometry
        path = Path(path)
        try:
            return write_text(path, dumps(doc) + "\n")
        except OutputPathError as exc:
            raise PlanFileError(f"{path}: cannot write plan file ({exc})") from None

    @classmethod
    def load(cls, path) -> "Plan":
        """Read and validate a plan file: key by key, then against the documented JSON Schema
        (``flipkit/data/plan-format.schema.json``, :func:`check_schema`). A
        ``flipkit-plan/1`` file (before per-segment payloads and portable URDF names) is read
        too: each segment then carries the bodies its behaviour carries (the spec's ``carries_burger``).

        Raises:
            PlanFileError: Not a path, missing or unreadable file, not JSON, or not
                ``flipkit-plan/1`` or ``/2`` (the one-line message names the file and the
                offending key).
        """
        path = plan_path(path)
        doc = read_plan_doc(path)  # file, JSON, format, top-level keys: before any schema
        try:
            keys = ("behavior", "status", "robot", "gravity", "grill_height", "spatula", "burger",
                    "cone", "segments", "created_by")
            fields = check_keys(doc, "", keys)
            if isinstance(fields["segments"], list):  # the plan replaces the segment dicts:
                fields["segments"] = list(fields["segments"])  # the schema sees the file's
            # the key checks first: their messages are the more precise, and a file they
            # refuse is refused without importing jsonschema
            plan = cls(**fields, format=doc["format"], cell_geometry=doc.get("cell_geometry"))
            check_schema(doc)
            return plan
        except RecursionError:
            raise PlanFileError(f"{path}: nested too deeply to be a plan file") from None
        except ConfigError as exc:
            raise PlanFileError(f"{path}: {exc}") from None
