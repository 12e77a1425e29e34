"""The simulated patty bends: hinged strips with the bending stiffness of the sourced modulus."""

from dataclasses import replace

import mujoco
import numpy as np
import pytest

from flipkit.config import CellConfig, PhysicsConfig
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot
from flipkit.simulation import patty
from flipkit.simulation.scene import build_scene, park_burger, place_burger

G = 9.81


def _cell(n: int = 5, **physics) -> CellConfig:
    cell = CellConfig()
    return replace(cell, physics=replace(cell.physics, burger_strips=n, **physics))


@pytest.fixture(scope="module")
def bare():
    return Robot(CellConfig(), with_burger=False)


def test_strips_share_the_mass_and_tile_the_disc():
    cell = _cell(5)
    ss = patty.strips(cell)
    assert [s.index for s in ss] == list(range(5))
    assert sum(s.mass for s in ss) == pytest.approx(cell.burger.mass, rel=1e-12)
    assert ss[0].x0 == pytest.approx(-0.05) and ss[-1].x1 == pytest.approx(0.05)
    assert all(a.x1 == pytest.approx(b.x0) for a, b in zip(ss, ss[1:]))
    assert ss[2].hinge_x is None and ss[2].stiffness == 0.0  # the root
    # symmetric about the middle, and the middle strip (the widest) is the heaviest
    assert ss[0].mass == pytest.approx(ss[4].mass, rel=1e-9)
    assert ss[2].mass > ss[1].mass > ss[0].mass
    # k = E c h^3 / (12 a), c the chord at the hinge, a = d / n
    r, h, a = 0.05, cell.burger.thickness, 0.1 / 5
    chord = 2 * np.sqrt(r**2 - 0.01**2)
    assert ss[3].hinge_x == pytest.approx(0.01)
    assert ss[3].stiffness == pytest.approx(cell.physics.burger_modulus * chord * h**3 / 12 / a)
    stiffer = patty.strips(_cell(5, burger_modulus=100e3))
    assert stiffer[3].stiffness == pytest.approx(2 * ss[3].stiffness)


def test_strip_vertices_lie_in_their_slab_and_on_the_disc():
    v = patty.strip_vertices(0.05, 0.015, 0.005, 0.01, 0.03)
    assert v[:, 0].min() == pytest.approx(0.01) and v[:, 0].max() == pytest.approx(0.03)
    assert np.all(np.hypot(v[:, 0], v[:, 1]) <= 0.05 + 1e-12)
    assert np.all(np.abs(v[:, 2]) <= 0.0075 + 1e-12)


@pytest.mark.parametrize("n", [0, 2, 4, -1, 2.0, True])
def test_strip_count_must_be_odd_and_positive(n):
    with pytest.raises(ConfigError, match="odd integer"):
        PhysicsConfig(burger_strips=n)


def _sagged_chain(cell, bare):
    """Hinge angles (rad) of a patty held up in the air by a force on its middle strip equal
    to its whole weight (the symmetric chains hang from it), at rest under gravity."""
    scene = build_scene(bare, cell)
    m, d = scene.model, scene.data
    place_burger(scene, (0.2, 0.6), q=cell.robot.q_home)  # away from the arm and the table
    d.qpos[scene.qpos_of(0).start + 2] += 0.3
    d.xfrc_applied[scene.burger_bodies[0], 2] = cell.burger.mass * G
    qa, _ = scene.hinges_of(0)
    for _ in range(8000):  # 4 s: the hinges are critically damped, periods of tens of ms
        d.qpos[:6], d.qvel[:6] = cell.robot.q_home, 0.0
        mujoco.mj_step(m, d)
    assert d.ncon == 0
    return d.qpos[qa].copy(), scene


def test_the_held_patty_sags_as_its_hinges_say(bare):
    """Each hinge turns by the moment of the strips beyond it over its stiffness (small
    angles), and the rim droops as a cantilever of the disc's varying width would."""
    cell = _cell(5)
    angles, scene = _sagged_chain(cell, bare)
    ss = patty.strips(cell)
    by_index = {s.index: s for s in ss}
    # scene.hinges_of lists the strips in body order: the +x chain (3, 4), then the -x (1, 0)
    order = [3, 4, 1, 0]
    for angle, j in zip(angles, order):
        s = by_index[j]
        out = [by_index[i] for i in (range(j, 5) if j > 2 else range(0, j + 1))]
        moment = sum(o.mass * G * (o.com[0] - s.hinge_x) for o in out)
        # a strip beyond +x hangs down: it turns about +y by a positive angle (z x x = +y)
        assert angle == pytest.approx(moment / s.stiffness, rel=0.03)
    # the rim droops by a few millimetres: far more than the blade is thick (1 mm)
    droop = sum(angles[k] * (0.05 - by_index[j].hinge_x) for k, j in enumerate(order[:2]))
    assert 0.002 < droop < 0.02
    # the continuous beam of width c(x) = 2 sqrt(r^2 - x^2) held level at its middle, x = 0
    r, h, E = 0.05, cell.burger.thickness, cell.physics.burger_modulus
    x = np.linspace(0.0, r, 4001)
    c = 2 * np.sqrt(np.maximum(r**2 - x**2, 0))
    q = cell.burger.mass / (np.pi * r**2) * G * c  # weight per length (N/m)
    shear = np.array([np.trapezoid(q[i:], x[i:]) for i in range(len(x))])
    moment = np.array([np.trapezoid(shear[i:], x[i:]) for i in range(len(x))])
    curvature = moment / (E * np.maximum(c, 1e-3) * h**3 / 12)
    slope = np.concatenate([[0], np.cumsum((curvature[1:] + curvature[:-1]) / 2 * np.diff(x))])
    tip = np.trapezoid(slope, x)
    assert droop == pytest.approx(tip, rel=0.15)  # 4.5 mm against 4.9 mm


def test_a_patty_of_strips_lies_flat_on_the_grill(bare):
    cell = _cell(5)
    scene = build_scene(bare, cell)
    m, d = scene.model, scene.data
    place_burger(scene, (0.7, -0.1), q=cell.robot.q_home, heading=0.4)
    for _ in range(1000):
        mujoco.mj_step(m, d)
        d.qpos[:6], d.qvel[:6] = cell.robot.q_home, 0.0
    qa, _ = scene.hinges_of(0)
    assert np.abs(d.qpos[qa]).max() < 2e-3
    root = d.qpos[scene.qpos_of(0)]
    assert root[2] == pytest.approx(scene.grill_height + cell.burger.thickness / 2, abs=5e-4)
    yaw = 2 * np.arctan2(root[6], root[3])
    assert yaw == pytest.approx(0.4, abs=1e-3)  # laid along the given heading
    assert len(scene.burger_geoms[0]) == 5 and scene.geoms["burger"] in scene.burger_geoms[0]


def test_a_rigid_patty_is_the_disc_and_keeps_yaw_zero(bare):
    cell = _cell(1)
    scene = build_scene(bare, cell)
    place_burger(scene, (0.7, -0.1), heading=0.4)
    flex = int(scene.blade_contact["flex"] == "hinge")  # the flexing blade's hinge
    assert scene.model.nq == 6 + flex + 7
    assert scene.burger_geoms == ((scene.geoms["burger"],),)
    assert np.allclose(scene.data.qpos[scene.qpos_of(0)][3:], (1, 0, 0, 0))


def test_several_patties_park_and_place_with_their_strips(bare):
    cell = _cell(5)
    scene = build_scene(bare, cell, burgers=3)
    m, d = scene.model, scene.data
    assert m.nq == 6 + 1 + 3 * (7 + 4)  # the arm, the flexing blade's hinge, three patties
    place_burger(scene, (0.7, 0.1), burger=1, heading=0.2)
    assert np.all(m.body_gravcomp[scene.patty_bodies(1)] == 0.0)
    assert np.all(m.body_gravcomp[scene.patty_bodies(0)] == 1.0)  # still parked
    assert np.allclose(d.qpos[scene.qpos_of(1)][:2], (0.7, 0.1))
    qa, _ = scene.hinges_of(1)
    d.qpos[qa] = 0.1
    park_burger(scene, 1)
    assert np.all(m.body_gravcomp[scene.patty_bodies(1)] == 1.0)
    assert np.all(d.qpos[qa] == 0.0)
    assert d.qpos[scene.qpos_of(1)][2] < -1.0


def test_scoop_heading_is_the_blade_yaw_at_the_end_of_the_scoop(bare):
    class Seg:
        def __init__(self, name, q):
            self.name, self.q = name, q

    q = np.array(CellConfig().robot.q_home)
    R = bare.rotation(q)

    class P:
        segments = [Seg("go_to_burger", [q * 0, q * 0]), Seg("scoop", [q * 0, q])]

    assert patty.scoop_heading(P, bare) == pytest.approx(np.arctan2(R[1, 0], R[0, 0]))

    class NoScoop:
        segments = [Seg("translate", [q])]

    assert patty.scoop_heading(NoScoop, bare) == 0.0
