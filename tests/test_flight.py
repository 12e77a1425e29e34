"""Release, flight and landing: the closed-form flight model, its derivatives through the
collocation blocks (against central finite differences, seeded), its independent
recomputation in verify, and the landing recorded in a solved flip plan."""

import math

import numpy as np
import pytest
from conftest import central_fd, check_block_jacobian

from flipkit.behaviors.options import R_LAND, SegmentOptions
from flipkit.behaviors.transcribe import transcribe
from flipkit.transcription.layout import Evaluation
from flipkit.config import CellConfig
from flipkit.transcription.constraints.flight import FlightClearance, Landing
from flipkit.errors import ConfigError, UnreachableError
from flipkit.model.flight import TILT_MIN_DEG, predict_landing
from flipkit.behaviors.models import Models
from flipkit.planning.plans.verify import verify_plan
from flipkit.planning.plans.verify_flight import recompute_landing
from scipy.spatial.transform import Rotation

G = (0.0, 0.0, -9.81)


def test_drop_from_rest_lands_below_after_free_fall_time():
    h, hg, z = 0.015, 0.072, 0.3
    out = predict_landing([0.7, -0.1, z - h / 2], np.zeros(3), np.eye(3), np.zeros(3),
                          thickness=h, diameter=0.1, grill_height=hg, gravity=G,
                          target=(0.7, -0.1))
    assert out["time_of_flight"] == pytest.approx(math.sqrt(2 * (z - hg - h / 2) / 9.81), rel=1e-9)
    assert out["offset"] == pytest.approx(0.0, abs=1e-5)
    assert out["tilt_deg"] == pytest.approx(0.0, abs=0.2)


def test_spin_half_turn_in_flight_lands_upside_down_downrange():
    # thrown up at 1 m/s and 0.5 m/s along x, spinning about x: half a turn in the flight time
    h, hg = 0.015, 0.072
    p, v = np.array([0.6, 0.0, 0.2]), np.array([0.5, 0.0, 1.0])
    c0z = p[2] + h / 2
    tf = (1.0 + math.sqrt(1.0 + 2 * 9.81 * (c0z - hg - h / 2))) / 9.81
    w = np.array([math.pi / tf, 0.0, 0.0])
    out = predict_landing(p, v, np.eye(3), w, thickness=h, diameter=0.1, grill_height=hg,
                          gravity=G, target=(0.6, 0.0))
    assert out["time_of_flight"] == pytest.approx(tf, rel=1e-9)
    assert out["tilt_deg"] == pytest.approx(180.0, abs=0.2)
    # the centre starts h/2 above the blade and turns with it: ω × (h/2 ẑ) adds −ω h/2 along y
    assert out["point"][0] == pytest.approx(0.6 + 0.5 * tf, abs=1e-9)
    assert out["point"][1] == pytest.approx(-w[0] * h / 2 * tf, abs=1e-9)


def _thrown_disc(w):
    """A disc (r 5 cm, h 1.5 cm) thrown up at 2 m/s from 0.3 m, flat, spinning at ω (rad/s)."""
    return dict(p=np.array([0.7, 0.0, 0.3]), v=np.array([0.0, 0.0, 2.0]), R=np.eye(3),
                w=np.asarray(w, float), thickness=0.015, diameter=0.1, grill_height=0.072,
                gravity=G)


def _tilt_after_free_flight(w, r, h, tf):
    """Tilt (deg) of the disc's axis from +z after tf s of torque-free rotation from flat,
    integrated from Euler's equations of the body (not the model's closed form)."""
    from scipy.integrate import solve_ivp

    inertia = np.array([(3 * r * r + h * h) / 12] * 2 + [r * r / 2])

    def rhs(_, y):
        R, wb = y[:9].reshape(3, 3), y[9:]
        dR = R @ np.array([[0, -wb[2], wb[1]], [wb[2], 0, -wb[0]], [-wb[1], wb[0], 0]])
        dw = np.cross(inertia * wb, wb) / inertia
        return np.concatenate([dR.ravel(), dw])

    y = solve_ivp(rhs, (0, tf), np.concatenate([np.eye(3).ravel(), w]), rtol=1e-11,
                  atol=1e-12).y[:, -1]
    return math.degrees(math.acos(np.clip(y[8], -1, 1)))


@pytest.mark.parametrize("w", [(6.0, 0.0, 0.6), (-5.7, -3.0, 0.5), (4.0, 2.0, -1.5)])
def test_landing_tilt_follows_the_free_disc_not_the_blade_spin(w):
    """A flip releases the burger spinning partly about its own axis: its axis then turns about
    the angular momentum, not about ω. The model's tilt agrees with Euler's equations of the
    disc, and differs from a rotation about ω by degrees."""
    case = _thrown_disc(w)
    out = predict_landing(**case)
    tf = out["time_of_flight"]
    r, h = case["diameter"] / 2, case["thickness"]
    assert out["tilt_deg"] == pytest.approx(_tilt_after_free_flight(np.array(w), r, h, tf),
                                            abs=1e-3)
    about_w = math.degrees(math.acos(np.clip(
        Rotation.from_rotvec(np.array(w) * tf).apply([0, 0, 1.0])[2], -1, 1)))
    assert abs(out["tilt_deg"] - about_w) > 2.0


def test_landing_tilt_matches_a_free_disc_in_mujoco():
    """The simulator's free disc, thrown with the same ω, ends where the model says."""
    import mujoco

    r, h, m = 0.05, 0.015, 0.113
    it, ia = m * (3 * r * r + h * h) / 12, m * r * r / 2
    model = mujoco.MjModel.from_xml_string(
        f'<mujoco><option timestep="0.0005" gravity="0 0 -9.81" integrator="RK4"/><worldbody>'
        f'<body pos="0 0 1"><freejoint/><inertial pos="0 0 0" mass="{m}" '
        f'diaginertia="{it} {it} {ia}"/><geom type="cylinder" size="{r} {h / 2}" '
        f'contype="0" conaffinity="0"/></body></worldbody></mujoco>')
    data = mujoco.MjData(model)
    w = np.array([-5.7, -3.0, 0.5])
    data.qvel[3:6] = w  # body frame = world at the start (flat)
    case = _thrown_disc(w)
    tf = predict_landing(**case)["time_of_flight"]
    while data.time < tf - 1e-9:
        mujoco.mj_step(model, data)
    z_axis = data.xmat[1].reshape(3, 3)[:, 2]
    simulated = math.degrees(math.acos(np.clip(z_axis[2], -1, 1)))
    assert predict_landing(**case)["tilt_deg"] == pytest.approx(simulated, abs=0.1)


def test_flight_model_rejects_sideways_gravity():
    with pytest.raises(ConfigError, match="gravity along -z"):
        predict_landing(np.zeros(3), np.zeros(3), np.eye(3), np.zeros(3), thickness=0.01,
                        diameter=0.1, grill_height=0.0, gravity=(1.0, 0.0, -9.81))


@pytest.fixture(scope="module")
def flip_nlp():
    """A flip NLP at a pickup end state, evaluated at a moving point of its initial guess."""
    cell = CellConfig()
    models = Models(cell)
    from flipkit.model.ik import solve_pose
    from flipkit.behaviors.targets import pickup_end

    pb = np.array([0.69, -0.16, 0.072])
    pose = pickup_end(cell, pb)
    q0 = solve_pose(models.loaded, pose.p, pose.o, models.loaded.q_home)
    return transcribe("flip", models, q0, np.zeros(6), location=pb)


@pytest.mark.parametrize("block_type", [Landing, FlightClearance])
@pytest.mark.parametrize("seed", [0, 1])
def test_flight_block_jacobians_match_finite_differences(flip_nlp, block_type, seed):
    block = next(b for b in flip_nlp.blocks if isinstance(b, block_type))
    assert np.all(np.isfinite(check_block_jacobian(flip_nlp, block, seed)))


def _set(x, cols, z):
    y = x.copy()
    y[cols] = z
    return y


def test_release_node_and_options_are_validated():
    assert SegmentOptions().release_node() == 14  # ⌈0.7 · 20⌉
    with pytest.raises(ConfigError, match="r_land"):
        SegmentOptions(r_land=0.0)
    with pytest.raises(ConfigError, match="release_fraction"):
        SegmentOptions(release_fraction=0.95)


def test_landing_spot_off_the_grill_is_refused(flip_nlp):
    from flipkit.planning.planners.planner import plan_flip

    with pytest.raises(UnreachableError, match="landing spot"):
        plan_flip((0.69, -0.16, 0.072), land=(1.5, 0.0))


def test_solved_flip_records_a_landing_that_verify_recomputes(flip_plan):
    flip = flip_plan.segment("flip")
    land = flip.landing
    assert flip.release["node"] == 14 and land["r_land"] == R_LAND
    assert land["offset"] <= R_LAND + 1e-6 and land["tilt_deg"] >= TILT_MIN_DEG - 1e-6
    np.testing.assert_allclose(land["target"], flip_plan.burger["location"][:2])
    cell = flip_plan.cell()
    again = recompute_landing(flip_plan.robot_for("flip", cell), flip, cell)
    np.testing.assert_allclose(again["point"], land["point"], atol=1e-6)
    assert again["tilt_deg"] == pytest.approx(land["tilt_deg"], abs=1e-4)
    assert again["time_of_flight"] == pytest.approx(land["time_of_flight"], abs=1e-6)
    assert verify_plan(flip_plan).ok


def test_tampered_landing_record_fails_verify(flip_plan):
    import copy

    plan = copy.deepcopy(flip_plan)
    flip = plan.segment("flip")
    flip.landing["point"][0] += 0.01  # claims a landing 1 cm off what the arrays give
    report = verify_plan(plan)
    assert not report.ok and report.worst()[0] == "landing"
    flip.landing, flip.release = None, None  # a flip without its release fails too
    assert verify_plan(plan).groups["landing"].ok is False


def test_cone_and_landing_for_a_burger_off_centre(flip_nlp):
    """A burger dragged 5 cm toward the tip: the cone rows act at the blade point under it
    (their Jacobian against central differences) and the landing starts from there."""
    cell = CellConfig()
    nlp0 = flip_nlp
    q0, qd0 = nlp0.x0[nlp0.layout.iq(0)], nlp0.x0[nlp0.layout.iqd(0)]
    nlp = transcribe("flip", Models(cell), q0, qd0, location=(0.69, -0.16, 0.072),
                        on_blade=(0.05, 0.01))
    cone = next(b for b in nlp.blocks if b.name == "cone")
    x = nlp.x0.copy()
    x[nlp.layout.T_index] = 0.5
    vals, entries = cone.evaluate(Evaluation(nlp.layout, nlp.robot, x))
    vals0 = next(b for b in nlp0.blocks if b.name == "cone").evaluate(
        Evaluation(nlp0.layout, nlp0.robot, x))[0]
    assert np.max(np.abs(vals - vals0)) > 1e-3  # a different point, a different margin
    J = np.zeros((cone.m, nlp.n))
    np.add.at(J, (cone.rows, cone.cols), entries)
    cols = np.unique(cone.cols)[:30]
    fd = central_fd(lambda z: cone.evaluate(Evaluation(nlp.layout, nlp.robot,
                                                       _set(x, cols, z)))[0], x[cols])
    np.testing.assert_allclose(J[:, cols], fd, atol=1e-5, rtol=1e-6)
    landing = next(b for b in nlp.blocks if b.name == "landing")
    assert landing.on_blade == [0.05, 0.01]


@pytest.mark.parametrize("extra, message", [
    (["--land", "2", "0"], "landing spot (2.000, 0.000) is outside the grill"),
    (["--r-land", "0"], "--r-land must be in [0.0001, 0.1] m"),
    (["--r-land", "1e-9"], "landing's spread"),
    (["--r-land", "0.2"], "--r-land must be in [0.0001, 0.1] m"),
    (["--land", "0.7"], "--land"),
])
def test_cli_landing_options_fail_in_one_line(tmp_path, capsys, extra, message):
    from flipkit.cli import main

    out = tmp_path / "p.json"
    rc = main(["plan", "flip", "--burger", "0.69", "-0.16", "0.072", *extra, "--json", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and message in err and "\n" not in err and not out.exists()
