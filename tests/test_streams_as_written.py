"""Every export checked as written: each format of a solved flip parsed back here on its own
and held to UR's published limits, the start guard and the plan's ends; the simulation's
position mode sends exactly the URScript's targets; the arm's safety system stops a run."""

from dataclasses import replace

import numpy as np
import pytest
import yaml

from flipkit.cli import main
from flipkit.config import arm
from flipkit.experiments.perturbations import Perturbations
from flipkit.experiments.trial_jobs import protective_stop
from flipkit.experiments.trials import run_trial, trial_jobs
from flipkit.model.robot import Robot
from flipkit.planning.plans.export_urscript import write_urscript
from flipkit.planning.plans.stream_parse import parse_urscript
from flipkit.simulation.control import plan_references
from flipkit.simulation.safety import SafetyMonitor

PUBLISHED = np.radians([120, 120, 180, 180, 180, 180])  # rad/s, UR10 (CB3) and UR10e


@pytest.mark.parametrize("fmt, rate, suffix", [("urscript", "125", ".script"), ("csv", "125", ".csv"),
                                               ("ros2", "125", ".yaml"),
                                               ("urscript", "500", ".script"),
                                               ("ros2", "500", ".yaml"), ("csv", "500", ".csv")])
def test_each_format_of_a_flip_is_within_the_arm_as_written(flip_plan, tmp_path, capsys, fmt,
                                                            rate, suffix):
    src = flip_plan.to_json(tmp_path / "flip.json")
    out = tmp_path / f"flip{suffix}"
    assert main(["export", str(src), "--format", fmt, "--rate", rate, "--out", str(out)]) == 0
    assert "stream checked against the ur10 profile" in capsys.readouterr().out
    text = out.read_text()
    first, last = flip_plan.segments[0].q[0], flip_plan.segments[-1].q[-1]
    if fmt == "urscript":  # servoj holds each target for its period
        targets = np.array([[float(x) for x in line.split("[")[1].split("]")[0].split(",")]
                            for line in text.splitlines() if line.startswith("  servoj(")])
        speed = np.abs(np.diff(targets, axis=0)) * float(rate)
        assert np.all(speed <= PUBLISHED) and np.allclose(targets[-1], targets[-2], atol=0)
        assert np.abs(targets[0] - first).max() < 1e-8 and np.abs(targets[-1] - last).max() < 1e-8
        return
    if fmt == "ros2":
        points = yaml.safe_load(text)["points"]
        t = np.array([p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"]
                      for p in points])
        q = np.array([p["positions"] for p in points])
        qd = np.array([p["velocities"] for p in points])
    else:
        rows = np.loadtxt(out, delimiter=",", skiprows=1)
        t, q, qd = rows[:, 0], rows[:, 1:7], rows[:, 7:13]
    assert np.all(np.abs(qd) <= PUBLISHED) and np.abs(qd[-1]).max() < 1e-9
    assert np.all(np.abs(np.diff(q, axis=0)) / np.diff(t)[:, None] <= PUBLISHED)
    assert t[-1] == pytest.approx(flip_plan.duration, abs=1e-9)
    assert np.abs(q[0] - first).max() == 0 and np.abs(q[-1] - last).max() < 1e-12


def test_position_mode_sends_exactly_the_urscript_targets(flip_plan, tmp_path):
    """With the servo's smoothing off, the command the simulated PD holds at each servo
    period is the exported program's target, to its printed precision."""
    path = tmp_path / "flip.script"

    write_urscript(flip_plan, path, 125.0)
    stream = parse_urscript(path.read_text())
    robot = Robot(flip_plan.cell(), with_burger=False)
    physics = replace(flip_plan.cell().physics, servo_lookahead_s=0.0, servo_rate_hz=125.0)
    refs = plan_references(flip_plan, robot, physics, "position", "raw", 1e-3, 0.1)
    k = np.round((stream.t + physics.latency_s) / 1e-3).astype(int) + 1  # inside each hold
    k = k[k < len(refs.t)]
    np.testing.assert_allclose(refs.q_cmd[k], stream.q[:len(k)], rtol=0, atol=0.6e-8)


def test_the_safety_monitor_stops_at_the_first_excess():
    robot = Robot()
    monitor = SafetyMonitor(robot)
    q, slow = robot.q_home, 0.5 * robot.qd_limit
    monitor(0.0, q, slow, 10.0)
    assert monitor.stop is None and not monitor.tripped
    assert monitor.peaks["joint_speed"] == pytest.approx(0.5)
    fast = slow.copy()
    fast[4] = 1.05 * robot.qd_limit[4]
    monitor(0.1, q, fast, 10.0)
    assert monitor.tripped and monitor.stop["quantity"] == "joint_speed"
    assert monitor.stop["joint"] == "wrist_2_joint" and monitor.stop["time_s"] == 0.1
    monitor(0.2, q, slow, 300.0)  # a later excess is a peak, not the stop
    assert monitor.stop["quantity"] == "joint_speed" and monitor.peaks["tcp_force"] == 300.0
    pressed = SafetyMonitor(robot, enabled=False)
    pressed(0.0, q, slow, 260.0)
    assert pressed.stop["quantity"] == "tcp_force" and not pressed.tripped


def test_a_protective_stop_fails_the_stages_not_yet_ended():
    ok = {"scoop": True, "pickup": True, "flip": True}
    safety = {"stop": {"time_s": 1.2, "quantity": "tcp_force", "value": 300.0,
                       "limit": 250.0, "joint": None}}
    ends = {"scoop": 1.1, "pickup": 1.35, "flip": 3.0}
    ok2, ind, failure = protective_stop(ok, dict(ok), None, safety, ends)
    assert ok2 == {"scoop": True, "pickup": False, "flip": False} and ind == ok2
    assert failure["stage"] == "pickup" and failure["reason"] == "protective_stop"
    assert failure["amount"] == pytest.approx(1.2) and "tcp_force 300" in failure["detail"]
    earlier = {"stage": "scoop", "reason": "overlap", "amount": 0.3}
    assert protective_stop(ok, dict(ok), earlier, safety, ends)[2] is earlier
    assert protective_stop(ok, dict(ok), None, {"stop": None}, ends) == (ok, ok, None)


def test_a_run_over_the_preset_is_a_protective_stop(flip_plan_file, monkeypatch):
    """A preset whose TCP speed the flip exceeds (0.5 m/s): the run ends at the excess and
    the trial fails there, reason protective_stop; the nominal preset lets it through."""
    text = flip_plan_file.read_text()
    job = trial_jobs(text, 1, 0, Perturbations(), mode="position")[0]
    nominal = run_trial(job)
    assert nominal["safety"]["stop"] is None
    tight = replace(arm.LEAST_RESTRICTED, tcp_speed=0.5)
    profile = replace(arm.PROFILES["ur10"], presets={**arm.PROFILES["ur10"].presets,
                                                     "least_restricted": tight})
    monkeypatch.setitem(arm.PROFILES, "ur10", profile)
    out = run_trial(job)
    stop = out["safety"]["stop"]
    assert stop["quantity"] == "tcp_speed" and stop["value"] > 0.5
    assert out["failure"]["reason"] == "protective_stop" and not out["ok"]["flip"]
    assert out["safety"]["peaks"]["tcp_speed"] < nominal["safety"]["peaks"]["tcp_speed"]
