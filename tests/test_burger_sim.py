"""MuJoCo burger physics under prescribed spatula motions, and the Sec. V success judges."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, RotationSpline

from flipkit.simulation.judges import judge_flip, judge_pickup, judge_scoop, overlap_fraction
from flipkit.simulation.prescribed_blade import BurgerSim
from flipkit.simulation.run import BurgerRun
from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.model.orientation import rpy_matrix

CELL = CellConfig()
HG = CELL.grill.height
START = np.array([0.70, -0.20, 0.30])  # spatula held well above the grill
PB = np.array([0.75, 0.0, HG])  # a burger location on the grill


@pytest.fixture(scope="module")
def sim():
    return BurgerSim(CELL)


def still(T, o=(0.0, 0.0, 0.0), p=START):
    t = np.array([0.0, T])
    return t, np.tile(p, (2, 1)), np.tile(rpy_matrix(o), (2, 1, 1))


def bang_bang(accel, t_acc=0.2, T=0.8, n=161):
    """Along world x: +accel for t_acc, −accel for t_acc, then rest (m/s²)."""
    t = np.linspace(0.0, T, n)
    a = np.where(t < t_acc, accel, np.where(t < 2 * t_acc, -accel, 0.0))
    v = np.concatenate(([0.0], np.cumsum((a[1:] + a[:-1]) / 2 * np.diff(t))))
    x = np.concatenate(([0.0], np.cumsum((v[1:] + v[:-1]) / 2 * np.diff(t))))
    return t, START + np.outer(x, [1.0, 0.0, 0.0]), np.tile(np.eye(3), (n, 1, 1))


def smooth(s):
    """Quintic 0→1 with zero end velocity and acceleration."""
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def roll_flip(T=0.5):
    """From the pickup pose above PB: rise 25 cm while rolling the blade 2.9 rad."""
    t = np.linspace(0.0, T, 41)
    s = smooth(t / T)
    P = PB + [0.02, 0.0, 0.05] + np.outer(s, [0.0, 0.0, 0.25])
    return t, P, np.array([rpy_matrix([2.9 * si**2, -0.05, 0.0]) for si in s])


def slip(run):
    rel = run.in_blade_frame()
    return np.linalg.norm(rel[:, :2] - rel[0, :2], axis=1).max()


# ------------------------------------------------------------------ physics
def test_burger_rests_on_still_flat_spatula(sim):
    run = sim.simulate(*still(1.0), burger_start="on_spatula")
    assert np.linalg.norm(run.burger_pos - run.burger_pos[0], axis=1).max() < 1e-3
    assert run.touch_spatula[1:].all() and not run.touch_grill.any()
    g = -CELL.gravity[2]
    assert run.force_spatula[-1] == pytest.approx(CELL.burger.mass * g, rel=0.02)


def test_burger_on_grill_rests_and_touches_only_grill():
    run = BurgerSim(CELL, burger_xy=(0.75, 0.0)).simulate(*still(0.3))
    np.testing.assert_allclose(run.burger_pos[-1], [0.75, 0.0, HG + CELL.burger.thickness / 2],
                               atol=1e-4)
    assert run.touch_grill[1:].all() and not run.touch_spatula.any()


def test_blade_follows_prescribed_motion(sim):
    t, P, R = bang_bang(1.0)
    run = sim.simulate(t, P, R, burger_start="on_spatula")
    x_ref = np.interp(run.t, t, P[:, 0])
    assert np.abs(run.spatula_pos[:, 0] - x_ref).max() < 5e-4
    assert np.abs(run.spatula_rot - np.eye(3)).max() < 1e-3
    t, P, R = roll_flip()  # fast rotation, burger flung off: still on track
    run = sim.simulate(t, P, R, burger_start="on_spatula")
    R_ref = RotationSpline(t, Rotation.from_matrix(R))(run.t)
    assert (Rotation.from_matrix(run.spatula_rot) * R_ref.inv()).magnitude().max() < 2e-3


def test_fast_translation_slides_burger_gentle_one_does_not(sim):
    mu_g = CELL.burger.mu * 9.81
    fast = sim.simulate(*bang_bang(2.0 * mu_g), burger_start="on_spatula")
    gentle = sim.simulate(*bang_bang(0.3 * mu_g), burger_start="on_spatula")
    assert slip(fast) > 0.03
    assert slip(gentle) < 3e-3


def test_tilt_holds_below_friction_angle_and_slides_above(sim):
    angle = np.arctan(CELL.burger.mu)
    held = sim.simulate(*still(0.5, (0.0, angle - 0.03, 0.0)), burger_start="on_spatula")
    slid = sim.simulate(*still(0.5, (0.0, angle + 0.03, 0.0)), burger_start="on_spatula")
    assert slip(held) < 1e-3 < 0.02 < slip(slid)


def test_motionless_spatula_fails_the_flip(sim):
    run = sim.simulate(*still(0.6), burger_start="on_spatula")
    v = judge_flip(run, (0.1, 0.5), START[:2])
    assert not v.ok and not v.upside_down and v.contact_fraction == 1.0


def test_fast_roll_turns_the_burger_over_near_the_spot(sim):
    t, P, R = roll_flip()
    run = sim.simulate(t, P, R, burger_start="on_spatula", hold=1.0)
    v = judge_flip(run, (0.0, t[-1]), PB[:2])
    assert v.upside_down and v.on_grill and max(map(abs, v.offset)) < 0.05


@pytest.mark.parametrize("mu_grill, ok", [(None, True), (0.5, False)])
def test_scripted_scoop_and_pickup(mu_grill, ok):
    """Tip on the grill (eq. 24) from scoop-ready (eq. 23) to flat under the burger, then lift
    (eq. 25). A sticky grill holds the rigid puck while the wedge slides under it; a slippery
    one lets the blade push it ahead."""
    l, d, Ts = CELL.spatula.length, CELL.burger.diameter, 0.6
    ts = np.linspace(0.0, Ts, 61)
    s = smooth(ts / Ts)
    o, tip = 0.314 * (1 - s), PB[0] - d / 2 + s * (d / 2 + l / 2)
    P = np.column_stack((tip - l / 2 * np.cos(o), 0 * o, HG + l / 2 * np.sin(o)))
    R = np.array([rpy_matrix([0.0, oi, 0.0]) for oi in o])
    tp = Ts + np.linspace(0.0, 0.5, 51)[1:]
    sp = smooth((tp - Ts) / 0.5)
    Pp = PB + np.outer(sp, [0.02, 0.0, 0.05])
    Rp = np.array([rpy_matrix([0.0, -0.05 * si, 0.0]) for si in sp])
    sim = BurgerSim(CELL, burger_xy=PB[:2], mu_grill=mu_grill)
    run = sim.simulate(np.concatenate((ts, tp)), np.vstack((P, Pp)), np.vstack((R, Rp)))
    scoop, pickup = judge_scoop(run, (0.0, Ts)), judge_pickup(run, (Ts, Ts + 0.5))
    assert scoop.ok == ok and pickup.ok == ok
    if ok:
        assert scoop.overlap > 0.9 and pickup.clearance > 0.04


@pytest.mark.parametrize("kwargs", [dict(mu=-0.1), dict(mass=0.0), dict(grill_height=np.nan),
                                    dict(solref=(0.001, 1.0))])
def test_invalid_sim_parameters(kwargs):
    with pytest.raises(ConfigError):
        BurgerSim(CELL, **kwargs)


def test_invalid_simulate_arguments(sim):
    t, P, R = still(0.1)
    for bad in [dict(t=t[::-1]), dict(spatula_pos=P[:, :2]), dict(spatula_rot=R[:1]),
                dict(burger_start="in_air"), dict(burger_start="on_grill")]:
        args = dict(t=t, spatula_pos=P, spatula_rot=R, burger_start="on_spatula") | bad
        with pytest.raises(ConfigError):
            sim.simulate(**args)


# ------------------------------------------------------------------ judges on hand-made runs
def made(burger_xyz, burger_o=(0.0, 0.0, 0.0), blade_o=(0.0, 0.0, 0.0), n=11,
         touch_spatula=True, touch_grill=False):
    """A run of n samples over 1 s, everything still; burger given in the blade frame."""
    Rs, Rb = rpy_matrix(blade_o), rpy_matrix(burger_o)
    p = START + Rs @ np.asarray(burger_xyz, float)
    ts = np.broadcast_to(np.asarray(touch_spatula), (n,)).copy()
    return BurgerRun(
        t=np.linspace(0, 1, n), burger_pos=np.tile(p, (n, 1)), burger_rot=np.tile(Rb, (n, 1, 1)),
        spatula_pos=np.tile(START, (n, 1)), spatula_rot=np.tile(Rs, (n, 1, 1)),
        touch_spatula=ts, touch_grill=np.full(n, touch_grill), force_spatula=np.zeros(n),
        force_grill=np.zeros(n), burger_diameter=0.10, burger_thickness=0.015,
        blade_length=0.16, blade_width=0.12, grill_height=START[2] - 0.2)


def segment_fraction(a, r=0.05):
    """Fraction of a disc of radius r whose centre is a from a line, on the centre's side."""
    a = np.clip(a, -r, r)
    cut = r**2 * np.arccos(abs(a) / r) - abs(a) * np.sqrt(r**2 - a**2)
    return 1 - cut / (np.pi * r**2) if a >= 0 else cut / (np.pi * r**2)


@pytest.mark.parametrize("x", [0.0, 0.05, 0.07, 0.08, 0.10, 0.12])
def test_overlap_fraction_matches_circular_segment(x):
    run = made((x, 0.0, 0.0075), burger_o=(0.0, 0.3, 0.0), blade_o=(0.0, 0.3, 0.0))
    assert overlap_fraction(run, 0) == pytest.approx(segment_fraction(0.08 - x), abs=0.01)


def test_judge_scoop_half_over_vs_mostly_off():
    assert judge_scoop(made((0.07, 0.0, 0.0075)), (0, 1)).ok
    off = judge_scoop(made((0.11, 0.02, 0.0075)), (0, 1))
    assert not off.ok and off.overlap < 0.3
    under = judge_scoop(made((0.0, 0.0, -0.02)), (0, 1))
    assert under.overlap == 1.0 and not under.above and not under.ok


def test_judge_pickup():
    ok = judge_pickup(made((0.0, 0.0, 0.0075)), (0, 1))
    assert ok.ok and ok.clearance == pytest.approx(0.2, abs=1e-9)
    assert ok.gap == pytest.approx(0.0, abs=1e-12) and ok.over_blade
    assert not judge_pickup(made((0, 0, 0.0075), touch_grill=True), (0, 1)).ok
    assert not judge_pickup(made((0, 0, 0.0075), touch_spatula=False), (0, 1)).ok


def flickering(gap=0.0, n=401, T=0.4, burger_xy=(0.0, 0.0), tilt=0.0, grill=None):
    """A 1 kHz pickup: the blade rises and decelerates, the burger rests on it (lowest point
    ``gap`` above the face) and the contact flag alternates every millisecond."""
    t = np.linspace(0.0, T, n)
    Rs = rpy_matrix((0.0, tilt, 0.0))
    P = START + np.outer(smooth(t / T), [0.0, 0.0, 0.05])
    B = P + Rs @ np.array([*burger_xy, 0.0075 + gap])
    flag = np.arange(n) % 2 == 0
    return BurgerRun(
        t=t, burger_pos=B, burger_rot=np.tile(Rs, (n, 1, 1)), spatula_pos=P,
        spatula_rot=np.tile(Rs, (n, 1, 1)), touch_spatula=flag,
        touch_grill=np.zeros(n, bool) if grill is None else grill, force_spatula=np.zeros(n),
        force_grill=np.zeros(n), burger_diameter=0.10, burger_thickness=0.015,
        blade_length=0.16, blade_width=0.12, grill_height=START[2] - 0.02)


@pytest.mark.parametrize("last", [True, False])
def test_judge_pickup_flickering_contact_still_on_spatula(last):
    """The contact flag alternates while the burger rests on the blade: whichever value the
    last sample has, the burger is on the spatula (gap ~0, contact within the last 50 ms)."""
    run = flickering(gap=2e-5, n=401 if last else 400)
    assert bool(run.touch_spatula[-1]) == last
    v = judge_pickup(run, (0.0, run.t[-1]))
    assert v.ok and v.on_spatula and v.off_grill
    assert v.gap == pytest.approx(2e-5, abs=1e-9) and v.spatula_contact == pytest.approx(0.5,
                                                                                         abs=0.03)
    tilted = flickering(gap=1e-4, tilt=0.2)  # the gap is along the blade normal, not world z
    assert judge_pickup(tilted, (0.0, tilted.t[-1])).ok


def test_judge_pickup_rejects_burger_off_the_blade_despite_contact():
    lifted = flickering(gap=0.01)  # 1 cm above the face: tossed, not resting
    v = judge_pickup(lifted, (0.0, lifted.t[-1]))
    assert not v.ok and not v.on_spatula and v.gap == pytest.approx(0.01)
    hanging = flickering(burger_xy=(0.09, 0.0))  # centre past the tip
    v = judge_pickup(hanging, (0.0, hanging.t[-1]))
    assert not v.ok and not v.over_blade


def test_judge_pickup_grill_contact_in_window_or_too_low_is_on_grill():
    grill = np.zeros(401, bool)
    grill[-30] = True  # one grill contact 30 ms before the end
    v = judge_pickup(flickering(grill=grill), (0.0, 0.4))
    assert v.on_spatula and not v.off_grill and not v.ok
    grill[:] = False
    grill[-60] = True  # 60 ms before the end: outside the window
    assert judge_pickup(flickering(grill=grill), (0.0, 0.4)).ok
    # At the pickup's start the blade is 2 cm above the grill: lowest point 1 mm below it
    early = judge_pickup(flickering(gap=-0.021), (0.0, 0.0))
    assert not early.off_grill


def test_judge_flip_counts_flickering_contact_as_carried():
    run = flickering(gap=1e-5)
    v = judge_flip(run, (0.0, run.t[-1]), START[:2])
    assert v.contact_fraction == 1.0  # the flag is set on only half the samples
    # Leaving: no contact after mid-flip, though still within BLADE_GAP_TOL for a while —
    # not bridged (no later contact), so counted off from the last contact on.
    run.touch_spatula[201:] = False
    v = judge_flip(run, (0.0, run.t[-1]), START[:2])
    assert v.contact_fraction == pytest.approx(201 / 401)
    # A 60 ms flag-off run between contacts is longer than CONTACT_WINDOW: not bridged.
    run.touch_spatula[:] = True
    run.touch_spatula[100:160] = False
    v = judge_flip(run, (0.0, run.t[-1]), START[:2])
    assert v.contact_fraction == pytest.approx(341 / 401)


def test_judge_flip_landing_and_orientation():
    down = (np.pi, 0.0, 0.0)
    spot = START[:2]
    near = made((0.03, 0.0, 0.0), burger_o=down, touch_grill=True)
    assert judge_flip(near, (0, 1), spot).ok
    far = judge_flip(made((0.07, 0.0, 0.0), burger_o=down, touch_grill=True), (0, 1), spot)
    assert not far.ok and far.offset[0] == pytest.approx(0.07)
    upright = judge_flip(made((0.03, 0.0, 0.0), touch_grill=True), (0, 1), spot)
    assert not upright.ok and upright.up_z == pytest.approx(1.0)
    brief = made((0.0, 0.0, 0.0), burger_o=down, touch_grill=True,
                 touch_spatula=np.arange(11) < 5)  # 5 of 11 samples in contact
    v = judge_flip(brief, (0, 1), spot)
    assert not v.ok and v.contact_fraction == pytest.approx(5 / 11)
    with pytest.raises(ConfigError):
        judge_flip(near, (2.0, 3.0), spot)
