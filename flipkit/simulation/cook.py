"""A whole cook in one MuJoCo simulation: every motion of a schedule, in order, on one cell
holding every burger.

The scene is :func:`~flipkit.simulation.scene.build_scene` with one body per burger (and
burger–burger contact). On the cook's clock (s, the timeline's):

* a burger appears at its drop time, placed at rest on the grill at its drop position;
  before that it is parked out of the cell (below the floor, held against gravity);
* the arm runs the timeline's motions at their start times, each plan stepped by
  :func:`~flipkit.simulation.control.step_references` with the controller of
  :func:`~flipkit.simulation.execute.execute_plan` (default: position mode, the plans'
  own commands — the robot's own servo; feed-forward as an option), from whatever state the
  previous motion left (no reset: a burger lies where it landed, the arm where it stopped);
* after a motion the arm holds its plan's last command for at least
  :data:`~flipkit.simulation.execute.HOLD_S` (less when the next motion starts sooner), then
  on while any burger or the arm still moves faster than :data:`REST_SPEED` (at most
  :data:`MAX_SETTLE_S`);
* a served burger is taken away (parked again) the table's dwell (``timeline.dwell_s``,
  :data:`~flipkit.planning.kitchen.table.DWELL_S` by default) after its serve ends, and
  not before its serve is judged (``HOLD_S`` after the serve).

Idle intervals are skipped, not stepped: from the end of a motion's settling to the next
motion's start the state is carried over unchanged (only the clock moves, and drops and
take-aways happen at their times). This stands for stepping them because every body is at
rest then — the arm holds home under its PD, each burger rests on a plate under static
friction (``noslip``) — so stepping would leave the state where it is; the speeds at each
skip are reported (:attr:`CookSimulation.skip_speed`), and ``step_idle=True`` steps them
instead (the arm holding its last command), for comparison. A motion that starts less
than one control step after the previous one's settling ends skips that fraction too.

With ``sense_serve`` a serve is sense-plan-act: at its start the camera sees where its burger
lies on the grill (the true place plus the camera's error, :data:`SENSING_SIGMA` per axis,
seeded) and the serve is re-planned for that place; the new plan runs if it is verified and
no longer than the planned one (the schedule is kept), else the planned one does. Planning
happens while the burger cooks its second side, so it takes no cook time. With
``sense_blade`` the camera also sees the burger on the blade during the carry, and place and
return home are re-planned while the carry finishes (:mod:`flipkit.simulation.cook_blade`).

The burgers are judged one by one on their own trajectories
(:mod:`flipkit.simulation.cook_judges`); a burger moved while it lay untouched by its own
motions is reported as knocked (:mod:`flipkit.simulation.cook_record`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import mujoco
import numpy as np

from flipkit.behaviors.library import SERVE
from flipkit.config import CellConfig, SensingUncertainty
from flipkit.errors import ConfigError, FlipkitError, InvalidChoiceError
from flipkit.model.robot import Robot
from flipkit.planning.plans.servo_command import COMMANDS, DEFAULT_COMMAND
from flipkit.simulation.control import ArmController, plan_references, step_references
from flipkit.simulation.cook_judges import BurgerResult, judge_burger
from flipkit.simulation.cook_record import CookRecorder, Watch
from flipkit.simulation.execute import HOLD_S
from flipkit.simulation.modes import MODES, POSITION
from flipkit.simulation.cook_blade import blade_replan, sense_time
from flipkit.simulation.patty import scoop_heading
from flipkit.simulation.scene import ARM_JOINTS, Scene, build_scene, park_burger, place_burger

REST_SPEED = 1e-3  # m/s (burger centres) and rad/s (arm joints): "at rest" before a skip
MAX_SETTLE_S = 5.0  # s after a motion's end: the longest the cell is stepped to come to rest
# m per axis: the camera's error on a burger's place, as sense-plan-act's on the blade
# (flipkit.config.SensingUncertainty, with its source)
SENSING_SIGMA = SensingUncertainty().sigma


class CookNotSimulatedError(ConfigError):
    """A timeline that is not a solved cook (a failed plan, no motions): not simulated."""


@dataclass
class CookSimulation:
    """A simulated cook.

    Attributes:
        burgers: One :class:`~flipkit.simulation.cook_judges.BurgerResult` per burger, in
            drop order.
        mode, command: The controller and position mode's command stream.
        min_distance_m: Smallest centre distance (m, in the plane) between two burgers
            lying on the grill or table (``inf``: never two at once).
        stepped_s, skipped_s: Cook time stepped and skipped (s).
        skip_speed: Largest burger speed (m/s) and arm joint speed (rad/s) when an idle
            interval was skipped: ``{"burger_m_s", "arm_rad_s"}``.
        wall_s: Wall time of the simulation (s).
        frames: ``(cook time s, label, qpos)`` for the film (empty without ``film_fps``).
        scene: The cell, in its final state.
        runs: ``{(burger id, kind): BurgerRun}``: each burger's own trajectory over its flip
            and serve windows, on times from the motion's start (what the judges read).
        sensed: One record per sensed serve (``sense_serve``): ``burger``, ``true_xy``,
            ``sensed_xy``, ``planned_xy`` (m), ``replanned`` and ``why`` (the planned serve
            ran), ``wall_s`` of the re-plan.
        sensed_blade: One record per serve sensed on the blade (``sense_blade``):
            ``serve`` (burger id) and :func:`~flipkit.simulation.cook_blade.blade_replan`'s
            record.
    """

    burgers: list[BurgerResult]
    mode: str
    command: str
    min_distance_m: float
    stepped_s: float
    skipped_s: float
    skip_speed: dict
    wall_s: float
    frames: list
    scene: Scene
    runs: dict
    sensed: list = field(default_factory=list)
    sensed_blade: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """Every burger flipped and served."""
        return all(b.ok for b in self.burgers)

    def to_dict(self) -> dict:
        """JSON-ready summary (the timeline's ``simulation``)."""
        return {"mode": self.mode, "command": self.command, "ok": self.ok,
                "burgers": [b.to_dict() for b in self.burgers],
                "min_distance_m": (None if not np.isfinite(self.min_distance_m)
                                   else round(self.min_distance_m, 6)),
                "stepped_s": round(self.stepped_s, 3), "skipped_s": round(self.skipped_s, 3),
                "skip_speed": {k: float(f"{v:.3g}") for k, v in self.skip_speed.items()},
                "wall_s": round(self.wall_s, 2), "sensed_serves": self.sensed,
                "sensed_on_blade": self.sensed_blade}


def _check(timeline, mode: str, command: str, kinds_needed=("flip", "serve")) -> list:
    if mode not in MODES:
        raise InvalidChoiceError("execution mode", mode, MODES)
    if command not in COMMANDS:
        raise InvalidChoiceError("position command", command, COMMANDS)
    if not timeline.motions or not timeline.ok:
        bad = next((m for m in timeline.motions if not m.ok), None)
        raise CookNotSimulatedError(
            "a failed schedule is not simulated" + (f": {bad.key}: {bad.failure}" if bad else
                                                    ": it has no motions"))
    if any(m.plan is None for m in timeline.motions):
        raise CookNotSimulatedError("the timeline holds no plans (read from JSON?): "
                                    "nothing to simulate")
    return list(timeline.motions)


def simulate_cook(timeline, *, mode: str = POSITION, command: str = DEFAULT_COMMAND,
                  cell: CellConfig | None = None, rate_hz: float = 1000.0,
                  film_fps: float = 0.0, step_idle: bool = False, sense_serve=None,
                  sense_blade=None, sensing_sigma: float = SENSING_SIGMA,
                  seed: int = 0) -> CookSimulation:
    """Simulate the whole cook of ``timeline`` (module docstring).

    Args:
        timeline: A solved :class:`~flipkit.planning.kitchen.schedule.Timeline` with its
            plans (``MotionRecord.plan``).
        mode, command: The controller (:data:`~flipkit.simulation.modes.MODES`) and
            position mode's commands, as :func:`~flipkit.simulation.execute.execute_plan`.
        cell: The simulated cell; default the first plan's (``plan.cell()``).
        rate_hz: Joint controller rate (Hz).
        film_fps: Keep a frame every 1/film_fps s of stepped cook time (0: none).
        step_idle: Step the idle intervals instead of skipping them.
        sense_serve: ``sense_serve(motion, xy) -> plan``: the serve of ``motion``
            re-planned for its burger seen at ``xy`` (m) on the grill (module docstring;
            :class:`~flipkit.errors.FlipkitError` for a place it refuses);
            ``None`` (default): every serve runs open loop as planned.
        sense_blade: ``sense_blade(plan, on_blade) -> plan``: during each serve's carry,
            :data:`~flipkit.simulation.cook_blade.SENSE_LEAD_S` before it ends, place and
            return home re-planned for where the camera sees the burger on the blade
            (:func:`~flipkit.planning.planners.serve.replan_serve`;
            :mod:`flipkit.simulation.cook_blade`); ``None`` (default): none.
        sensing_sigma: The camera's error (m, per axis). seed: Seed of its draws.

    Raises:
        CookNotSimulatedError: A failed schedule or one without plans.
        InvalidChoiceError: Unknown mode or command.
    """
    started = time.perf_counter()
    motions = _check(timeline, mode, command)
    cell = cell or motions[0].plan.cell()
    robot = Robot(cell, with_burger=False)
    records = timeline.burgers
    index = {b.burger.burger: k for k, b in enumerate(records)}
    n = len(records)
    scene = build_scene(robot, cell, burgers=n)
    m, d = scene.model, scene.data
    control = ArmController.of(robot, cell.physics, mode, rate_hz, m.opt.timestep)
    dt = control.substeps * m.opt.timestep
    watches = [Watch(index[mo.burger], mo.kind, mo.start, mo.end + HOLD_S) for mo in motions]
    rec = CookRecorder(scene, watches, dt, film_fps)
    # each patty's strips lie along its flip's scoop (its serve's scoop meets them at an angle)
    heading = {index[mo.burger]: scoop_heading(mo.plan, robot) for mo in motions
               if mo.kind == "flip"}
    events = sorted([(b.burger.t_drop, 0, k) for k, b in enumerate(records)]
                    + [(max(mo.end + timeline.dwell_s, mo.end + HOLD_S), 1, index[mo.burger])
                       for mo in motions if mo.kind == "serve"])

    def apply_events(t: float) -> None:
        while events and events[0][0] <= t + 1e-9:
            _, away, k = events.pop(0)
            if away and n > 1:
                park_burger(scene, k)
                rec.removed(k)
            elif not away:
                b = records[k].burger
                place_burger(scene, (b.x, b.y), burger=k, heading=heading.get(k, 0.0))
                rec.placed(k)

    d.qpos[:ARM_JOINTS] = motions[0].plan.segments[0].q[0]
    d.qvel[:] = 0.0
    mujoco.mj_forward(m, d)
    now = min(b.burger.t_drop for b in records)
    stepped = skipped = 0.0
    speed = {"burger_m_s": 0.0, "arm_rad_s": 0.0}
    refs_of, plans, sensed, sensed_blade = {}, {}, [], []
    rng = np.random.default_rng(seed)
    rng_blade = np.random.default_rng([seed, 1])  # its own draws: the grill's stay as they are
    for i, mo in enumerate(motions):
        if mo.start > now + 1e-9:  # idle: skipped (module docstring)
            _note_speed(scene, rec, speed)
            skipped += mo.start - now
        apply_events(mo.start)
        rec.skipped_to(mo.start)
        nxt = motions[i + 1].start if i + 1 < len(motions) else np.inf
        plan = plans[i] = mo.plan
        if sense_serve is not None and mo.kind == "serve":
            plan = plans[i] = sensed_serve(mo, scene, index[mo.burger], sense_serve,
                                            rng.normal(0.0, sensing_sigma, 2), sensed)
        gap = nxt - mo.end
        hold = gap if step_idle and np.isfinite(gap) else min(max(gap, 0.0), MAX_SETTLE_S)
        refs = plan_references(plan, robot, cell.physics, mode, command, dt, hold)
        refs_of[i] = refs
        d.time = mo.start
        # the serve's end (s into it) and references as they are now: a re-plan on the blade
        # moves the one and replaces the other
        now_run = {"end": plan.duration, "refs": refs, "sensed": None, "stop": np.inf,
                   "done": mo.kind != "serve" or sense_blade is None}

        def hook(k, refs, mo=mo, i=i, nxt=nxt, run=now_run):
            apply_events(mo.start + refs.t[k])
            if run["sensed"] is not None:  # where the sensed burger lies when the carry stops
                if refs.t[k] >= run["stop"] - 1e-9:
                    body = scene.burger_bodies[index[mo.burger]]
                    at_stop = [round(float(v), 5) for v in scene.in_blade_frame(body)[:2]]
                    run["sensed"]["on_blade_at_stop"] = at_stop
                    run["sensed"]["shift_over_lead_m"] = round(float(np.hypot(*np.subtract(
                        at_stop, run["sensed"]["on_blade_true"]))), 5)
                    run["sensed"] = None
                return None
            if run["done"]:
                return None
            carry = refs.bounds[SERVE.step(SERVE.sensed).name]
            if refs.t[k] < sense_time(carry) - 1e-9:
                return None
            run["done"], run["stop"] = True, max(carry[1], refs.t[k])
            new_refs, new, note = blade_replan(
                scene, index[mo.burger], plans[i], sense_blade,
                rng_blade.normal(0.0, sensing_sigma, 2),
                t_now=refs.t[k], t_stop=run["stop"], start=mo.start, next_start=nxt, dt=dt,
                references={"robot": robot, "physics": cell.physics, "mode": mode,
                            "command": command, "hold_max": MAX_SETTLE_S})
            note = {"serve": mo.burger, **note}
            sensed_blade.append(note)
            run["sensed"] = note
            if new_refs is None:
                return None
            plans[i], refs_of[i], run["refs"] = new, new_refs, new_refs
            run["end"] = max(b[1] for b in new_refs.bounds.values())
            watches[i].t1 = max(watches[i].t1, mo.start + run["end"] + HOLD_S)
            return new_refs

        def stop(k, refs, mo=mo, nxt=nxt, run=now_run):
            if mo.start + (k + 1) * dt > nxt + 1e-9:  # the next motion starts
                return True
            return (not step_idle and refs.t[k] >= run["end"] + HOLD_S - 1e-9
                    and _at_rest(scene, rec.active))

        def record(k, q, u, mo=mo, run=now_run):
            rec.sample(mo.start + run["refs"].t[k], mo.key)

        _, steps = step_references(scene, control, refs, record, hook, stop)
        stepped += steps * dt
        now = mo.start + steps * dt
    results, all_runs = [], {}
    for k, b in enumerate(records):
        runs = {}
        for i, (mo, w) in enumerate(zip(motions, watches)):
            if w.burger == k:
                runs[mo.kind] = (plans[i], w.run(scene, mo.start), refs_of[i].bounds, mo.start)
                all_runs[(mo.burger, mo.kind)] = runs[mo.kind][1]
        results.append(judge_burger(b, runs.get("flip"), runs.get("serve"), cell.table,
                                    rec.knocked_m[k], rec.contact_s[k]))
    return CookSimulation(results, mode, command, rec.min_distance_m, stepped, skipped, speed,
                          time.perf_counter() - started, rec.frames, scene, all_runs, sensed,
                          sensed_blade)


def sensed_serve(mo, scene: Scene, k: int, sense_serve, error, sensed: list):
    """The serve plan to run for motion ``mo``: re-planned for burger ``k`` where the camera
    sees it (true place + ``error``), if verified and no longer than the serve's slot in the
    schedule (its start to its end)."""
    true_xy = np.array(scene.data.qpos[scene.qpos_of(k)][:2], float)
    xy = true_xy + np.asarray(error, float)
    t0 = time.perf_counter()
    try:
        new = sense_serve(mo, xy)
        why = _unusable(new, mo.end - mo.start)
    except FlipkitError as exc:  # a place the planner refuses, with its reason
        new, why = None, f"the re-plan was refused: {exc}"
    wall = time.perf_counter() - t0
    sensed.append({"burger": mo.burger, "true_xy": [round(float(v), 5) for v in true_xy],
                   "sensed_xy": [round(float(v), 5) for v in xy],
                   "planned_xy": [round(float(v), 5) for v in mo.plan.burger["location"][:2]],
                   "replanned": why is None, "why": why, "wall_s": round(wall, 3)})
    return mo.plan if why is not None else new


def _unusable(new, T_old: float) -> str | None:
    """Why the re-planned serve ``new`` cannot replace one of ``T_old`` s, or ``None``."""
    if new is None or new.status != "solved":
        reason = getattr(new, "failure", None)
        return "the re-plan failed" + (f": {reason}" if reason else "")
    if new.duration > T_old + 1e-9:
        return "the re-plan is longer than the scheduled serve"
    return None


def _at_rest(scene: Scene, active: np.ndarray) -> bool:
    """Every placed burger slower than :data:`REST_SPEED` (m/s), every arm joint too (rad/s)."""
    d = scene.data
    if np.abs(d.qvel[:ARM_JOINTS]).max() >= REST_SPEED:
        return False
    return all(np.linalg.norm(d.qvel[scene.qvel_of(k)][:3]) < REST_SPEED
               for k in np.flatnonzero(active))


def _note_speed(scene: Scene, rec: CookRecorder, speed: dict) -> None:
    """Keep the largest burger (m/s) and arm joint (rad/s) speeds seen at a skip."""
    d = scene.data
    speed["arm_rad_s"] = max(speed["arm_rad_s"], float(np.abs(d.qvel[:ARM_JOINTS]).max()))
    for k in np.flatnonzero(rec.active):
        speed["burger_m_s"] = max(speed["burger_m_s"],
                                  float(np.linalg.norm(d.qvel[scene.qvel_of(k)][:3])))


__all__ = ["MAX_SETTLE_S", "REST_SPEED", "SENSING_SIGMA", "sensed_serve", "CookNotSimulatedError", "CookSimulation",
           "simulate_cook"]
