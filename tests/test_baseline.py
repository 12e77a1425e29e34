"""End-effector-space + IK baseline: the EE QPs meet their constraints (checked from the
samples, not from the QP), placo's spatula frame is pinocchio's, and the classifier names
each failure with the measured amount."""

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors import targets as tg
from flipkit.baseline import (EE_METHODS, REASONS, PlacoTracker, Thresholds, classify_segment,
                              plan_segment, run_baseline)
from flipkit.baseline.ee_opt import EEState
from flipkit.config import TABLE1_LOCATIONS, RobotConfig, SpatulaConfig
from flipkit.model.contact import specific_force
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.model.ik import solve_pose
from flipkit.model.orientation import rpy
from flipkit.model.robot import Robot

BENIGN = TABLE1_LOCATIONS[5]  # (0.69, -0.16): the first three subbehaviours track exactly
RATE = 200.0


@pytest.fixture(scope="module")
def benign(cell):
    return run_baseline(BENIGN, cell, rate=RATE, ee="fixed")


@pytest.fixture(scope="module")
def bare(cell):
    return Robot(cell)


def edge_heights(cell, p, R):
    sp = cell.spatula
    edges = np.array([[sp.length / 2, 0, 0], [-sp.length / 2, 0, 0],
                      [0, sp.width / 2, 0], [0, -sp.width / 2, 0]]).T
    return p[:, 2:3] + np.einsum("kj,jc->kc", R[:, 2], edges)


def test_all_five_subbehaviours_run(benign):
    """(Their EE and IK times against the paper's < 1 s: ``python -m
    bench.bench flip --baseline``.)"""
    assert [s.subbehavior for s in benign.segments] == list(FLIP_NAMES)
    assert len(benign.trajectories) == len(benign.tracks) == 5
    for seg, traj in zip(benign.segments, benign.trajectories):
        assert np.diff(traj.t).max() <= 1 / RATE + 1e-12 and traj.t[-1] == traj.T
    assert set(benign.time_s) == set(FLIP_NAMES)


def test_the_bench_reports_the_ee_and_ik_times(cell, capsys):
    """The EE optimisation and IK times, against the paper's < 1 s, are the bench's to print
    (``bench flip --baseline``): one per subbehaviour run, with each EE method."""
    from bench.bench import _bench_baseline

    out = _bench_baseline(cell, [BENIGN])
    assert set(out) == set(EE_METHODS)
    for rec in out.values():
        assert len(rec["ee_s"]) == len(rec["ik_s"]) == len(rec["segments"][0]) > 0
        assert all(t > 0 for t in rec["ee_s"] + rec["ik_s"])
    assert "EE < 1 s" in capsys.readouterr().out


def test_endpoints_and_continuity(benign, cell, bare):
    pb = np.array(BENIGN)
    tr = {t.name: t for t in benign.trajectories}
    home = bare.placement(bare.q_home)
    ends = {"go_to_burger": tg.scoop_ready(cell, pb, 0.0), "scoop": tg.scoop_end(cell, pb, 0.0),
            "pickup": tg.pickup_end(cell, pb),
            "turn_back": tg.Pose(tuple(home.translation), tuple(rpy(home.rotation)))}
    for name, pose in ends.items():
        assert np.allclose(tr[name].p[-1], pose.p, atol=1e-6), name
        assert np.allclose(rpy(tr[name].R[-1]), pose.o, atol=1e-9), name
    assert np.allclose(tr["go_to_burger"].v[[0, -1]], 0, atol=1e-6)  # from and to rest
    assert np.allclose(tr["turn_back"].v[-1], 0, atol=1e-6)  # starts at the flip's end velocity
    assert np.allclose(tr["go_to_burger"].p[0], home.translation, atol=1e-6)
    for prev, nxt in zip(benign.trajectories, benign.trajectories[1:]):
        assert np.allclose(nxt.p[0], prev.p[-1], atol=1e-6)
        assert np.allclose(nxt.v[0], prev.v[-1], atol=1e-5)
        assert np.allclose(nxt.R[0], prev.R[-1], atol=1e-9)
    scoop = tr["scoop"]  # eq. (24): the tip stays on the grill (at the burger's height)
    tip = scoop.p[:, 2] + scoop.R[:, 2, 0] * cell.spatula.length / 2
    assert np.allclose(tip, pb[2], atol=1e-6)
    flip = tr["flip"]
    lo_n, hi_n = (np.array(b) for b in tg.FLIP_NORMAL_BOUNDS)
    assert np.all(flip.R[-1][:, 2] >= lo_n) and np.all(flip.R[-1][:, 2] <= hi_n)
    lo_x, hi_x = (np.array(b) for b in tg.FLIP_XAXIS_BOUNDS)
    assert np.all(flip.R[:, :, 0] >= lo_x) and np.all(flip.R[:, :, 0] <= hi_x)
    band = cell.grill.height + np.array(tg.FLIP_HEIGHT_BAND)
    assert band[0] - 1e-6 <= flip.p[-1, 2] <= band[1] + 1e-6
    for t in benign.trajectories:  # blade above the grill everywhere
        assert edge_heights(cell, t.p, t.R).min() >= min(cell.grill.height, pb[2]) - 1e-6


def test_friction_cone_from_sampled_accelerations(benign, cell):
    mu, g = cell.burger.mu, np.array(cell.gravity)
    for traj in benign.trajectories:
        if traj.name not in ("pickup", "flip"):
            assert not traj.cone.any()
            continue
        n_cone = traj.cone.sum()
        assert n_cone == (len(traj.t) if traj.name == "pickup"
                          else int(tg.FLIP_CONE_FRACTION * (len(traj.t) - 1)) + 1)
        # acceleration by central differences of the sampled positions, not the QP's basis
        a_fd = (traj.p[2:] - 2 * traj.p[1:-1] + traj.p[:-2]) / (traj.t[1] - traj.t[0]) ** 2
        assert np.allclose(a_fd, traj.a[1:-1], atol=0.05)
        for k in np.flatnonzero(traj.cone):
            a = traj.a[k] if k in (0, len(traj.t) - 1) else a_fd[k - 1]
            f = specific_force(traj.R[k], a, g)
            assert f[2] >= -0.05, (traj.name, k, f)
            assert abs(f[0]) <= mu * f[2] + 0.05 and abs(f[1]) <= mu * f[2] + 0.05, (k, f)


def test_benign_verdicts(benign):
    by = {s.subbehavior: s for s in benign.segments}
    for name in ("go_to_burger", "scoop", "pickup"):
        assert by[name].status == "solved", by[name]
        # placo's IK accuracy, where the profile's speeds (0.9 of UR's) bind for a few samples
        assert by[name].measures["tracking_position_m"] < 1e-4  # measured 42 µm
    # the 2.7 rad roll within the flip's T_max needs ~9 rad/s of wrist 3 (bound 2.83): IK lags
    assert benign.status == "failed" and benign.subbehavior == "flip"
    assert benign.reason == "tracking_error" and benign.amount > 0.05
    assert all(s.reason in REASONS for s in benign.segments if s.status == "failed")


def test_placo_spatula_frame_matches_pinocchio(bare):
    tracker = PlacoTracker(bare)
    for dq in (0.0, 0.3, -0.5):
        q = bare.q_home + dq * np.array([1, -0.5, 0.7, 1, -1, 2])
        tracker.set_q(q)
        assert np.allclose(tracker.get_q(), q)
        T = tracker.placo.get_T_world_frame("spatula")
        assert np.allclose(T, bare.placement(q).homogeneous, atol=1e-12)


def test_narrowed_joint_limit_is_reported(benign, cell, tmp_path):
    """Wrist 1 may go only 0.5 mrad beyond its extreme on go-to-burger: the IK still tracks
    (the limit is not active) but the joint comes within 1e-3 rad of it."""
    q4_max = benign.tracks[0].q[:, 3].max()
    text = Path(Robot(cell).urdf).read_text()
    text = re.sub(r'(<joint name="wrist_1_joint".*?<limit [^>]*upper=")[^"]*"',
                  lambda m: m.group(1) + f'{q4_max + 5e-4:.9f}"', text, flags=re.S)
    # a URDF of one's own stays within the UR10's published speeds (or is refused)
    text = re.sub(r'velocity="[^"]*"', 'velocity="2.0"', text)
    urdf = tmp_path / "ur10_narrow.urdf"
    urdf.write_text(text)
    narrow = replace(cell, robot=RobotConfig(urdf=str(urdf)))
    result = run_baseline(BENIGN, narrow, rate=RATE, ee="fixed")
    assert result.subbehavior == "go_to_burger" and result.reason == "joint_limit"
    assert result.amount == pytest.approx(5e-4, abs=5e-5)
    assert "joint 4" in result.failure.detail


def test_infeasible_cone_is_ee_infeasible(cell):
    slippery = replace(cell, burger=replace(cell.burger, mu=0.01))
    result = run_baseline(BENIGN, slippery, rate=RATE, ee="fixed")
    assert result.reason == "ee_infeasible" and result.subbehavior in ("pickup", "flip")
    assert len(result.segments) < 5


def _static(robot, q, n=21, rate=RATE):
    t = np.arange(n) / rate
    qs = np.tile(np.asarray(q, float), (n, 1))
    return t, qs


def _refs(robot, qs):
    Ms = [robot.placement(q) for q in qs]
    return np.array([M.translation for M in Ms]), np.array([M.rotation for M in Ms])


def _verdict(robot, t, qs, p=None, R=None):
    p0, R0 = _refs(robot, qs)
    return classify_segment("test", robot, t, qs, p0 if p is None else p, R0 if R is None else R)


def test_classifier_hand_made(bare, cell):
    t, qs = _static(bare, bare.q_home)
    assert _verdict(bare, t, qs).status == "solved"

    p_ref, R_ref = _refs(bare, qs)
    v = _verdict(bare, t, qs, p=p_ref + np.array([0, 0.002, 0]))
    assert (v.reason, v.amount, v.limit) == ("tracking_error", pytest.approx(0.002), 1e-3)

    near = qs.copy()
    near[:, 5] = bare.q_max[5] - 4e-4
    v = _verdict(bare, t, near)
    assert v.reason == "joint_limit" and v.amount == pytest.approx(4e-4)

    jump = qs.copy()
    jump[10:, 1] += 0.3
    v = _verdict(bare, t, jump)
    assert v.reason == "configuration_jump" and v.amount == pytest.approx(0.3)

    fast = qs + np.outer(t, [3.0, 0, 0, 0, 0, 0])  # base at 3 rad/s > 0.9 × 2.094
    v = _verdict(bare, t, fast)
    assert v.reason == "joint_velocity" and v.amount == pytest.approx(3.0)
    assert v.limit == pytest.approx(0.9 * np.radians(120)) and "joint 1" in v.detail

    accel = qs + np.outer(0.5 * 25.0 * t**2, [0, 0, 0, 1, 0, 0])  # 25 rad/s² > 20
    v = _verdict(bare, t, accel)
    assert v.reason == "joint_acceleration" and v.amount == pytest.approx(25.0)

    q_low = solve_pose(bare, (0.70, -0.20, 0.05), (0.0, 0.0, 0.0))  # blade flat 2.2 cm low
    t, low = _static(bare, q_low)
    v = _verdict(bare, t, low)
    assert v.reason == "below_grill" and v.amount == pytest.approx(0.05, abs=1e-7)
    assert v.limit == pytest.approx(cell.grill.height - 1e-3)


def test_classifier_torque_with_heavy_payload(cell):
    heavy = Robot(replace(cell, spatula=SpatulaConfig(mass=80.0)))
    t, qs = _static(heavy, heavy.q_home)
    v = _verdict(heavy, t, qs)
    u = np.abs(heavy.inverse_dynamics(heavy.q_home, np.zeros(6), np.zeros(6)))
    j = int(np.argmax(u / heavy.u_max))
    assert v.reason == "torque" and v.amount == pytest.approx(u[j]) and v.limit == heavy.u_max[j]


def test_arguments_are_validated(cell, bare):
    with pytest.raises(ConfigError):
        Thresholds(position=0.0)
    with pytest.raises(ConfigError):
        PlacoTracker(bare, iterations=0)
    start = EEState((0.6, -0.2, 0.3), (0, 0, 0), (0, 0, 0))
    with pytest.raises(InvalidChoiceError):
        plan_segment("dance", cell, BENIGN, start, 0.5)
    with pytest.raises(ConfigError):
        plan_segment("scoop", cell, BENIGN, start, -1.0)
    with pytest.raises(ConfigError):
        run_baseline(BENIGN, cell, rate=0.0)
    t, qs = _static(bare, bare.q_home)
    with pytest.raises(ConfigError):
        classify_segment("x", bare, t, qs[:-1], *_refs(bare, qs))


@pytest.mark.parametrize("speed, T, want", [(0.9, 1.0, None), (1.5, 1.0, "time_scalable"),
                                           (3.0, 0.4, "dynamic")])
def test_time_scaling_class(bare, speed, T, want):
    """A wrist-3 sweep run at `speed` × its velocity limit: under the limit it passes; 1.5×
    passes once slowed down by s ≈ 1.5 (≤ 2: time_scalable); 3× needs more than 2× (dynamic)."""
    from flipkit.baseline.classify import MAX_TIME_SCALING, classify_segment

    n = 501
    t = np.linspace(0.0, T, n)
    amp = speed * bare.qd_max[5] * T / np.pi  # q6 = amp sin(πt/T): peak rate amp π / T
    q = np.tile(bare.q_home, (n, 1))
    q[:, 5] -= amp * np.sin(np.pi * t / T)  # starts and ends at q_home's q6, within limits
    M = [bare.placement(qk) for qk in q]
    v = classify_segment("go_to_burger", bare, t, q, np.array([m.translation for m in M]),
                         np.array([m.rotation for m in M]))
    assert v.failure_class == want
    if want is None:
        assert v.status == "solved"
        return
    assert v.reason == "joint_velocity" and v.amount == pytest.approx(speed * bare.qd_max[5],
                                                                      rel=1e-3)
    if want == "time_scalable":
        assert v.time_scaling == pytest.approx(speed, rel=2e-3)
        assert v.time_scaling <= MAX_TIME_SCALING
    else:
        assert v.time_scaling == float("inf")
