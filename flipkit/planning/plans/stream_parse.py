"""Read an exported command stream back from its own text, as a controller would.

Each export is checked as written (:mod:`~flipkit.planning.plans.stream_check`): the text is
made, parsed back here, checked, and only then written. The parsers read exactly what the
files say: the URScript's ``q_start`` and ``servoj`` lines (its period, from ``t``), the CSV's
rows, the ROS 2 message's points. Each returns a :class:`Stream`.
"""

from __future__ import annotations

import io
import re
from dataclasses import dataclass

import numpy as np
import yaml

from flipkit.errors import ExportError

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_VECTOR = rf"\[\s*({_NUMBER}(?:\s*,\s*{_NUMBER})*)\s*\]"
_SERVOJ = re.compile(rf"^\s*servoj\({_VECTOR},\s*({_NUMBER}),\s*({_NUMBER}),\s*({_NUMBER}),")
_START = re.compile(rf"^\s*q_start\s*=\s*{_VECTOR}\s*$")


@dataclass(frozen=True)
class Stream:
    """A stream as its file states it.

    Attributes:
        t: Sample times (s, from the first). q: Positions (n×nq, rad). qd: Velocities
            (n×nq, rad/s) or ``None`` (URScript sends positions only). interpolation:
            ``hold`` (servoj) or ``cubic`` (CSV, ROS 2). q_start: A start guard's
            configuration (URScript), else ``None``.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray | None
    interpolation: str
    q_start: np.ndarray | None = None


def _floats(text: str) -> list:
    return [float(x) for x in text.split(",")]


def parse_urscript(text: str) -> Stream:
    """The ``servoj`` targets of a flipkit URScript program, each held for its ``t``.

    Raises:
        ExportError: No ``q_start`` or no ``servoj`` line, or periods that differ.
    """
    start, targets, periods = None, [], set()
    for line in text.splitlines():
        if (m := _START.match(line)) is not None:
            start = np.array(_floats(m.group(1)))
        elif (m := _SERVOJ.match(line)) is not None:
            targets.append(_floats(m.group(1)))
            periods.add(float(m.group(4)))
    if start is None or not targets:
        raise ExportError("the URScript program has no q_start or no servoj line")
    if len(periods) != 1:
        raise ExportError(f"the URScript program's servoj periods differ: {sorted(periods)}")
    period = periods.pop()
    q = np.array(targets)
    return Stream(period * np.arange(len(q)), q, None, "hold", start)


def parse_csv(text: str) -> Stream:
    """The rows ``t,q1..qn,qd1..qn`` of a flipkit CSV (a header line first)."""
    data = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1, ndmin=2)
    nq = (data.shape[1] - 1) // 2
    return Stream(data[:, 0], data[:, 1:1 + nq], data[:, 1 + nq:], "cubic")


def parse_ros2(text: str) -> Stream:
    """The points of a JointTrajectory YAML (``time_from_start`` in sec and nanosec)."""
    message = yaml.safe_load(text)
    points = message["points"]
    t = np.array([p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"]
                  for p in points])
    return Stream(t, np.array([p["positions"] for p in points], float),
                  np.array([p["velocities"] for p in points], float), "cubic")


PARSERS = {"urscript": parse_urscript, "csv": parse_csv, "ros2": parse_ros2}
"""The parser of each export format."""

__all__ = ["PARSERS", "Stream", "parse_csv", "parse_ros2", "parse_urscript"]
