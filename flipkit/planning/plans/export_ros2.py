"""Write a verified plan as a ROS 2 ``trajectory_msgs/msg/JointTrajectory`` in YAML.

The document is the message as ``ros2 topic pub`` and the ``trajectory`` field of a
``control_msgs/action/FollowJointTrajectory`` goal take it::

    header: {stamp: {sec: 0, nanosec: 0}, frame_id: ''}     # stamp 0: start on receipt
    joint_names: [shoulder_pan_joint, ..., wrist_3_joint]    # ur_description's names
    points:
    - positions: [6 rad]
      velocities: [6 rad/s]
      time_from_start: {sec: s, nanosec: ns}

The points are the samples of :func:`flipkit.planning.plans.export.resample` (t_j = j / rate on
the plan's own clock, and the plan's end at T_total, the arm at rest), so the trajectory ends
where the plan does. The message is read back from its own text and checked against the
arm's published limits, with the controller's cubic spline between points, before it is
written (:func:`~flipkit.planning.plans.export.check_written`). Positions and velocities are the plan's as planned: the servo compensation of the
URScript export (:mod:`flipkit.planning.plans.servo_command`) is not applied, since the
controller that follows the message interpolates between points itself. Numbers are written
in full (``repr``, round-trip exact).
"""

from __future__ import annotations

from pathlib import Path

import yaml

from flipkit.errors import ExportError
from flipkit.fileio import write_text
from flipkit.model.robot import Robot
from flipkit.planning.plans.export import check_rate, check_written, resample
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify import TOL, require_verified

# The UR arms' joints as ur_description names them (ROS-Industrial universal_robot and
# Universal_Robots_ROS2_Description, urdf/ur_macro.xacro, without a tf_prefix), base first;
# also the names of the plan's URDF (example-robot-data's copy of ur_description).
JOINT_NAMES = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
               "wrist_2_joint", "wrist_3_joint")
MESSAGE = "trajectory_msgs/msg/JointTrajectory"


def duration(t: float) -> dict:
    """``builtin_interfaces/Duration`` of ``t`` s (≥ 0): ``{sec, nanosec}``, to the ns."""
    ns = round(t * 1e9)
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def trajectory(plan: Plan, rate: float, *, force: bool = False) -> dict:
    """The JointTrajectory message of ``plan`` sampled at ``rate`` (Hz), as a dict.

    Raises:
        ExportError: The plan's URDF names its joints otherwise than :data:`JOINT_NAMES`.
        FlipkitError: As :func:`~flipkit.planning.plans.export.resample`.
    """
    t, q, qd = resample(plan, check_rate("ros2", rate), force=force)
    names = tuple(Robot(plan.cell(), with_burger=False).model.names[1:])
    if names != JOINT_NAMES:
        raise ExportError(f"ros2 export needs the joints {', '.join(JOINT_NAMES)}; the plan's "
                          f"URDF has {', '.join(names)}")
    samples = list(zip((round(x * 1e9) for x in t), q, qd))
    points = [{"positions": [float(x) for x in pos], "velocities": [float(x) for x in vel],
               "time_from_start": duration(ns / 1e9)} for ns, pos, vel in samples]
    return {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
            "joint_names": list(JOINT_NAMES), "points": points}


def ros2_text(plan: Plan, message: dict, rate: float, where: str) -> str:
    """The YAML document, after comment lines that say what it is."""
    made = plan.created_by
    head = [f"# {MESSAGE} from flipkit export --format ros2: {where}, a {plan.behavior} plan "
            f"of {len(plan.segments)} segments, {plan.duration:.3f} s",
            f"# planned by flipkit {made['flipkit']} (git {made['git']}); passed flipkit "
            "verify before this was written",
            f"# {len(message['points'])} points: samples at {rate:g} Hz and the plan's end; "
            "rad, rad/s; not run on a robot by flipkit"]
    body = yaml.safe_dump(message, sort_keys=False, default_flow_style=None, width=1000)
    return "\n".join(head) + "\n" + body


def write_ros2(plan: Plan, path, rate: float, *, force: bool = False, tol: float = TOL,
               where=None, on_check=None) -> int:
    """Verify ``plan``, then write its JointTrajectory YAML to ``path``; return the point count.

    Args:
        plan: The plan. path: Output file (.yaml). rate: Sampling rate (Hz).
        force: Export even a plan whose status is not ``solved`` (it must still verify).
        tol: Verification tolerance (:data:`flipkit.planning.plans.verify.TOL`).
        on_check: Called with the stream's check
            (:class:`~flipkit.planning.plans.stream_check.StreamCheck`) once it passed.
        where: How messages and the file's header name the plan; default ``"plan"``.

    Raises:
        VerificationError: The plan fails verification; nothing is written.
        ExportError: The message as written fails its stream check; nothing is written.
        FlipkitError: As :func:`trajectory`, or the file cannot be written.
    """
    where = "plan" if where is None else str(where)
    message = trajectory(plan, rate, force=force)
    require_verified(plan, where, force=force, tol=tol)
    text = ros2_text(plan, message, rate, Path(where).name)
    checked = check_written(plan, "ros2", text, where)
    if on_check is not None:
        on_check(checked)
    write_text(Path(path), text)
    return len(message["points"])
