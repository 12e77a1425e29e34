"""Closed-loop execution in the MuJoCo cell: contact reaches the arm, modes differ, inputs
are checked."""

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

from flipkit.simulation.judges import SCOOP_OVERLAP, judge_scoop
from flipkit.config import PhysicsConfig
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.simulation import execute
from flipkit.simulation.execute import HOLD_S, MODES, SETTLED_WINDOW, execute_plan


def held(plan, q, burger_dx=0.0):
    """``plan`` with every segment holding the configuration q at rest (gravity torques)."""
    segs = []
    for seg in plan.segments:
        robot = plan.robot_for(seg.name)
        n = seg.t.size
        g = pin.computeGeneralizedGravity(robot.model, robot.data, np.asarray(q, float))
        segs.append(replace(seg, q=np.tile(q, (n, 1)), qd=np.zeros((n, 6)),
                            qdd=np.zeros((n, 6)), u=np.tile(g, (n, 1))))
    return replace(plan, segments=segs)


@pytest.fixture(scope="module")
def feedforward(flip_plan):
    return execute_plan(flip_plan, "feedforward")


def test_motionless_arm_never_scoops(flip_plan):
    plan = held(flip_plan, flip_plan.segments[0].q[0])
    ex = execute_plan(plan, "feedforward", hold=0.0)
    verdict = judge_scoop(ex.run, ex.bounds["scoop"])
    assert not verdict.ok and verdict.overlap < SCOOP_OVERLAP
    moved = np.linalg.norm(ex.run.burger_pos[-1, :2] - ex.run.burger_pos[0, :2])
    assert moved < 1e-3  # nobody touched it
    assert max(e["max_m"] for e in ex.errors.values()) < 1e-3  # holding still


# the rigid blade whose press the grill's compliant contact absorbs (not the default's hinge)
CONTACT = PhysicsConfig(blade_flex="contact")


def test_blade_pressed_into_grill_pushes_back_and_arm_tracks(flip_plan):
    """q_home holds the blade flat and level; the grill is raised so that the planned blade
    underside is 2 mm below its surface."""
    cell = flip_plan.cell()
    plan = held(flip_plan, cell.robot.q_home)
    from flipkit.model.robot import Robot

    top = Robot(cell).placement(cell.robot.q_home).translation[2]
    bottom = top - cell.physics.blade_thickness
    offset = bottom + 0.002 - cell.grill.height
    ex = execute_plan(plan, "feedforward", draw={"grill_offset_m": offset, "dx_m": 0.15},
                      hold=0.0, physics=CONTACT, safety_stop=False)
    late = ex.run.t > ex.run.t[-1] - 0.5
    force = ex.force_blade_grill[late]
    assert force.min() > 1.0  # the grill pushes the blade up the whole time (N)
    robot = ex.scene.robot
    err = np.array([np.linalg.norm(robot.placement(a).translation
                                   - robot.placement(b).translation)
                    for a, b in zip(ex.q[late], ex.q_des[late])])
    assert 1e-4 < err.max() < 0.004  # pushed off the plan by the grill, within a few mm
    assert ex.run.spatula_pos[late, 2].min() > top  # lifted above the plan: it cannot sink


def test_feedforward_tracks_closely_without_contact(flip_plan):
    ex = execute_plan(flip_plan, "feedforward", draw={"grill_offset_m": -1.0}, hold=0.2)
    assert max(e["max_m"] for e in ex.errors.values()) < 0.003
    assert not ex.run.touch_spatula.any() and ex.force_blade_grill.max() == 0.0


def test_position_mode_lags_feedforward(flip_plan, feedforward):
    """Sent the plan's (q, q̇) as they are, the position servo lags; the more so, the later
    they arrive."""
    pos = execute_plan(flip_plan, "position", hold=0.0, command="raw")
    for seg in ("go_to_burger", "flip"):
        assert pos.errors[seg]["max_m"] > feedforward.errors[seg]["max_m"] + 0.005
    cell = flip_plan.cell()
    slower = execute_plan(flip_plan, "position", physics=replace(cell.physics, latency_s=0.030),
                          hold=0.0, command="raw")
    assert slower.errors["go_to_burger"]["max_m"] > pos.errors["go_to_burger"]["max_m"] + 0.005


def test_run_layout_and_determinism(flip_plan, feedforward):
    ex = feedforward
    run = ex.run
    T = sum(s.T for s in flip_plan.segments)
    # the flipped burger settles within the hold, and the run ends a window after it did
    assert run.t[0] == 0.0 and T + SETTLED_WINDOW - 2e-3 <= run.t[-1] < T + HOLD_S - 0.1
    assert list(ex.bounds) == [s.name for s in flip_plan.segments]
    assert ex.bounds["turn_back"][1] == pytest.approx(T)
    assert run.spatula_pos.shape == (run.t.size, 3) and ex.qpos.shape[0] == run.t.size
    assert np.all(np.abs(ex.u) <= ex.scene.robot.u_max + 1e-9)
    again = execute_plan(flip_plan, "feedforward")
    np.testing.assert_array_equal(again.run.burger_pos, run.burger_pos)


def test_run_ends_once_the_burger_has_settled(flip_plan, feedforward, monkeypatch):
    """Held for the whole hold (a burger never counted as settled), the burger ends where the
    early end left it: within the settled motion, and judged the same."""
    settled_motion = execute.SETTLED_MOTION
    monkeypatch.setattr(execute, "SETTLED_MOTION", 0.0)
    full = execute_plan(flip_plan, "feedforward")
    T = sum(s.T for s in flip_plan.segments)
    assert full.run.t[-1] == pytest.approx(T + HOLD_S, abs=2e-3)
    early = feedforward.run
    assert early.t.size < full.run.t.size
    np.testing.assert_array_equal(full.run.burger_pos[:early.t.size], early.burger_pos)
    moved = np.abs(full.run.burger_pos[-1] - early.burger_pos[-1]).max()
    assert moved < settled_motion
    assert abs(full.run.up_z[-1] - early.up_z[-1]) < 1e-3


def test_perturbation_draw_reaches_the_plant(flip_plan):
    ex = execute_plan(flip_plan, "feedforward", hold=0.0,
                      draw={"dx_m": 0.01, "dy_m": -0.02, "grill_offset_m": 0.001,
                            "mu_factor": 1.1, "mass_factor": 0.9})
    pb = np.asarray(flip_plan.burger["location"])
    np.testing.assert_allclose(ex.run.burger_pos[0, :2], pb[:2] + [0.01, -0.02], atol=1e-9)
    assert ex.run.grill_height == pytest.approx(flip_plan.grill_height + 0.001)
    m = ex.scene.model
    bodies = ex.scene.patty_bodies(0)  # every strip of the patty
    assert m.body_mass[bodies].sum() == pytest.approx(0.9 * flip_plan.burger["mass"])


def test_bad_inputs(flip_plan):
    with pytest.raises(InvalidChoiceError) as exc:
        execute_plan(flip_plan, "torque")
    assert all(repr(m) in str(exc.value) for m in MODES)
    with pytest.raises(ConfigError, match="perturbation keys"):
        execute_plan(flip_plan, draw={"dz_m": 0.1})
    with pytest.raises(ConfigError):
        execute_plan(flip_plan, hold=-1.0)


def test_validate_checks_the_mode_and_records_it(flip_plan_file):
    from flipkit.experiments.trials import Perturbations, run_trial, trial_jobs, validate

    with pytest.raises(InvalidChoiceError, match="'feedforward', 'position'"):
        validate([((0.69, -0.16, 0.072), {}, None)], 1, mode="servo")
    text = flip_plan_file.read_text()
    raw = run_trial(trial_jobs(text, 1, 0, Perturbations(), mode="position")[0])
    assert raw["mode"] == "position" and set(raw["ok"]) == {"scoop", "pickup", "flip"}
    assert raw["command"] == "raw"  # the default: the plan's own (q, q̇), as export writes
    assert raw["safety"]["preset"] == "least_restricted" and raw["safety"]["stop"] is None
    assert 0.5 < raw["safety"]["peaks"]["joint_speed"] <= 1.0
    job = trial_jobs(text, 1, 0, Perturbations(), mode="position", command="compensated")[0]
    out = run_trial(job)
    assert out["command"] == "compensated"
    # compensated commands track within 5 mm once under way (the servo's smoothing lags the
    # go to burger's first step of torque by up to a centimetre), the plan as it is lags
    under_way = ("scoop", "pickup", "flip", "turn_back")
    assert max(out["tracking"][k]["max_m"] for k in under_way) < 0.005
    assert out["tracking"]["go_to_burger"]["max_m"] < 0.015
    assert min(raw["tracking"][k]["max_m"] for k in under_way) > 0.02


def test_pressed_blade_is_the_blades_spring_and_does_not_bounce(flip_plan):
    """The scoop's first configuration held (tip commanded 3 mm into the grill): the blade
    stays on the grill, and the steady force is the blade's stiffness times its flex (the
    penetration), at most k × 3 mm (the arm's PD yields the rest)."""
    scoop = flip_plan.segment("scoop")
    plan = held(flip_plan, scoop.q[0])
    # burger out of the way; the run starts pressed (the safety system would stop its first step)
    ex = execute_plan(plan, "feedforward", draw={"dx_m": 0.2}, hold=0.0, safety_stop=False,
                      physics=CONTACT)
    late = ex.run.t > 0.5
    force = ex.force_blade_grill[late]
    assert np.mean(force > 0) >= 0.95
    k = ex.scene.blade_contact["stiffness"]
    cell = flip_plan.cell()
    assert k == pytest.approx(cell.physics.blade_stiffness(cell.spatula))
    m, d, g = ex.scene.model, ex.scene.data, ex.scene.geoms
    flex = [-d.contact[i].dist for i in range(d.ncon)
            if set(d.contact[i].geom) == {g["blade"], g["grill"]}]
    assert flex, "no blade-grill contact at the end of the press"
    f_end = force[-1]
    assert f_end == pytest.approx(k * np.mean(flex) * len(flex) / 2, rel=0.1)
    assert 0.2 * k * 0.003 < f_end <= 1.05 * k * 0.003
    # no chatter: the force moves less than 5 % of its mean from one control step to the next
    assert np.abs(np.diff(force)).max() < 0.05 * force.mean()
    # steady while the plan's feed-forward torques are the scoop's (the later segments' carry
    # the burger's weight, which this held run does not hold: the press shifts with them)
    t0, t1 = ex.bounds["scoop"]
    scoop_window = ex.force_blade_grill[(ex.run.t > 0.5) & (ex.run.t <= t1)]
    assert np.ptp(scoop_window) < 0.1 * scoop_window.mean()
