"""The arm profile (flipkit.config.arm): UR's published limits, held by the model, recorded
by the plan file, checked by verify; a URDF or a plan file cannot loosen them."""

import json
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from test_plan import translate_plan

from flipkit.behaviors.models import Models
from flipkit.cli import main
from flipkit.config import CellConfig, RobotConfig
from flipkit.config import arm
from flipkit.errors import ConfigError, InvalidChoiceError, PlanFileError
from flipkit.model.robot import Robot
from flipkit.model.tool_motion import ToolMotion
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify import verify_plan


def test_the_profiles_are_urs_published_numbers():
    for name in ("ur10", "ur10e"):
        p = arm.arm_profile(name)
        np.testing.assert_allclose(p.qd_max, np.radians([120, 120, 180, 180, 180, 180]))
        np.testing.assert_allclose(p.q_range, np.radians([360] * 6))
        assert p.u_max == (330.0, 330.0, 150.0, 56.0, 56.0, 56.0) and p.qdd_max is None
        assert "joint_limits.yaml" in p.sources["joints"]
    assert arm.DEFAULT_PROFILE == "ur10" and arm.DEFAULT_PRESET == "least_restricted"
    lr = arm.arm_profile("ur10").preset("least_restricted")
    assert (lr.tcp_speed, lr.tcp_force, lr.momentum, lr.power) == (5.0, 250.0, 100.0, 1000.0)


def test_bad_names_list_the_choices():
    with pytest.raises(InvalidChoiceError, match="'ur10', 'ur10e'"):
        arm.arm_profile("ur5")
    with pytest.raises(InvalidChoiceError, match="'default', 'least_restricted'"):
        RobotConfig(safety_preset="loose")
    for margin in (0.0, 1.01, float("nan"), True):
        with pytest.raises(ConfigError, match="speed_margin"):
            RobotConfig(speed_margin=margin)


def _urdf_with_speeds(tmp_path, speed: float) -> str:
    text = Path(Robot().urdf).read_text()
    path = tmp_path / f"ur10_{speed:g}.urdf"
    path.write_text(re.sub(r'velocity="[^"]*"', f'velocity="{speed}"', text))
    return str(path)


def test_a_urdf_looser_than_the_arm_is_refused(tmp_path):
    """example-robot-data's own URDF rounds UR's speeds up (2.16, 3.2 rad/s): the profile cuts
    them. A URDF of one's own that claims more than the arm is refused, naming the joint."""
    raw = pin.buildModelFromUrdf(Robot().urdf)
    assert raw.velocityLimit[0] == pytest.approx(2.16)  # the file as shipped
    robot = Robot()
    np.testing.assert_allclose(robot.model.velocityLimit, robot.qd_limit)
    np.testing.assert_allclose(robot.qd_max, 0.9 * robot.qd_limit)
    fast = _urdf_with_speeds(tmp_path, 10.0)
    with pytest.raises(ConfigError, match=r"shoulder_pan_joint's speed limit 10 rad/s exceeds "
                                          r"the UR10 \(CB3\)'s published 2.094"):
        Robot(CellConfig(robot=RobotConfig(urdf=fast)))
    slow = Robot(CellConfig(robot=RobotConfig(urdf=_urdf_with_speeds(tmp_path, 1.5))))
    np.testing.assert_allclose(slow.qd_max, 1.5)  # a slower arm of one's own is kept


def test_the_plan_records_the_arm_and_a_file_cannot_loosen_it(tmp_path, capsys):
    plan = translate_plan(Models(CellConfig()))
    path = plan.to_json(tmp_path / "p.json")
    doc = json.loads(path.read_text())
    assert doc["robot"]["arm"] == {"profile": "ur10", "speed_margin": 0.9,
                                   "safety_preset": "least_restricted"}
    assert Plan.load(path).cell().robot.speed_margin == 0.9
    for key, value, words in (("speed_margin", 1.5, "speed_margin"),
                              ("profile", "ur99", "arm profile 'ur99'"),
                              ("safety_preset", ["x"], "robot.arm.safety_preset")):
        bad = json.loads(path.read_text())
        bad["robot"]["arm"][key] = value
        out = tmp_path / f"bad_{key}.json"
        out.write_text(json.dumps(bad))
        with pytest.raises(PlanFileError, match=re.escape(words)):
            Plan.load(out)
        assert main(["verify", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and "Traceback" not in err


def test_a_plan_over_the_published_speed_fails_verify_whatever_its_urdf(tmp_path):
    """A base turn at 2.05 rad/s: within UR's 2.094 but over the plans' 90 % (1.885)."""
    models = Models(CellConfig())
    plan = translate_plan(models, turns=(np.array([1.37, 0, 0, 0, 0, 0]),), durations=(1.0,))
    report = verify_plan(plan)
    assert not report.groups["qd_limits"].ok
    assert report.groups["qd_limits"].violation == pytest.approx(1.5 * 1.37 - 0.9 * 2 * np.pi / 3)


def test_tool_motion_matches_finite_differences():
    robot = Robot(CellConfig(), with_burger=True)
    tool = ToolMotion(robot)
    rng = np.random.default_rng(3)
    q, qd = robot.q_home + rng.uniform(-0.3, 0.3, 6), rng.uniform(-1.5, 1.5, 6)
    h = 1e-6

    def points(x):
        M = robot.placement(x)
        return np.vstack([M.translation + M.rotation @ p for p in tool.points]
                         + [tool_flange(robot, x)])

    fd = (points(q + h * qd) - points(q - h * qd)) / (2 * h)
    assert tool.tcp_speed(q, qd) == pytest.approx(np.linalg.norm(fd, axis=1).max(), rel=1e-6)
    data = robot.model.createData()
    com = lambda x: pin.centerOfMass(robot.model, data, x).copy()  # noqa: E731
    mass = sum(inertia.mass for inertia in robot.model.inertias[1:])  # [0]: the fixed base
    v_com = (com(q + h * qd) - com(q - h * qd)) / (2 * h)
    assert tool.momentum(q, qd) == pytest.approx(mass * np.linalg.norm(v_com), rel=1e-6)
    # the safety system's one-pass form gives the same two numbers
    assert tool.speed_and_momentum(q, qd) == pytest.approx(
        (tool.tcp_speed(q, qd), tool.momentum(q, qd)), rel=1e-12)


def tool_flange(robot, q):
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.model.getFrameId("tool0")].translation.copy()


def test_verify_holds_the_plan_to_the_cells_safety_preset(monkeypatch):
    """The preset is looked up by the name the plan records: a preset whose TCP speed is
    below the plan's fails ``safety_limits`` by the excess."""
    models = Models(CellConfig())
    plan = translate_plan(models)
    assert verify_plan(plan).groups["safety_limits"].ok
    tight = replace(arm.LEAST_RESTRICTED, tcp_speed=0.05)
    profile = replace(arm.PROFILES["ur10"], presets={**arm.PROFILES["ur10"].presets,
                                                     "least_restricted": tight})
    monkeypatch.setitem(arm.PROFILES, "ur10", profile)
    group = verify_plan(plan).groups["safety_limits"]
    assert not group.ok and 0.05 < group.violation + 0.05 < 2.0
