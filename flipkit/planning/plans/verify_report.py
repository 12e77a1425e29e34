"""The result of :func:`flipkit.planning.plans.verify.verify_plan`: per check group, the worst row
relative to its tolerance, where it is, and whether the group passes; and the tolerance's
default and range (:data:`TOL`, :data:`TOL_RANGE`), light to import for the command line."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from flipkit.errors import VerificationError
from flipkit.fileio import write_text

TOL = 1e-5  # scaled units: 10 × SQPOptions.tol (verify's module docstring)
# scaled units: tighter than TOL down to 1e-9, looser at most 10 ×, so that no pose or burger
# centimetres off passes (a tolerance near 1 lets one pass)
TOL_RANGE = (1e-9, 1e-4)

GROUPS = {"time_grid": "s", "dynamics": "N·m", "defects": "rad | rad/s", "q_limits": "rad",
          "qd_limits": "rad/s", "qdd_limits": "rad/s²", "u_limits": "N·m",
          "interpolant": "rad/s | rad/s²",
          "endpoints": "m | rad | rad/s", "behavior_path": "m | 1", "continuity": "rad | rad/s",
          "cone": "m/s²", "release": "m/s²", "grill_clearance": "m", "landing": "m | deg | s",
          "landing_scenarios": "m | deg | s", "flight_clearance": "m", "placing": "m",
          "arm_clearance": "m", "orientation": "rad", "safety_limits": "m/s | kg·m/s",
          "singularity": "rad", "completeness": "segments"}


@dataclass
class GroupResult:
    """Worst row of a check group — the largest violation relative to its tolerance — with
    both in the group's unit, and where (segment index, node; ``None`` if no row was checked)."""

    name: str
    unit: str
    violation: float = 0.0
    tolerance: float = math.inf
    segment: int | None = None
    node: int | None = None

    @property
    def ratio(self) -> float:
        """violation / tolerance of the worst row (≤ 1 passes; NaN counts as infinite)."""
        ratio = self.violation / self.tolerance
        return math.inf if math.isnan(ratio) else ratio

    @property
    def ok(self) -> bool:
        """Whether every row of the group is within its tolerance."""
        return self.ratio <= 1.0


@dataclass
class VerificationReport:
    """Per-group results of :func:`verify_plan`; ``segments`` lists the segment names."""

    tol: float
    segments: list
    groups: dict = field(default_factory=lambda: {g: GroupResult(g, u) for g, u in GROUPS.items()})

    def add(self, group: str, segment: int, violation, tolerance, node: int | None = None):
        """Record the rows ``violation`` (≥ 0) against ``tolerance`` (broadcast), at ``node``."""
        v = np.atleast_1d(np.asarray(violation, float))
        self.add_nodes(group, segment, v[None], tolerance, [node])

    def add_nodes(self, group: str, segment: int, violation, tolerance, nodes=None):
        """Record rows given node by node: ``violation`` (n, k) holds node ``nodes[r]``'s
        rows in row r (default nodes 0..n−1); the same as :meth:`add` once per node, in order."""
        v = np.asarray(violation, float)
        v = v.reshape(len(v), -1)
        if v.size == 0:
            return
        tol = np.broadcast_to(tolerance, v.shape)
        ratio = v / tol
        ratio = np.where(np.isnan(ratio), np.inf, ratio)
        r, c = np.unravel_index(int(np.argmax(ratio)), v.shape)
        res = self.groups[group]
        if res.segment is None or ratio[r, c] > res.ratio:
            res.violation, res.segment = float(v[r, c]), segment
            node = r if nodes is None else nodes[r]
            res.node = None if node is None else int(node)
            res.tolerance = float(tol[r, c])

    @property
    def ok(self) -> bool:
        """Whether every group passes."""
        return all(g.ok for g in self.groups.values())

    def worst(self) -> tuple[str, int | None, float]:
        """(group, segment index, violation) of the group with the largest violation/tolerance."""
        g = max(self.groups.values(), key=lambda r: r.ratio)
        return g.name, g.segment, g.violation

    def summary(self) -> str:
        """One line: pass, or the worst group, where, and by how much."""
        if self.ok:
            return f"plan verified: {len(self.groups)} check groups pass"
        name, k, amount = self.worst()
        g = self.groups[name]
        at = f" at node {g.node}" if g.node is not None else ""
        return (f"plan fails {name!r} in segment {k} ({self.segments[k]}){at}: violation "
                f"{amount:.3g} {g.unit} > tolerance {g.tolerance:.3g}")

    def table(self) -> str:
        """The groups as a text table: unit, max violation, tolerance, where, ok/FAIL."""
        # each column as wide as its longest entry and two spaces apart
        name_w = max(len("group"), *(len(g.name) for g in self.groups.values())) + 2
        unit_w = max(len("unit"), *(len(g.unit) for g in self.groups.values())) + 2
        rows = [f"{'group':<{name_w}}{'unit':<{unit_w}}{'max violation':>14}{'tolerance':>11}  "
                f"{'segment':<16}status"]
        for g in self.groups.values():
            where = "-" if g.segment is None else f"{g.segment}:{self.segments[g.segment]}"
            tol = "-" if math.isinf(g.tolerance) else f"{g.tolerance:.2e}"
            rows.append(f"{g.name:<{name_w}}{g.unit:<{unit_w}}{g.violation:>14.3e}{tol:>11}  "
                        f"{where:<16}{'ok' if g.ok else 'FAIL'}")
        return "\n".join(rows)

    def to_json(self) -> dict:
        """The report as JSON values (non-finite numbers as null)."""
        finite = lambda x: x if math.isfinite(x) else None  # noqa: E731
        return {"ok": self.ok, "tol": self.tol, "segments": self.segments, "groups": [
            {"name": g.name, "unit": g.unit, "max_violation": finite(g.violation),
             "tolerance": finite(g.tolerance),
             "segment": g.segment, "node": g.node, "ok": g.ok} for g in self.groups.values()]}

    def write_json(self, path) -> None:
        """Write :meth:`to_json` to ``path`` atomically (:func:`flipkit.fileio.write_text`)."""
        write_text(path, json.dumps(self.to_json(), indent=1))

    def raise_if_failed(self) -> None:
        """Raise :class:`VerificationError` with :meth:`summary` when the plan fails."""
        if not self.ok:
            raise VerificationError(self.summary())


__all__ = ["GROUPS", "TOL", "TOL_RANGE", "GroupResult", "VerificationReport"]
