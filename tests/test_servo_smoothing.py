"""The held state after a plan, and the servo's optional smoothing of position commands
(``physics.servo_lookahead_s``, UR's servoj lookahead)."""

from dataclasses import replace

import numpy as np
import pytest

from flipkit.config import CellConfig, PhysicsConfig
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot
from flipkit.planning.plans.servo_command import lookahead_command, smoothed
from flipkit.simulation.control import hold_torque, plan_references


@pytest.fixture(scope="module")
def bare():
    return Robot(CellConfig(), with_burger=False)


def test_after_the_plan_its_final_configuration_is_held_at_rest(flip_plan, bare):
    """After the plan the desired torque is gravity at the final configuration (not the last
    node's torque, which carries M q̈ of an acceleration ending there), so position commands
    are the final q itself."""
    last = flip_plan.segments[-1]
    g = bare.inverse_dynamics(last.q[-1], np.zeros(6), np.zeros(6))
    np.testing.assert_allclose(hold_torque(flip_plan), g, atol=1e-9)
    assert np.abs(last.u[-1] - g).max() > 1.0  # the last node is not static
    ph = replace(flip_plan.cell().physics, servo_lookahead_s=0.0)  # commands as they are
    refs = plan_references(flip_plan, bare, ph, "position", "compensated", 1e-3, 0.2)
    after = refs.t > flip_plan.duration + ph.latency_s + 2.0 / ph.servo_rate_hz
    assert after.sum() > 100
    np.testing.assert_allclose(refs.u_ff[after], np.tile(g, (after.sum(), 1)), atol=1e-9)
    np.testing.assert_allclose(refs.q_cmd[after], np.tile(last.q[-1], (after.sum(), 1)),
                               atol=1e-9)


def test_a_negative_or_unfinite_lookahead_is_refused():
    for bad in (-0.01, float("nan"), float("inf")):
        with pytest.raises(ConfigError, match="servo_lookahead_s"):
            PhysicsConfig(servo_lookahead_s=bad)


def test_the_smoothing_is_a_first_order_low_pass_of_the_held_stream():
    """A unit step held from sample 1 on reaches 1 − exp(−k dt/τ) k samples later."""
    dt, tau = 1e-3, 0.03
    x = np.ones((200, 1))
    x[0] = 0.0
    y = smoothed(x, dt, tau)
    k = np.arange(200)
    want = np.where(k == 0, 0.0, 1.0 - np.exp(-(k - 1) * dt / tau))
    np.testing.assert_allclose(y[:, 0], want, atol=1e-12)
    assert smoothed(x, dt, 0.0) is not None and np.array_equal(smoothed(x, dt, 0.0), x)


def test_commands_made_for_the_smoothing_come_out_of_it_as_planned():
    """A smooth command stream, its filter inverse applied, leaves the low-pass within a
    small fraction of the lag the plain stream gets."""
    dt, tau = 1e-3, 0.03
    t = np.arange(0, 1.0, dt)
    q = np.sin(2 * np.pi * t)[:, None]
    qd = (2 * np.pi * np.cos(2 * np.pi * t))[:, None]
    qdd = (-(2 * np.pi) ** 2 * np.sin(2 * np.pi * t))[:, None]
    ph = PhysicsConfig(servo_lookahead_s=tau)
    x, v = lookahead_command(q, qd, qdd, t, ph)
    late = t > 5 * tau  # after the start transient
    plain = np.abs(smoothed(q, dt, tau) - q)[late].max()
    made = np.abs(smoothed(x, dt, tau) - q)[late].max()
    assert plain > 0.1 and made < 0.02 * plain
    assert np.abs(smoothed(v, dt, tau) - qd)[late].max() < 0.02 * np.abs(
        smoothed(qd, dt, tau) - qd)[late].max()
    same = lookahead_command(q, qd, qdd, t, PhysicsConfig(servo_lookahead_s=0.0))
    assert np.array_equal(same[0], q) and np.array_equal(same[1], qd)


def test_a_step_between_segments_is_sent_bounded_and_comes_out_in_place():
    """Where segments meet the compensation steps by Δ. Inverted exactly that would be an
    impulse (τ/Δt times Δ for a sample); the commands spread it over τ around the step, so
    they stay within about Δ of the stream, and the smoothed command is back on the stream
    within τ after the step, where the step passed as it is still lags by Δ/e."""
    dt, tau, c = 8e-3, 0.1, 100
    t = dt * np.arange(300)
    q = np.where(np.arange(300) >= c, 1.0, 0.0)[:, None] + 0.2 * t[:, None]  # ramp + step
    pieces = (np.arange(300) >= c).astype(int)
    ph = PhysicsConfig(servo_lookahead_s=tau)
    x, _ = lookahead_command(q, np.zeros_like(q), np.zeros_like(q), t, ph, pieces)
    assert np.abs(x - q - tau * 0.2).max() < 1.05  # no impulse: within Δ (m dt ≈ τ)
    after = slice(c + int(round(tau / dt)), c + int(round(2 * tau / dt)))
    spread = np.abs(smoothed(x, dt, tau) - q)[after].max()
    passed = x - np.where(np.abs(x - q - tau * 0.2) > 1e-9, x - q - tau * 0.2, 0.0)
    lagging = np.abs(smoothed(passed, dt, tau) - q)[after].max()
    assert spread < 0.05 and lagging > 0.3, (spread, lagging)
    one = lookahead_command(q, np.zeros_like(q), np.zeros_like(q), t, ph)[0]
    assert np.abs(one - q).max() > 5.0  # one piece: the step inverted as an impulse


def test_the_smoothing_reaches_the_pd_and_the_commands_are_made_for_it(flip_plan, bare):
    """With a lookahead the PD's references are the smoothed stream of commands made for the
    smoothing: close to the commands of a servo without it, once under way; with a lookahead
    of 0 they are that servo's commands, unfiltered."""
    ph = replace(flip_plan.cell().physics, servo_lookahead_s=0.0)
    args = (flip_plan, bare)
    plain = plan_references(*args, ph, "position", "compensated", 1e-3, 0.2)
    sent = np.unique(np.floor(np.maximum(plain.t - ph.latency_s, 0) * ph.servo_rate_hz
                              + 1e-9))
    assert len(np.unique(plain.q_cmd[:, 0])) <= len(sent)  # held samples, not filtered
    smooth = plan_references(*args, replace(ph, servo_lookahead_s=0.03), "position",
                             "compensated", 1e-3, 0.2)
    raw = plan_references(*args, replace(ph, servo_lookahead_s=0.03), "position", "raw",
                          1e-3, 0.2)
    busy = (plain.t > 0.2) & (plain.t < flip_plan.duration)
    rms = lambda d: np.sqrt(np.mean(d[busy] ** 2, axis=0))  # noqa: E731  (rad, per joint)
    made = rms(smooth.q_cmd - plain.q_cmd)
    lagged = rms(raw.q_cmd - plan_references(*args, ph, "position", "raw", 1e-3, 0.2).q_cmd)
    assert np.all(made < 0.2 * lagged), (made, lagged)  # measured 0.06-0.09 x


def test_trials_with_another_lookahead_carry_it_and_are_cached_apart():
    """The nominal servo smooths with servoj's default lookahead (0.1 s); a validation's
    trials with another one (0: none) say so in their physics, and their cache keys
    differ; with the default, the nominal jobs."""
    from flipkit.experiments.perturbations import Perturbations
    from flipkit.experiments.trial_jobs import lookahead_of, servo_physics, trial_jobs, trial_key

    assert PhysicsConfig().servo_lookahead_s == 0.1
    assert servo_physics(None) is None and servo_physics(0.1) is None
    assert servo_physics(0.0) == {"physics.servo_lookahead_s": 0.0}
    assert servo_physics(0.2) == {"physics.servo_lookahead_s": 0.2}
    assert lookahead_of(None) == 0.1 and lookahead_of(0.0) == 0.0
    with pytest.raises(ConfigError, match="lookahead"):
        servo_physics(-1.0)
    plain = trial_jobs("{}", 1, 0, Perturbations(), mode="position")[0]
    bare = trial_jobs("{}", 1, 0, Perturbations(), mode="position",
                      physics=servo_physics(0.0))[0]
    assert "physics" not in plain and bare["physics"] == {"physics.servo_lookahead_s": 0.0}
    assert trial_key(plain) != trial_key(bare)


def test_the_smoothing_starts_from_the_state_held_before_the_plan(flip_plan, bare):
    """Before a plan the servo holds the arm at rest at the plan's first configuration, so
    its smoothed command starts there (not at the first command, whose torque compensation
    and lead it has yet to reach: the arm was kicked ahead and overshot by 5 cm at τ 0.1 s),
    and it tracks the plan's start within a centimetre."""
    from flipkit.simulation.execute import execute_plan

    ph = replace(flip_plan.cell().physics, servo_lookahead_s=0.1)
    refs = plan_references(flip_plan, bare, ph, "position", "compensated", 1e-3, 0.2)
    first = flip_plan.segments[0]
    np.testing.assert_allclose(refs.q_cmd[0], first.q[0], atol=1e-12)
    np.testing.assert_allclose(refs.qd_cmd[0], first.qd[0], atol=1e-12)
    # the first command does differ from the held state (the compensation of q̈(0))
    sent = plan_references(flip_plan, bare, replace(ph, servo_lookahead_s=0.0), "position",
                           "compensated", 1e-3, 0.2).q_cmd[0]
    assert np.abs(sent - first.q[0]).max() > 5e-3
    ex = execute_plan(flip_plan, "position", None, physics=ph, hold=0.0, command="compensated")
    assert ex.errors["go_to_burger"]["max_m"] < 0.015  # measured 9.8 mm
