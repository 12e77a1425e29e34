"""Export formats a robot cell loads (issue 33, item 1): every output is parsed back.

URScript: the header and the def ... end structure, the start guard, one servoj per
resampled sample, its numbers equal to the stream to the printed precision and inside the
joint limits; the compensated stream against the servo model recomputed here. ROS 2: the
YAML loads, its joint names are ur_description's, its times increase strictly and its
positions are the resampled ones. A tampered plan and bad options are refused by every
format in one line, nothing written. The plans are test_plan's synthetic translate (no
optimiser) and, once, conftest's flip.
"""

import json
import re

import numpy as np
import pinocchio as pin
import pytest
import yaml
from test_plan import translate_plan

from flipkit.cli import export as cli_export
from flipkit.behaviors.models import Models
from flipkit.cli import main
from flipkit.config import CellConfig, PhysicsConfig
from flipkit.errors import ExportError, VerificationError
from flipkit.model.robot import Robot
from flipkit.planning.plans import export, export_ros2, export_urscript, servo_command
from flipkit.planning.plans.export_ros2 import write_ros2
from flipkit.planning.plans.export_urscript import ServoOptions, write_urscript
from flipkit.planning.plans.plan_file import Plan

# ur_description (ROS-Industrial universal_robot, Universal_Robots_ROS2_Description), base first
UR_JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
             "wrist_2_joint", "wrist_3_joint"]
HALF_ULP = 0.5e-8 + 1e-12  # rad: the program prints 8 decimals
NUM = r"-?\d+(?:\.\d+)?(?:e-?\d+)?"
VEC = rf"\[({NUM}(?:, {NUM}){{5}})\]"
SERVOJ = re.compile(rf"^  servoj\({VEC}, 0, 0, ({NUM}), ({NUM}), ({NUM})\)$")


@pytest.fixture(scope="module")
def plan():
    return translate_plan(Models(CellConfig()))  # 1.0 + 0.8 s, carries the burger; 0.1 s


@pytest.fixture(scope="module")
def robot(plan):
    return Robot(plan.cell(), with_burger=False)


def vector(text):
    return np.array([float(x) for x in text.split(", ")])


def parse_urscript(text: str) -> dict:
    """The program's parts; asserts its shape: comments, one def ... end with balanced
    blocks, two-space indentation, the guard before the first servoj, stopj last."""
    lines = text.rstrip("\n").split("\n")
    head = [ln for ln in lines if ln.startswith("#")]
    assert lines[:len(head)] == head and len(head) >= 3
    body = lines[len(head):]
    match = re.fullmatch(r"def (flipkit_\w+)\(\):", body[0])
    assert match and body[-1] == "end" and body[-2].startswith("  stopj(")
    depth = 0
    for ln in body:
        stripped = ln.strip()
        indent = len(ln) - len(ln.lstrip(" "))
        if stripped == "end":
            depth -= 1
        assert indent == 2 * depth, ln
        if re.match(r"(def|while|if) .*:$", stripped):
            depth += 1
    assert depth == 0
    where = [i for i, ln in enumerate(body) if "servoj(" in ln]
    first, servo = where[0], [body[i] for i in where]
    assert where == list(range(first, first + len(where)))  # one block, then stopj
    parsed = [SERVOJ.match(ln) for ln in servo]
    assert all(parsed), [ln for ln, m in zip(servo, parsed) if not m][:1]
    guard = body[1:first]
    start = re.fullmatch(rf"  q_start = {VEC}", guard[0])
    tol = re.fullmatch(rf"    if norm\(q_now\[j\] - q_start\[j\]\) > ({NUM}):", guard[4])
    assert start and tol, guard
    assert guard[1:4] == ["  q_now = get_actual_joint_positions()", "  j = 0", "  while j < 6:"]
    assert guard[5].startswith('      popup("flipkit: the arm is not at the plan') \
        and "error=True" in guard[5]
    assert guard[6:10] == ["      halt", "    end", "    j = j + 1", "  end"]
    return {"name": match.group(1), "head": head, "q_start": vector(start.group(1)),
            "tol": float(tol.group(1)), "q": np.array([vector(m.group(1)) for m in parsed]),
            "t": {float(m.group(2)) for m in parsed}, "lookahead": {float(m.group(3)) for m in parsed},
            "gain": {float(m.group(4)) for m in parsed}}


def within_limits(robot, q):
    assert np.all(q >= robot.q_min) and np.all(q <= robot.q_max)


# ------------------------------------------------------------------ URScript
def test_urscript_streams_the_plans_q_and_ends_at_rest(plan, robot, tmp_path):
    """The default command is the plan's own q at t_j = j / rate, through the plan's end
    (1.8 s is sample 225 at 125 Hz), then the final configuration once more: at rest."""
    path = tmp_path / "flip.script"
    assert ServoOptions().command == "raw"
    assert write_urscript(plan, path, 125.0) == 227
    prog = parse_urscript(path.read_text())
    t = np.arange(227) / 125.0
    q = export.evaluate(plan, np.minimum(t, plan.duration))[0]
    assert prog["name"] == "flipkit_translate" and prog["q"].shape == q.shape == (227, 6)
    assert np.abs(prog["q"] - q).max() <= HALF_ULP
    assert np.abs(prog["q"][-2:] - plan.segments[-1].q[-1]).max() <= HALF_ULP
    assert np.abs(prog["q_start"] - plan.segments[0].q[0]).max() <= HALF_ULP
    assert np.abs(prog["q"][0] - prog["q_start"]).max() == 0.0
    assert prog["tol"] == 0.01 and prog["t"] == {0.008}
    assert prog["lookahead"] == {0.1} and prog["gain"] == {300.0}
    assert "command raw" in "\n".join(prog["head"])
    within_limits(robot, prog["q"])


def test_urscript_options_and_rate(plan, tmp_path):
    path = tmp_path / "flip.urscript"
    options = ServoOptions(lookahead=0.05, gain=1000, command="raw", start_tol=0.02)
    write_urscript(plan, path, 500.0, options)
    prog = parse_urscript(path.read_text())
    assert prog["q"].shape[0] == 900 + 2  # 1.8 s at 500 Hz, its end and the rest sample
    assert prog["t"] == {0.002} and prog["lookahead"] == {0.05} and prog["gain"] == {1000.0}
    assert prog["tol"] == 0.02


@pytest.mark.parametrize("rate", [125.0, 500.0])
def test_the_compensated_stream_is_the_servo_models_inverse(plan, robot, rate):
    """The first segment is a cubic: the plan 8 ms (latency) + half a servo period ahead is
    known in closed form, u between nodes is linear, and Kp (q_c − q_d) + g_c(q_d)
    must give back the plan's torque u_d (the burger's weight, which the controller's model
    lacks, makes the offset non-zero). The stream is q_c made for servoj's smoothing at the
    default lookahead (0.1 s): x = q_c + τ q̇_c, q̇_c by differences within the segment."""
    t_sent, q_cmd, _ = export_urscript.servo_stream(plan, rate, "compensated")
    physics, seg = PhysicsConfig(), plan.segments[0]
    lead = physics.latency_s + 0.5 / rate
    t = t_sent + lead
    first = t <= seg.T
    s, d = t[first] / seg.T, seg.q[-1] - seg.q[0]
    q_d = seg.q[0] + np.outer(3 * s**2 - 2 * s**3, d)
    u_d = np.column_stack([np.interp(t[first], seg.t, seg.u[:, j]) for j in range(6)])
    data = robot.model.createData()
    g_c = np.array([pin.computeGeneralizedGravity(robot.model, data, x) for x in q_d])
    kp = np.asarray(physics.kp)
    q_c = q_d + (u_d - g_c) / kp
    tau = physics.servo_lookahead_s
    assert tau == 0.1
    x = q_c + tau * np.gradient(q_c, t[first], axis=0)
    # the last τ/2 (and a sample) carry the spread step to the next segment
    inner = t[first] < seg.T - tau / 2 - 1.0 / rate
    np.testing.assert_allclose(q_cmd[first][inner], x[inner], atol=1e-9)
    assert np.abs(q_c - q_d).max() > 1e-4


def test_the_compensated_stream_of_a_flip_is_refused_by_the_arms_limits(flip_plan, tmp_path,
                                                                        capsys):
    """Where the plan's torque steps (the segments' joins) the compensated stream steps too,
    faster than the UR10's published joint speeds: refused in one line naming the joint, the
    time and the amount, nothing written; the raw stream of the same plan is written."""
    src = flip_plan.to_json(tmp_path / "flip.json")
    for rate in ("125", "500"):
        out = tmp_path / f"c{rate}.script"
        assert main(["export", str(src), "--format", "urscript", "--rate", rate, "--out",
                     str(out), "--command", "compensated"]) == 2
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and "nothing written" in err and not out.exists()
        assert re.search(r"speed: \w+_joint at [\d.]+ rad/s near t = [\d.]+ s, [\d.]+x the UR10",
                         err), err
        assert main(["export", str(src), "--format", "urscript", "--rate", rate, "--out",
                     str(out)]) == 0
        assert "stream checked" in capsys.readouterr().out


def test_a_flip_streams_within_the_arms_limits(flip_plan, tmp_path):
    """The raw stream as written, parsed here on its own: within 100 % of UR's published
    speeds (the plan keeps to 95 %), starting at the guard's q_start and ending at rest."""
    path = tmp_path / "flip.script"
    n = write_urscript(flip_plan, path, 500.0)
    prog = parse_urscript(path.read_text())
    assert prog["q"].shape == (n, 6)
    assert np.abs(prog["q_start"] - flip_plan.segments[0].q[0]).max() <= HALF_ULP
    robot = Robot(flip_plan.cell(), with_burger=False)
    within_limits(robot, prog["q"])
    speed = np.abs(np.diff(prog["q"], axis=0)) * 500.0
    assert np.all(speed <= np.radians([120, 120, 180, 180, 180, 180]))
    assert np.all(prog["q"][-1] == prog["q"][-2])


def test_a_stream_over_the_arms_speed_is_refused_with_nothing_written(plan, tmp_path):
    """A stream that asks a joint for more than the UR10 publishes never reaches a file: one
    sample moved 0.05 rad (6 rad/s at 125 Hz on the elbow)."""
    from flipkit.planning.plans import stream_check

    t, q, _ = export_urscript.servo_stream(plan, 125.0)
    q = q.copy()
    q[40, 2] += 0.05
    report = stream_check.check_stream(plan, t, q, evaluate=export.evaluate)
    assert not report.ok and report.speed_ratio > 1.9  # 6.25 rad/s on a 3.14 rad/s joint
    assert report.failures[0].startswith("speed: elbow_joint at")
    assert "t = 0.312 s" in report.failures[0] or "t = 0.320 s" in report.failures[0]
    with pytest.raises(ExportError, match="nothing written: speed: elbow_joint"):
        stream_check.require_stream(report, "p.json")
    bad = export_urscript.urscript_text(plan, t, q, 125.0, ServoOptions(), "p.json")
    with pytest.raises(ExportError, match="elbow_joint"):
        export.check_written(plan, "urscript", bad, "p.json")
    assert any("deviation" in f for f in report.failures)  # 0.05 rad moves the blade cm


# ------------------------------------------------------------------ ROS 2
def test_ros2_yaml_is_the_resampled_trajectory(plan, robot, tmp_path):
    path = tmp_path / "flip.yaml"
    # 227 on the grid, 15 of them within a quarter period of a node (left out), 37 nodes off
    # the grid, the end
    assert write_ros2(plan, path, 126.0) == 227 - 15 + 37 + 1
    doc = yaml.safe_load(path.read_text())
    assert list(doc) == ["header", "joint_names", "points"]
    assert doc["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    assert doc["joint_names"] == UR_JOINTS == list(robot.model.names)[1:]
    pts = doc["points"]
    assert all(set(p) == {"positions", "velocities", "time_from_start"} for p in pts)
    stamp = [p["time_from_start"] for p in pts]
    assert all(isinstance(s["sec"], int) and 0 <= s["nanosec"] < 10**9 for s in stamp)
    ns = np.array([s["sec"] * 10**9 + s["nanosec"] for s in stamp])
    assert ns[0] == 0 and np.all(np.diff(ns) > 0) and ns[-1] == 1_800_000_000
    t, q, qd = export.resample(plan, 126.0)
    np.testing.assert_array_equal(ns, np.round(t * 1e9))
    pos, vel = (np.array([p[k] for p in pts]) for k in ("positions", "velocities"))
    np.testing.assert_array_equal(pos, q)  # repr: round-trip exact
    np.testing.assert_array_equal(vel, qd)
    np.testing.assert_allclose(pos[-1], plan.segments[-1].q[-1], rtol=0, atol=1e-12)
    assert np.abs(vel[-1]).max() < 1e-9  # ends at rest
    within_limits(robot, pos)
    # the velocities are the positions' slope: a spline through them is the plan's q
    from scipy.interpolate import CubicHermiteSpline
    mid = (t[:-1] + t[1:]) / 2
    spline = CubicHermiteSpline(t, pos, vel, axis=0)
    assert np.abs(spline(mid) - export.evaluate(plan, mid)[0]).max() < 1e-6


# ------------------------------------------------------------------ refusals
@pytest.fixture(scope="module")
def tampered(plan, tmp_path_factory):
    """One joint angle moved by 0.01 rad: verify fails the plan."""
    path = plan.to_json(tmp_path_factory.mktemp("tampered") / "plan.json")
    doc = json.loads(path.read_text())
    doc["segments"][0]["q"][7][2] += 0.01
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("fmt, name", [("csv", "o.csv"), ("urscript", "o.script"),
                                       ("ros2", "o.yaml")])
def test_a_tampered_plan_is_refused_by_every_format(tampered, tmp_path, capsys, fmt, name):
    out = tmp_path / name
    for extra in ([], ["--force"]):
        assert main(["export", str(tampered), "--format", fmt, "--out", str(out), *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and "plan fails" in err and "refused" in err
        assert not out.exists()
    write = {"csv": export.write_csv, "urscript": write_urscript, "ros2": write_ros2}[fmt]
    with pytest.raises(VerificationError, match="plan fails"):
        write(Plan.load(tampered), out, 125.0)
    assert not out.exists()


@pytest.mark.parametrize("args, words", [
    (["--format", "pdf", "--out", "o.pdf"], ["export format 'pdf'", "'csv', 'urscript', 'ros2'"]),
    (["--format", "urscript", "--out", "o.script", "--rate", "fast"], ["--rate", "'fast'"]),
    (["--format", "ros2", "--out", "o.yaml", "--rate", "0"], ["--rate", "[1, 10000] Hz"]),
    (["--format", "ros2", "--out", "o.yaml", "--rate", "10"], ["--rate", "[100, 1000] Hz"]),
    (["--format", "csv", "--out", "o.csv", "--rate", "2000"], ["--rate", "[100, 1000] Hz"]),
    (["--format", "urscript", "--out", "o.script", "--rate", "300"], ["125, 250, 500 Hz"]),
    (["--format", "urscript", "--out", "o.script", "--gain", "50"], ["--gain", "[100, 2000]"]),
    (["--format", "urscript", "--out", "o.script", "--gain", "big"], ["--gain", "'big'"]),
    (["--format", "urscript", "--out", "o.script", "--lookahead", "0.5"], ["--lookahead", "0.2"]),
    (["--format", "urscript", "--out", "o.script", "--start-tol", "nan"], ["--start-tol"]),
    (["--format", "urscript", "--out", "o.script", "--command", "comp"],
     ["position command 'comp'", "'raw', 'compensated'"]),
    (["--format", "ros2", "--out", "o.yaml", "--gain", "300"], ["--gain", "urscript only"]),
    (["--format", "ros2", "--out", "o.script"], ["--out", ".yaml"]),
    (["--format", "urscript"], ["--out"]),
    (["--format", "urscript", "--csv", "o.csv"], ["--csv"]),
])
def test_bad_options_one_line_nothing_written(plan, tmp_path, capsys, monkeypatch, args, words):
    path = plan.to_json(tmp_path / "plan.json")
    monkeypatch.chdir(tmp_path)
    assert main(["export", str(path), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("flipkit: error:") and "\n" not in err and "Traceback" not in err
    assert all(w in err for w in words), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.json"]


def test_the_command_lines_constants_are_the_librarys():
    """The CLI states ranges and defaults without importing the models; they must agree."""
    defaults = ServoOptions()
    for key, (_, rng, _, default, _) in cli_export.SERVO.items():
        assert default == getattr(defaults, key)
        assert rng == getattr(export_urscript, {"lookahead": "LOOKAHEAD_RANGE", "gain": "GAIN_RANGE",
                                                "start_tol": "START_TOL_RANGE"}[key])
    assert cli_export.COMMANDS == servo_command.COMMANDS
    assert defaults.command == servo_command.DEFAULT_COMMAND == servo_command.COMMANDS[0] == "raw"
    assert cli_export.RATE_RANGE == export.RATE_RANGE
    assert cli_export.STREAM_RATES == export.STREAM_RATES
    assert cli_export.SERVO_RATES == export_urscript.SERVO_RATES


def test_a_node_a_few_nanoseconds_off_the_grid_takes_the_grid_samples_place(plan):
    """A segment whose duration falls 2 ns short of the grid puts every later node 2 ns off
    it: the grid sample there gives way to the node, so no two samples are closer than a
    quarter period (written to the ns they would be one time stamp, and a spline through them
    asks for unbounded acceleration); every node stays among the samples."""
    from dataclasses import replace

    seg = plan.segments[0]
    T = 0.9 - 2e-9
    short = replace(plan, segments=[replace(seg, T=T, t=seg.t[0] + (seg.t - seg.t[0]) * T / seg.T)])
    t, q, qd = export.resample(short, 500.0)
    assert np.diff(t).min() >= export.MIN_GAP / 500.0 - 1e-15
    nodes = short.segments[0].t - short.segments[0].t[0]
    assert np.abs(t[:, None] - nodes[None, :]).min(axis=0).max() == 0.0
    assert t[-1] == T
    on_grid = np.isclose(nodes * 500.0, np.round(nodes * 500.0), rtol=0, atol=1e-5)
    assert on_grid.sum() >= 5  # nodes just off the grid: the case at stake
    near = np.abs(t[:, None] - nodes[None, on_grid]) < 1e-6
    assert np.all(near.sum(axis=0) == 1)  # one sample there, the node's own
