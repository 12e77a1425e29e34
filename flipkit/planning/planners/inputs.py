"""Checks of the planner's inputs: positions in the task area, joint vectors in their
limits, start states, the burger's place on the blade; each a one-line error naming what is
wrong."""

from __future__ import annotations

import math

import numpy as np

from flipkit.behaviors.targets import check_heading, default_heading
from flipkit.config import CellConfig
from flipkit.config.checks import real_number, real_vector
from flipkit.errors import AtlasError, ConfigError, UnreachableError, brief
from flipkit.fileio import InputFileError, check_input
from flipkit.model.singular import (ELBOW, SINGULARITY_MARGIN, WRIST, branch_band,
                                    branch_violation)

MAX_BATCH = 5  # burgers per batch (paper Sec. I: 4–5 burgers within 90 s)


def check_position(what: str, value, cell: CellConfig) -> np.ndarray:
    """``value`` as a finite 3-vector (m) inside the task-space box of ``cell``."""
    p = real_vector(what, value, 3, "m")
    lo, hi = np.asarray(cell.limits.p_min), np.asarray(cell.limits.p_max)
    if np.any(p < lo) or np.any(p > hi):
        box = ", ".join(f"{a} in [{lo[k]:g}, {hi[k]:g}]" for k, a in enumerate("xyz"))
        raise UnreachableError(f"{what} ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) m is outside the "
                               f"reachable task area {box} m")
    return p


def check_joint_vector(what: str, value, lo, hi, unit: str) -> np.ndarray:
    """``value`` as a finite joint vector of len(lo) within [lo, hi]."""
    try:
        v = np.asarray(value)
    except (TypeError, ValueError):  # a ragged sequence
        v = np.asarray(None)
    if v.dtype.kind not in "iuf":  # text, booleans, complex numbers, objects
        raise ConfigError(f"{what} must be {len(lo)} numbers ({unit}), got {brief(value)}")
    v = v.astype(float)
    if v.shape != np.shape(lo):
        raise ConfigError(f"{what} must have {len(lo)} values ({unit}), got {v.size}")
    if not np.all(np.isfinite(v)):
        raise ConfigError(f"{what} must be finite, got {v.tolist()}")
    bad = np.flatnonzero((v < lo) | (v > hi))
    if bad.size:
        j = int(bad[0])
        raise ConfigError(f"{what}: joint {j + 1} = {v[j]:.4g} {unit} is outside its limits "
                          f"[{lo[j]:.4g}, {hi[j]:.4g}] {unit}")
    return v


def check_atlas_file(path) -> None:
    """Refuse an atlas file that cannot be read or is not an ``.npz`` archive (a zip), before
    its arrays are loaded (:meth:`flipkit.planning.planners.atlas.Atlas.load`).

    Raises:
        AtlasError: One line naming the file and what to give instead.
    """
    try:
        check_input(path, "atlas")
        with open(path, "rb") as fh:
            magic = fh.read(4)
    except (InputFileError, OSError) as exc:
        raise AtlasError(f"cannot read atlas {path}: "
                         f"{str(exc).split(': ', 1)[-1]}") from None
    if magic != b"PK\x03\x04":  # every .npz is a zip archive
        raise AtlasError(f"cannot read atlas {path}: not an .npz archive; give a file "
                         "written by `flipkit atlas build`, or --no-atlas")


def check_spacing(locations, diameter: float, where: str) -> None:
    """Refuse two burgers closer than one diameter (m): they would overlap on the grill.

    Raises:
        ConfigError: One line naming the two rows (from 1) and their distance.
    """
    for i, a in enumerate(locations):
        for j in range(i + 1, len(locations)):
            b = locations[j]
            gap = math.hypot(a[0] - b[0], a[1] - b[1])
            if gap < diameter:
                raise ConfigError(f"{where}: burgers {i + 1} and {j + 1} are {gap * 1e3:.0f} mm "
                                  f"apart on the grill; they need one burger diameter "
                                  f"({diameter * 1e3:.0f} mm)")


def check_start(robot, q_start=None, qd_start=None, *, what: str = "start configuration",
                branch_side: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The start state (q, q̇) (rad, rad/s) within the joint limits; defaults q_home at rest.

    Args:
        robot: The arm's model (``q_min``, ``q_max``, ``qd_max``, ``q_home``, ``nq``).
        q_start, qd_start: The start state (rad, rad/s), or ``None``: q_home, at rest.
        what: How an error names ``q_start`` (``--start-q`` on the command line).
        branch_side: Also refuse a q3 or q5 within :data:`SINGULARITY_MARGIN` of its
            singular value, or past it (:mod:`flipkit.model.singular`): the planner keeps
            both on q_home's side by that margin, so every plan from there would fail
            ``verify`` (group ``singularity``). The command line asks for it, to refuse such
            a start before any planning.

    Raises:
        ConfigError: One line naming ``what`` (or the start velocity), the joint, its value
            and the range to use.
    """
    q = robot.q_home.copy() if q_start is None else check_joint_vector(
        what, q_start, robot.q_min, robot.q_max, "rad")
    qd = np.zeros(robot.nq) if qd_start is None else check_joint_vector(
        "start velocity", qd_start, -robot.qd_max, robot.qd_max, "rad/s")
    if branch_side and q_start is not None:
        violation = branch_violation(q, robot.q_home, SINGULARITY_MARGIN)[0]
        band = branch_band(robot.q_home, SINGULARITY_MARGIN)
        for col, (j, name) in enumerate(((ELBOW, "q3 (elbow)"), (WRIST, "q5 (wrist)"))):
            if violation[col] > 0:
                lo, hi = band[col]
                raise ConfigError(
                    f"{what}: {name} = {float(q[j]):.3f} rad is within "
                    f"{SINGULARITY_MARGIN:g} rad of its singularity (or past it); give "
                    f"{name.split()[0]} in [{lo:.3f}, {hi:.3f}] rad, the side of q_home")
    return q, qd


def check_on_blade(on_blade, cell: CellConfig) -> np.ndarray:
    """(x, y) (m) of the burger's centre in the blade frame, on the blade, or ConfigError."""
    xy = real_vector("burger position on the blade", on_blade, 2, "m")
    sp = cell.spatula
    if abs(xy[0]) > sp.length / 2 or abs(xy[1]) > sp.width / 2:
        raise ConfigError(f"burger position on the blade must be (x, y) within ±{sp.length / 2}"
                          f", ±{sp.width / 2} m, got {xy.tolist()}")
    return xy


def check_approach_height(height) -> float | None:
    """``None``, or a finite height (m) >= 0 that the go to burger keeps above the grill
    (:attr:`~flipkit.behaviors.spec.Task.approach_height`); ConfigError otherwise."""
    if height is None:
        return None
    h = real_number("approach_height", height, "m")
    if h < 0:
        raise ConfigError(f"approach_height must be a finite height >= 0 m, got {height!r}")
    return h


def resolve_heading(cell: CellConfig, pb, heading) -> tuple[float, bool]:
    """The scoop heading (rad) of a plan at ``pb`` and whether it is the default one (the
    atlas holds plans at the default heading only): ``heading`` checked
    (:func:`~flipkit.behaviors.targets.check_heading`), or ``None`` for the default
    (:func:`~flipkit.behaviors.targets.default_heading`)."""
    default = default_heading(cell, pb)
    if heading is None:
        return default, True
    psi = check_heading(heading)
    return psi, abs(psi - default) < 1e-9


def check_replan(plan, behavior: str, on_blade) -> tuple:
    """The cell of a solved ``behavior`` plan to re-plan, and the sensed ``on_blade`` (x, y)
    (m) checked on its blade; one-line ConfigError otherwise."""
    if plan.behavior != behavior or plan.status != "solved":
        raise ConfigError(f"replan_{behavior} needs a solved {behavior} plan")
    cell = plan.cell()
    return cell, check_on_blade(on_blade, cell)
