"""The collocation NLP of one segment: the single interface every solver consumes.

    minimise  J(Z) = Σ_i u_i²                      (eq. 6)
    s.t.      Z_lb ≤ Z ≤ Z_ub                      (13, 14, 16 and α bounds)
              c_lo ≤ c(Z) ≤ c_hi                   (7, 8–9, 18, behaviour constraints)

The constraint Jacobian has a fixed sparsity pattern (``jac_rows``, ``jac_cols``) computed at
construction; :meth:`NLP.evaluate` returns c and the Jacobian entries in that order. Solvers
work in scaled units: Z = Z_scale ⊙ Z̃, c̃ = c_scale ⊙ c, J̃ = J · Z_scale / ·, objective
scaled by ``obj_scale``. A constraint violation is reported in those scaled units.
"""

from __future__ import annotations

import functools
import hashlib

import numpy as np

from flipkit.transcription.layout import Evaluation, Layout
from flipkit.transcription.constraints import Block
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot


class NLP:
    """One collocation segment: variables, bounds, objective and constraint blocks.

    Args:
        name: Segment name (``translate``, ``scoop``, ...).
        layout: Variable layout. robot: Model used by the constraint functions.
        blocks: Constraint blocks. x_lb, x_ub: Variable bounds. x_scale: Variable scales.
        x0: Initial guess. cone_nodes: Nodes with the friction cone (for the plan file).
    """

    def __init__(self, name: str, layout: Layout, robot: Robot, blocks: list[Block], x_lb, x_ub,
                 x_scale, x0, cone_nodes=()):
        self.name, self.layout, self.robot, self.blocks = name, layout, robot, list(blocks)
        self.n = layout.n
        self.x_lb, self.x_ub = np.asarray(x_lb, float), np.asarray(x_ub, float)
        self.x_scale = np.asarray(x_scale, float)
        self.x0 = np.clip(np.asarray(x0, float), self.x_lb, self.x_ub)
        self.cone_nodes = [int(i) for i in cone_nodes]
        # blade points whose kinematics the blocks read: computed with the centre's, per node
        self.points = tuple(dict.fromkeys(
            pt for b in self.blocks for pt in getattr(b, "points", ())))
        for arr, what in ((self.x_lb, "x_lb"), (self.x_ub, "x_ub"), (self.x_scale, "x_scale"),
                          (self.x0, "x0")):
            if arr.shape != (self.n,):
                raise ConfigError(f"{what} must have shape ({self.n},), got {arr.shape}")
        if not np.all(np.isfinite(self.x0)):
            raise ConfigError(f"segment {name!r}: initial guess is not finite")
        offsets = np.cumsum([0] + [b.m for b in self.blocks])
        self.block_slices = {b.name: slice(offsets[k], offsets[k + 1]) for k, b in enumerate(self.blocks)}
        if len(self.block_slices) != len(self.blocks):
            raise ConfigError("constraint block names must be unique")
        self.m = int(offsets[-1])
        self.jac_rows = np.concatenate([b.rows + offsets[k] for k, b in enumerate(self.blocks)])
        self.jac_cols = np.concatenate([b.cols for b in self.blocks])
        self.c_lo = np.concatenate([b.lo for b in self.blocks])
        self.c_hi = np.concatenate([b.hi for b in self.blocks])
        self.c_scale = np.concatenate([b.scale for b in self.blocks])
        self.u_index = np.concatenate([layout.iu(i) for i in range(layout.n_nodes)])
        # exact corrections of the trial points, fixed values first (project_order 0)
        self._projections = sorted((b for b in self.blocks if hasattr(b, "project")),
                                   key=lambda b: getattr(b, "project_order", 1))
        self.obj_scale = 1.0 / (layout.n_nodes * 1e4)  # Σu² of a UR10 holding a pose is ~1e4/node

    @functools.cached_property
    def structure_key(self) -> str:
        """Hash of the sparsity pattern and bound structure; equal keys share a compiled QP.
        Computed once: an NLP's pattern and bounds do not change after it is built (the SQP
        asks for the key at every subproblem)."""
        h = hashlib.sha1()
        for arr in (self.jac_rows, self.jac_cols, np.isfinite(self.c_lo), np.isfinite(self.c_hi),
                    self.c_lo == self.c_hi, np.array([self.n, self.m])):
            h.update(np.ascontiguousarray(arr).tobytes())
        return h.hexdigest()

    # ------------------------------------------------------------- functions
    def evaluate(self, x) -> tuple[np.ndarray, np.ndarray]:
        """Constraint values c(x) (m,) and Jacobian entries (nnz,), pattern order."""
        ev = Evaluation(self.layout, self.robot, np.asarray(x, float), self.points)
        parts = [b.evaluate(ev) for b in self.blocks]
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])

    def constraints(self, x) -> np.ndarray:
        return self.evaluate(x)[0]

    def objective(self, x) -> float:
        """J = Σ u_i² (N²·m²), unscaled."""
        u = np.asarray(x)[self.u_index]
        return float(u @ u)

    def gradient(self, x) -> np.ndarray:
        g = np.zeros(self.n)
        g[self.u_index] = 2 * np.asarray(x)[self.u_index]
        return g

    def hessian_diagonal(self) -> np.ndarray:
        """∇²J is constant and diagonal: 2 on the torques."""
        h = np.zeros(self.n)
        h[self.u_index] = 2.0
        return h

    def project(self, x) -> np.ndarray:
        """x with the blocks' exact corrections applied (fixed values, then u from the
        dynamics), within bounds."""
        x = np.asarray(x, float)
        for b in self._projections:
            x = b.project(x, self.robot)
        return np.clip(x, self.x_lb, self.x_ub)

    # ------------------------------------------------------------- feasibility
    def scaled_violation(self, c: np.ndarray) -> np.ndarray:
        """Per-row violation max(lo − c, c − hi, 0) in scaled units."""
        return self.c_scale * np.maximum(np.maximum(self.c_lo - c, c - self.c_hi), 0.0)

    def violation_by_group(self, x) -> dict[str, float]:
        """Largest scaled violation of each constraint group, plus ``bounds`` for Z."""
        v = self.scaled_violation(self.constraints(x))
        out = {name: float(v[s].max(initial=0.0)) for name, s in self.block_slices.items()}
        xb = np.maximum(np.maximum(self.x_lb - x, x - self.x_ub), 0.0) / self.x_scale
        out["bounds"] = float(xb.max(initial=0.0))
        return out

    def worst_group(self, x) -> tuple[str, float]:
        """(group, amount) of the most violated constraint group."""
        groups = self.violation_by_group(x)
        name = max(groups, key=groups.get)
        return name, groups[name]
