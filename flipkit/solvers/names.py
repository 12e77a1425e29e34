"""The solvers' names, defined once: what a planner, the command line and the experiments
accept, and what a result records (:attr:`flipkit.solvers.result.SolveResult.solver`, a plan
segment's ``solver.name``).
"""

from __future__ import annotations

__all__ = ["EXACT_RESULT_NAMES", "EXACT_SOLVERS", "NLP_SOLVERS", "SOLVERS"]

NLP_SOLVERS = ("sqp", "ipopt")
"""The solvers of the :class:`~flipkit.transcription.nlp.NLP` interface: ``"sqp"``
(:func:`flipkit.solvers.sqp.solve_sqp`, cvxpy/OSQP subproblems) and ``"ipopt"``
(:func:`flipkit.solvers.ipopt.solve_ipopt`, CasADi's IPOPT with L-BFGS). A planned segment's
result carries one of these names."""

SOLVERS = (*NLP_SOLVERS, "auto")
"""The planner's solver choices, ``("sqp", "ipopt", "auto")``: one of :data:`NLP_SOLVERS`, or
``"auto"``, the SQP and then IPOPT from the same start where the SQP fails (the planners'
default)."""

EXACT_SOLVERS = ("fatrop", "ipopt", "sqpmethod")
"""The CasADi plugins of the exact-derivative solvers (:class:`flipkit.solvers.exact.ExactSolver`,
on the NLP's stage-wise SX graph): FATROP, exact-Hessian IPOPT and CasADi's SQP with HPIPM.
Used by benchmarks, not by the planner."""

EXACT_RESULT_NAMES = {"fatrop": "fatrop", "ipopt": "ipopt_exact", "sqpmethod": "sqpmethod"}
"""The name an exact-derivative solve records as its result's ``solver``, by plugin
(:data:`EXACT_SOLVERS`): ``"ipopt_exact"`` keeps exact-Hessian IPOPT apart from the L-BFGS
``"ipopt"`` of :data:`NLP_SOLVERS`."""
