"""A burger at rest sleeps; the records keep its contacts, the blade wakes it, and so does
moving it (place, park) in a scene of several burgers."""

import mujoco
import numpy as np
import pytest

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot
from flipkit.simulation.scene import ARM_JOINTS, build_scene, place_burger
from flipkit.simulation.trace import BurgerTrace

G = 9.81


@pytest.fixture(scope="module")
def bare():
    return Robot(CellConfig(), with_burger=False)


def _hold_arm(scene, q):
    """Step once with the arm held at q by its gravity torque (it never sleeps: driven)."""
    d = scene.data
    d.qpos[:ARM_JOINTS], d.qvel[:ARM_JOINTS] = q, 0.0
    mujoco.mj_forward(scene.model, d)
    d.qfrc_applied[:ARM_JOINTS] = d.qfrc_bias[:ARM_JOINTS]
    mujoco.mj_step(scene.model, d)


def _raised(robot, q, dz):
    """q moved so that the spatula frame rises by dz (m), its x and y kept (finite-difference
    Jacobian, least squares)."""
    p0 = robot.placement(q).translation
    J = np.column_stack([(robot.placement(q + 1e-6 * e).translation - p0) / 1e-6
                         for e in np.eye(len(q))])
    return q + np.linalg.lstsq(J, [0.0, 0.0, dz], rcond=None)[0]


def _rest(bare, sleep, steps=400, xy=(0.7, -0.1)):
    cell = bare.cell
    scene = build_scene(bare, cell, sleep=sleep)
    place_burger(scene, xy, q=cell.robot.q_home)
    trace = BurgerTrace(scene, steps)
    awake = np.zeros(steps, bool)
    for k in range(steps):
        _hold_arm(scene, cell.robot.q_home)
        trace(k)
        awake[k] = scene.data.body_awake[scene.burger_bodies[0]]
    return scene, trace, awake


def test_a_burger_at_rest_sleeps_and_its_record_keeps_lying_on_the_grill(bare):
    scene, trace, awake = _rest(bare, sleep=True)
    d, weight = scene.data, bare.cell.burger.mass * G
    assert scene.sleeps and awake[0] and not awake[-1]  # it fell asleep
    assert scene.data.body_awake[1]  # the arm did not
    own = set(scene.burger_geoms[0])
    assert not any(a in own or b in own for a, b, _ in scene.contacts())  # MuJoCo skips it
    asleep = ~awake
    assert asleep.sum() > 300
    assert trace.tg[asleep].all() and not trace.ts.any()  # still on the grill, off the blade
    assert trace.fg[asleep] == pytest.approx(weight, rel=0.05)  # it still weighs on it
    # ... as the same burger does in a scene that never sleeps
    _, plain, always = _rest(bare, sleep=False)
    assert always.all() and plain.tg[1:].all()  # (placed touching: contacts from step 1)
    assert trace.fg[-1] == pytest.approx(plain.fg[-1], rel=0.05)
    assert np.abs(trace.bp[-1] - plain.bp[-1]).max() < 1e-4


def test_the_blade_wakes_a_sleeping_burger(bare, flip_plan):
    """The arm put where the scoop ends (the blade flat under the burger's middle) meets the
    sleeping burger: MuJoCo wakes it, and the blade lifts it."""
    p_b = np.asarray(flip_plan.burger["location"], float)
    scene, _, awake = _rest(bare, sleep=True, steps=100, xy=p_b[:2])
    d, root = scene.data, scene.burger_bodies[0]
    assert not awake[-1]
    before = d.xpos[root].copy()
    q_under = _raised(bare, flip_plan.segment("scoop").q[-1], 0.004)  # into the burger's bottom
    _hold_arm(scene, q_under)
    assert d.body_awake[root], "the blade went through a sleeping burger"
    for _ in range(50):
        _hold_arm(scene, q_under)
    assert d.xpos[root][2] - before[2] > 2e-4  # simulated again: the blade lifted it


def test_moving_a_sleeping_burger_wakes_it(bare):
    """In a scene of two burgers (the cook's), a burger asleep on the grill is put elsewhere,
    3 cm up, and another is parked asleep and then placed: each wakes, falls and lies where it
    was put, and the cook's record keeps a sleeping burger's grill contact."""
    from flipkit.simulation.cook_record import CookRecorder
    from flipkit.simulation.scene import park_burger

    scene = build_scene(bare, burgers=2)
    assert scene.sleeps and not build_scene(bare, burgers=2, sleep=False).sleeps
    d, (b0, b1) = scene.data, scene.burger_bodies
    place_burger(scene, (0.70, -0.10), q=bare.cell.robot.q_home, burger=0)
    rec = CookRecorder(scene, [], dt=scene.model.opt.timestep)
    for _ in range(300):
        _hold_arm(scene, bare.cell.robot.q_home)
        flags = rec._contacts()  # as rec.sample does at every step
    assert not d.body_awake[b0] and not d.body_awake[b1]  # on the grill, and parked
    own = set(scene.burger_geoms[0])
    assert not any(a in own or b in own for a, b, _ in scene.contacts())  # MuJoCo skips it
    assert flags[0][1] and flags[0][3] > 0  # the record still has it on the grill
    place_burger(scene, (0.78, 0.05), burger=0, height=bare.cell.grill.height + 0.03)
    place_burger(scene, (0.65, -0.30), burger=1)
    assert d.body_awake[b0] and d.body_awake[b1]
    for _ in range(400):
        _hold_arm(scene, bare.cell.robot.q_home)
    rest = bare.cell.grill.height + bare.cell.burger.thickness / 2
    np.testing.assert_allclose(d.xpos[b0], [0.78, 0.05, rest], atol=2e-3)  # fell 3 cm
    np.testing.assert_allclose(d.xpos[b1], [0.65, -0.30, rest], atol=2e-3)
    park_burger(scene, 1)
    assert d.body_awake[b1]
