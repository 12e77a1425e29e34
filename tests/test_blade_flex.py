"""The flexing blade (``physics.blade_flex = "hinge"``, flipkit.simulation.scene "Blade flex"):
the arm's dynamics with the hinge at rest are the planner's, and a blade pressed into the grill
stays on its surface and bends by the cantilever's stiffness (the moment of the grill's push
about the hinge is the spring's), where the rigid blade of the default model sinks into it."""

from dataclasses import replace

import mujoco
import numpy as np
import pytest

from flipkit.config import CellConfig
from flipkit.config.physics import PhysicsConfig
from flipkit.errors import InvalidChoiceError
from flipkit.model.robot import Robot
from flipkit.simulation.execute import execute_plan
from flipkit.simulation.scene import build_scene, hinge_flex

from test_execute import held

CELL = CellConfig()
HINGE = replace(CELL, physics=replace(CELL.physics, blade_flex="hinge"))


def test_an_unknown_flex_model_is_refused_with_the_choices():
    with pytest.raises(InvalidChoiceError, match="'contact', 'hinge'"):
        PhysicsConfig(blade_flex="spring")


def test_the_arm_with_the_hinge_at_rest_has_the_planner_s_dynamics():
    robot = Robot(HINGE, with_burger=False)
    scene = build_scene(robot, HINGE)
    m, d = scene.model, scene.data
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "blade_flex")
    assert m.jnt_qposadr[j] == 6 and m.jnt_stiffness[j] == pytest.approx(
        hinge_flex(HINGE)["stiffness"])
    rng = np.random.default_rng(4)
    for _ in range(5):
        q = robot.q_home + rng.uniform(-0.6, 0.6, 6)
        qd, qdd = rng.uniform(-1.5, 1.5, 6), rng.uniform(-3, 3, 6)
        m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT  # the arm alone
        d.qpos[:] = m.qpos0
        d.qpos[:6], d.qvel[:], d.qacc[:] = q, 0.0, 0.0
        d.qvel[:6], d.qacc[:6] = qd, qdd
        mujoco.mj_inverse(m, d)
        assert np.allclose(d.qfrc_inverse[:6], robot.inverse_dynamics(q, qd, qdd), atol=1e-8)


def _hinge_moment(scene) -> tuple[float, float]:
    """The moment (N m) about the hinge axis of the blade-grill contact forces on the blade and
    of the blade body's weight, and the spring's κ θ."""
    m, d, g = scene.model, scene.data, scene.geoms
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "blade_flex")
    anchor, axis = d.xanchor[j], d.xaxis[j]
    moment, f6 = 0.0, np.zeros(6)
    for i in range(d.ncon):
        con = d.contact[i]
        if set(con.geom) != {g["blade"], g["grill"]}:
            continue
        mujoco.mj_contactForce(m, d, i, f6)
        force = con.frame.reshape(3, 3).T @ f6[:3]  # on geom2, along the normal from geom1
        on_blade = -force if con.geom[0] == g["blade"] else force
        moment += np.cross(con.pos - anchor, on_blade) @ axis
    body = m.jnt_bodyid[j]
    weight = m.body_mass[body] * m.opt.gravity
    moment += np.cross(d.xipos[body] - anchor, weight) @ axis
    return moment, m.jnt_stiffness[j] * d.qpos[m.jnt_qposadr[j]]


def test_a_pressed_flexing_blade_stays_on_the_grill_and_bends_by_its_stiffness(flip_plan):
    """The scoop's first configuration held, the tip commanded 3 mm into the grill. The run
    starts with the blade already 3 mm in (its first step's push is 426 N): the arm's safety
    system is off, as this is the blade's physics alone."""
    plan = held(flip_plan, flip_plan.segment("scoop").q[0])
    ex = execute_plan(plan, "feedforward", draw={"dx_m": 0.2}, hold=0.0, cell=HINGE,
                      safety_stop=False)
    late, end = ex.run.t > 0.5, ex.run.t > ex.run.t[-1] - 0.5
    force = ex.force_blade_grill
    assert np.mean(force[late] > 0) >= 0.95  # on the grill (the holds change at segment ends)
    assert np.ptp(force[end]) < 0.01 * force[end].mean()  # and at rest at the end
    moment, spring = _hinge_moment(ex.scene)
    assert moment == pytest.approx(spring, rel=0.02)  # the spring holds the push
    k = HINGE.physics.blade_stiffness(HINGE.spatula)
    assert 0.2 * k * 0.003 < force[-1] <= 1.05 * k * 0.003  # the flex's force, the arm yields
    d, g = ex.scene.data, ex.scene.geoms
    sink = max(-d.contact[i].dist for i in range(d.ncon)
               if set(d.contact[i].geom) == {g["blade"], g["grill"]})
    assert sink < 1e-4  # steel on steel: the blade stays on the surface
    rigid = execute_plan(plan, "feedforward", draw={"dx_m": 0.2}, hold=0.0, safety_stop=False,
                         physics=replace(HINGE.physics, blade_flex="contact"))
    d, g = rigid.scene.data, rigid.scene.geoms
    assert max(-d.contact[i].dist for i in range(d.ncon)
               if set(d.contact[i].geom) == {g["blade"], g["grill"]}) > 1e-3  # it sinks


def test_the_tip_deflects_by_the_cantilever_s_stiffness():
    """A 2 N push on the tip along the blade's normal, gravity and contacts off, the arm held:
    the tip moves 2 N / k (k = 3 E I / L³, :meth:`PhysicsConfig.blade_stiffness`)."""
    robot = Robot(HINGE, with_burger=False)
    scene = build_scene(robot, HINGE)
    m, d = scene.model, scene.data
    m.opt.gravity[:] = 0.0
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    m.dof_armature[:6] = 1e9  # the arm held still: the push cannot accelerate it
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "blade_flex")
    body, length = m.jnt_bodyid[j], HINGE.spatula.length
    d.qpos[:6] = robot.q_home
    mujoco.mj_forward(m, d)
    push = 2.0
    for _ in range(4000):  # 2 s: the hinge settles (critically damped, about 19 Hz)
        R = d.site_xmat[scene.blade_site].reshape(3, 3)
        tip = d.site_xpos[scene.blade_site] + R[:, 0] * length / 2
        d.qfrc_applied[:] = 0.0
        mujoco.mj_applyFT(m, d, push * R[:, 2], np.zeros(3), tip, body, d.qfrc_applied)
        mujoco.mj_step(m, d)
    theta = d.qpos[m.jnt_qposadr[j]]
    k = HINGE.physics.blade_stiffness(HINGE.spatula)
    assert abs(theta) * length == pytest.approx(push / k, rel=0.01)
