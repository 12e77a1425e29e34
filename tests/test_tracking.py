"""Joint PD tracking on the pinocchio plant: holding, sinusoids, gains, mismatch, validation."""

import numpy as np
import pinocchio as pin
import pytest

from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.model.robot import Robot
from flipkit.simulation.tracking import DEFAULT_KD, DEFAULT_KP, TrackingResult, track


@pytest.fixture(scope="module")
def ctrl():
    return Robot()  # controller model: spatula only


@pytest.fixture(scope="module")
def plant():
    return Robot(with_burger=True)  # the burger the controller does not know about


def hold(r, T=1.0):
    t = np.array([0.0, T])
    return t, np.tile(r.q_home, (2, 1)), np.zeros((2, r.nq))


def sinusoid(r, T=1.5, period=1.5):
    t = np.linspace(0, T, 31)
    w, amp = 2 * np.pi / period, np.array([0.3, 0.3, 0.3, 0.5, 0.5, 0.5])
    return t, r.q_home + amp * np.sin(w * t)[:, None], amp * w * np.cos(w * t)[:, None]


def test_default_gains_discretised_closed_loop_is_stable(ctrl, plant):
    dt, rng, I = 1e-3, np.random.default_rng(7), np.eye(6)
    Kp, Kd = np.diag(DEFAULT_KP), np.diag(DEFAULT_KD)
    for r in (ctrl, plant):
        for q in [r.q_home] + [r.q_home + rng.uniform(-1, 1, 6) for _ in range(4)]:
            M = np.triu(pin.crba(r.model, r.data, q))  # upper triangle is filled
            Mi = np.linalg.inv(M + np.triu(M, 1).T)
            A = np.block([[I - dt**2 * Mi @ Kp, dt * I - dt**2 * Mi @ Kd],
                          [-dt * Mi @ Kp, I - dt * Mi @ Kd]])  # semi-implicit Euler + ZOH PD
            assert np.abs(np.linalg.eigvals(A)).max() < 0.995


def test_holding_home_with_gravity_feedforward(ctrl, plant):
    res = track(ctrl, *hold(ctrl), u_ff="gravity", mismatch=plant)
    assert np.abs(res.q - ctrl.q_home).max() < 1e-3  # burger weight / Kp ≈ 0.5 mrad
    assert not res.saturated.any()
    sag = track(ctrl, *hold(ctrl), u_ff="none")  # without it the arm sags far more
    assert np.abs(sag.q - ctrl.q_home).max() > 1e-2


def test_sinusoid_error_bounded_and_shrinks_with_gains(ctrl):
    t, Q, QD = sinusoid(ctrl)
    base = track(ctrl, t, Q, QD, u_ff="gravity")
    stiff = track(ctrl, t, Q, QD, u_ff="gravity", kp=4 * np.array(DEFAULT_KP),
                  kd=2 * np.array(DEFAULT_KD))
    e0, e1 = base.errors()[0], stiff.errors()[0]
    assert e0.max < 0.03 and e1.max < 0.5 * e0.max and e1.rms < 0.5 * e0.rms
    full = track(ctrl, t, Q, QD)  # inverse-dynamics feed-forward: near-perfect
    assert full.errors()[0].max < 1e-3
    assert np.abs(full.u).max() <= ctrl.u_max.max()


def test_payload_mismatch_increases_error(ctrl, plant):
    t, Q, QD = sinusoid(ctrl)
    exact, off = track(ctrl, t, Q, QD), track(ctrl, t, Q, QD, mismatch=plant)
    assert off.errors()[0].rms > 1.5 * exact.errors()[0].rms


def test_plan_torques_as_feedforward_and_segments(ctrl):
    t, Q, QD = sinusoid(ctrl)
    U = np.array([ctrl.inverse_dynamics(q, qd, np.zeros(6)) for q, qd in zip(Q, QD)])
    res = track(ctrl, t, Q, QD, u_ff=U, rate_hz=500)
    assert np.allclose(np.diff(res.t), 2e-3) and res.t[-1] == pytest.approx(t[-1])
    segs = res.errors([0.0, 0.5, 1.5])
    assert len(segs) == 2 and all(0 <= s.rms <= s.max for s in segs)
    e = res.position_error
    assert segs[0].max == pytest.approx(e[res.t <= 0.5 + 1e-9].max())


def test_torque_saturation_is_enforced(ctrl):
    t, Q, QD = hold(ctrl, 0.2)
    res = track(ctrl, t, Q, QD, q0=ctrl.q_home + 0.5)
    assert res.saturated[0] and np.all(np.abs(res.u) <= ctrl.u_max + 1e-12)


def test_result_is_a_dataclass_with_poses(ctrl):
    res = track(ctrl, *hold(ctrl, 0.05))
    assert isinstance(res, TrackingResult)
    assert res.p.shape == (51, 3) and res.R.shape == (51, 3, 3)
    np.testing.assert_allclose(res.p_des[0], ctrl.position(ctrl.q_home))


@pytest.mark.parametrize("kwargs", [
    dict(t_des=[0.0, 0.0]), dict(t_des=[0.0]), dict(q_des=np.zeros((2, 5))),
    dict(qd_des=np.full((2, 6), np.nan)), dict(kp=-1.0), dict(kd=[1.0, 2.0]),
    dict(rate_hz=0.0), dict(q0=np.zeros(3)), dict(u_ff=np.zeros((3, 6))),
])
def test_invalid_arguments_raise_config_error(ctrl, kwargs):
    args = dict(t_des=[0.0, 0.1], q_des=np.tile(ctrl.q_home, (2, 1)), qd_des=np.zeros((2, 6)))
    args.update(kwargs)
    with pytest.raises(ConfigError):
        track(ctrl, **args)


def test_unknown_feedforward_lists_choices(ctrl):
    with pytest.raises(InvalidChoiceError, match="gravity"):
        track(ctrl, *hold(ctrl, 0.1), u_ff="magic")
    with pytest.raises(ConfigError):
        track(ctrl, *hold(ctrl, 0.1)).errors([0.05, 0.01])


def test_duration_a_hair_short_of_the_sample_grid(ctrl):
    """A plan time grid ending at 0.6 − 2e-16 (a duration summed from node spacings) still
    gets its last controller sample at 0.6 s rounded down onto the plan, not past its end."""
    t_end = 0.5999999999999998
    t = np.array([0.0, 0.3, t_end])
    Q, QD = np.tile(ctrl.q_home, (3, 1)), np.zeros((3, ctrl.nq))
    U = np.tile(ctrl.inverse_dynamics(ctrl.q_home, np.zeros(6), np.zeros(6)), (3, 1))
    res = track(ctrl, t, Q, QD, u_ff=U, rate_hz=500)
    assert res.t[-1] <= t_end and res.t[-1] == pytest.approx(0.6)
