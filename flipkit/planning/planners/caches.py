"""What planning keeps from one plan to the next, held by whoever plans many times.

A plan needs the cell's dynamics models and the arm's collision meshes, the constraint
blocks' sparsity patterns, and the SQP's compiled subproblems
(:class:`~flipkit.solvers.compiled.SQPWorkspace`: cvxpy's canonicalisation of a subproblem
costs more than many of its solves). None of them depends on the burger, so a
:class:`PlannerCaches` built once serves every plan made with it, and every ``plan_*`` entry
point takes one (``caches=``): the command, cook, sweep task or benchmark that plans many
motions makes one and passes it to each; a call given none makes its own, for itself alone.
The :class:`~flipkit.planning.planners.chain.Planner` passes each part down to where it is
used: the models and patterns to the transcription, the workspace to the SQP, the meshes to
the plan's verification.

Plans do not depend on what a :class:`PlannerCaches` held before: the models are built from
the cell alone, meshes and patterns are read-only once made, and every SQP solve resets its
structure's solver state on entry (:meth:`~flipkit.solvers.compiled.SQPWorkspace.reset`).
"""

from __future__ import annotations

from typing import Callable

from flipkit.behaviors.models import Models
from flipkit.config import CellConfig
from flipkit.model.collision import ArmMeshes
from flipkit.transcription.constraints.base import Patterns

__all__ = ["PlannerCaches"]


class PlannerCaches:
    """Models by cell, the arm's meshes, the blocks' patterns and the SQP's workspace.

    A workspace serves one solve at a time, so a :class:`PlannerCaches` serves one planner
    at a time: threads that plan at once (a cell that plans while it executes) hold one each,
    and so does every worker process.

    Attributes:
        meshes: The arm's loaded link meshes (:class:`~flipkit.model.collision.ArmMeshes`).
        patterns: The constraint blocks' sparsity patterns
            (:class:`~flipkit.transcription.constraints.base.Patterns`).
    """

    def __init__(self):
        self.meshes = ArmMeshes()
        self.patterns = Patterns()
        self._models: dict[CellConfig, Models] = {}
        self._workspace = None

    def models(self, cell: CellConfig) -> Models:
        """The :class:`~flipkit.behaviors.models.Models` of ``cell``, built on first use
        (a cell that cannot be hashed, with lists inside, gets new ones each time)."""
        try:
            models = self._models.get(cell)
        except TypeError:
            return Models(cell, self.meshes)
        if models is None:
            models = self._models[cell] = Models(cell, self.meshes)
        return models

    def workspace(self, make: Callable):
        """The SQP's workspace (:class:`~flipkit.solvers.compiled.SQPWorkspace`), made by
        ``make()`` on first use. The solving code passes ``make``, so that importing the
        planners does not load the solvers (cvxpy): the first solve does."""
        if self._workspace is None:
            self._workspace = make()
        return self._workspace
