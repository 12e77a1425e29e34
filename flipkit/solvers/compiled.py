"""The SQP's workspace: compiled subproblems, one per NLP structure and form, built on first use
and reused.

Canonicalising a subproblem with cvxpy costs more than many of its solves, so a workspace
compiles each (structure, form) once; its parameters then take each linearisation's values (DPP)
and its OSQP solver, set up once, is updated and warm-started.
:class:`~flipkit.solvers.sqp_solver.SQPSolver` owns one and calls :meth:`SQPWorkspace.reset` at
the start of every solve, which forgets the OSQP state of the NLP's structure, so a solve never
warm-starts from another solve's solution: results do not depend on what the workspace solved
before.

Who keeps a workspace decides how long compiled subproblems live: whoever plans many motions
keeps one in a :class:`~flipkit.planning.planners.caches.PlannerCaches` and passes it to
every planner, so that planners made one after another compile each structure once. A
workspace serves one solve at a time: solves running concurrently in threads need one each.
"""

from __future__ import annotations

from flipkit.errors import InvalidChoiceError
from flipkit.solvers.condensed_qp import CondensedQP
from flipkit.solvers.full_qp import QPSubproblem
from flipkit.solvers.subproblem import Subproblem
from flipkit.transcription.nlp import NLP

__all__ = ["FORMS", "SQPWorkspace"]

FORMS = ("full", "elastic", "condensed", "condensed_elastic")


class SQPWorkspace:
    """Compiled subproblems by (NLP structure key, form); see :data:`FORMS`."""

    def __init__(self):
        self._built: dict[tuple[str, str], Subproblem] = {}

    def get(self, nlp: NLP, form: str = "full") -> Subproblem:
        """The compiled subproblem of ``nlp``'s structure in ``form``.

        Raises:
            InvalidChoiceError: ``form`` is not one of :data:`FORMS`.
        """
        if form not in FORMS:
            raise InvalidChoiceError("subproblem form", form, FORMS)
        key = (nlp.structure_key, form)
        qp = self._built.get(key)
        if qp is None:
            elastic = form.endswith("elastic")
            qp = (CondensedQP(nlp, elastic) if form.startswith("condensed")
                  else QPSubproblem(nlp, elastic))
            self._built[key] = qp
        return qp

    def reset(self, nlp: NLP) -> None:
        """Forget the solver state of every compiled form of ``nlp``'s structure."""
        for (structure, _), qp in self._built.items():
            if structure == nlp.structure_key:
                qp.reset()

