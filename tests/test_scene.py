"""The MuJoCo cell mirrors the pinocchio arm: same inverse dynamics, same spatula frame."""

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from flipkit.config import CellConfig
from flipkit.model.robot import Robot
from flipkit.simulation.scene import ARM_JOINTS, blade_vertices, build_scene, place_burger

from conftest import random_states


@pytest.fixture(scope="module")
def bare():
    return Robot(CellConfig(), with_burger=False)


@pytest.fixture(scope="module")
def scene(bare):
    return build_scene(bare)


def _blade_world(scene):
    """World coordinates of the blade mesh vertices (MuJoCo recentres meshes)."""
    m, d, g = scene.model, scene.data, scene.geoms["blade"]
    adr, n = m.mesh_vertadr[m.geom_dataid[g]], m.mesh_vertnum[m.geom_dataid[g]]
    local = m.mesh_vert[adr:adr + n]
    return d.geom_xpos[g] + local @ d.geom_xmat[g].reshape(3, 3).T


def test_inverse_dynamics_matches_pinocchio(bare):
    scene = build_scene(bare, grill_offset=-2.0)  # out of the blade's reach: no contact
    m, d = scene.model, scene.data
    place_burger(scene, (0.74, -0.17))
    d.qpos[ARM_JOINTS + 2] += 0.5  # burger held in the air: no contact at all
    for q, qd, qdd in random_states(bare, seed=7, n=6):
        d.qpos[:ARM_JOINTS], d.qvel[:ARM_JOINTS], d.qacc[:ARM_JOINTS] = q, qd, qdd
        d.qvel[ARM_JOINTS:], d.qacc[ARM_JOINTS:] = 0, 0
        mujoco.mj_inverse(m, d)
        tau = pin.rnea(bare.model, bare.data, q, qd, qdd)
        assert d.ncon == 0
        np.testing.assert_allclose(d.qfrc_inverse[:ARM_JOINTS], tau, rtol=1e-6,
                                   atol=1e-6 * np.abs(tau).max())


def test_mass_matrix_includes_spatula(bare, scene):
    """The spatula payload is in the last body: a scene from a payload-free arm would differ."""
    m, d = scene.model, scene.data
    q = bare.q_home
    d.qpos[:ARM_JOINTS] = q
    mujoco.mj_forward(m, d)
    M, col = np.zeros((m.nv, m.nv)), np.zeros(m.nv)
    for i, e in enumerate(np.eye(m.nv)):
        mujoco.mj_mulM(m, d, col, e)
        M[:, i] = col
    np.testing.assert_allclose(M[:6, :6], pin.crba(bare.model, bare.data, q), atol=1e-9)
    last = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, bare.model.names[6])
    urdf_mass = pin.buildModelFromUrdf(bare.urdf).inertias[6].mass
    # the default blade flexes on a hinge at its neck: the spatula's mass is the blade body's
    blade = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "blade_flex")
    assert m.body_mass[last] == pytest.approx(urdf_mass)
    assert m.body_mass[blade] == pytest.approx(bare.cell.spatula.mass)
    assert m.body_mass[last] + m.body_mass[blade] == pytest.approx(bare.model.inertias[6].mass)


def test_blade_top_face_and_tip(bare, scene):
    sp, ph = bare.cell.spatula, bare.cell.physics
    rng = np.random.default_rng(3)
    for _ in range(4):
        q = bare.q_home + rng.uniform(-0.5, 0.5, 6)
        scene.data.qpos[:ARM_JOINTS] = q
        mujoco.mj_kinematics(scene.model, scene.data)
        M = bare.placement(q)
        p, R = scene.blade_pose()
        np.testing.assert_allclose(p, M.translation, atol=1e-9)
        np.testing.assert_allclose(R, M.rotation, atol=1e-9)
        local = (_blade_world(scene) - M.translation) @ M.rotation
        assert local[:, 2].max() == pytest.approx(0.0, abs=1e-9)  # top face = xy-plane
        assert local[:, 2].min() == pytest.approx(-ph.blade_thickness, abs=1e-9)
        tip = local[np.isclose(local[:, 0], sp.length / 2, atol=1e-9)]
        top_tip = tip[np.isclose(tip[:, 2], 0.0, atol=1e-9)].mean(axis=0)
        np.testing.assert_allclose(M.act(top_tip), M.act(np.array([sp.length / 2, 0, 0])),
                                   atol=1e-9)
        assert tip[:, 2].min() == pytest.approx(-ph.edge_thickness, abs=1e-9)  # bevelled edge


def test_blade_vertices_bevel():
    v = blade_vertices(0.16, 0.12, 0.001, 0.005, 0.0002)
    under = v[v[:, 2] < 0]
    assert under[:, 2].min() == -0.001 and under[under[:, 0] == 0.08][:, 2].max() == -0.0002
    assert set(np.round(under[under[:, 2] == -0.001][:, 0], 6)) == {-0.08, 0.075}


def test_grill_offset_moves_surface(bare):
    s = build_scene(bare, grill_offset=0.002)
    g = s.geoms["grill"]
    top = s.data.geom_xpos[g][2] + s.model.geom_size[g][2]
    assert top == pytest.approx(bare.cell.grill.height + 0.002)
    assert s.grill_height == pytest.approx(top)
