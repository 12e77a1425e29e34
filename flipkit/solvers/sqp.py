"""SQP for one segment's NLP: Gauss–Newton subproblems with an estimate of the rows' curvature
(cvxpy + OSQP), exact projection onto the dynamics rows, ℓ1 merit with a line search, and a
box trust region.

Settings are :class:`~flipkit.solvers.sqp_options.SQPOptions`, in four groups (``termination``,
``trust_region``, ``restoration``, ``qp``); lengths are in scaled variable units, J̃ is the
scaled cost and v the scaled violation. The design, its alternatives and references are in
``docs/sqp.md``.

Model. Each iteration linearises the constraints at Z_k and solves a convex QP for the step
d: the cost's exact Hessian (2 on the torques) plus a Levenberg–Marquardt weight ½μ‖d‖², every
linearised row hard, and the trust box |d|∞ ≤ Δ. With the dynamics rows u = RNEA(q, q̇, q̈)
hard this is the Gauss–Newton model of Σ‖RNEA‖² along the linearised constraints. With
``qp.quasi_newton`` (the default) the condensed QP adds M, a damped BFGS estimate of the
rows' curvature in the null space of the equality rows, updated after every accepted hard
step (:mod:`flipkit.solvers.reduced_hessian`): the flip's landing, flight and cone rows are
strongly curved, and without it the model over-predicted the decrease and the line search
halved the step. With ``qp.condense`` (the default) the QP is solved in
condensed form (:mod:`flipkit.solvers.condensed_qp`: the linearised equality rows eliminated by
a sparse LU, OSQP sees a small QP with an identity Hessian and inequality rows only), else in
full space (:mod:`flipkit.solvers.full_qp`, Gauss–Newton model only). The compiled QPs belong
to the solver's workspace (:class:`~flipkit.solvers.sqp_solver.SQPSolver`, which owns a
:class:`~flipkit.solvers.compiled.SQPWorkspace`), reset for the NLP's structure on entry so
that no solve warm-starts from another. μ regularises the
directions along which Σu² is nearly flat (wrist motions): it is divided by 4 after a full
step the model predicted well (actual/predicted ≥ ``trust_region.good_ratio``) and multiplied
by 4 after a shortened or rejected one, within ``trust_region.prox_range``.

Globalisation. Every trial point is projected first: u_i := RNEA(q_i, q̇_i, q̈_i), which
satisfies the dynamics rows exactly (u enters them alone and linearly), so the merit does not
see their second-order error. A trial point Z + a·d, a ∈ {1, ½, …, 2^−``backtracks``}, is
accepted when φ = J̃ + ρ‖v‖₁ falls by at least η·a·pred, pred the model's decrease; ρ stays
above twice the largest QP multiplier and large enough for d to descend on φ. With
``trust_region.second_order_correction`` (off by default), a full step that raises the
violation and falls short of its prediction gets a second-order correction (a Newton step
holding the QP's active rows) before it is judged. Δ doubles after a full,
well predicted step that used at least half of it, shrinks to the accepted length after a
shortened step, and to a tenth of the shorter of Δ and the step after a rejected one.

Subproblem failures. If OSQP runs out of iterations on the hard QP, μ is raised tenfold and
the QP re-solved (three tries, capped by ``qp.max_iter``); an infeasibility verdict from a warm
start is confirmed by a cold solve. A hard QP infeasible in a shrunken box is solved in the
largest box (Δ_max ∩ the variable bounds) and the line search shortens its step. Otherwise a
restoration step minimises ½σ‖s‖² + ½μ_r‖d‖² over slacks s: in condensed form, the equality
rows hard and slacks on the inequality rows, else (equalities and box incompatible) in full
space with slacks on every row; its box is ±``restoration.radius`` while Δ is at its largest.
A restoration step is judged by the violation alone: its trial points must lower ½‖v‖₂² by
η·a times the linearised reduction, whatever Σu² does. An accepted restoration step opens a
restoration phase, as in filter SQP methods: the next steps are restoration steps too, without
the hard QP's attempts, until the max violation is down to ``restoration.exit`` times its
value when the phase began. The OSQP tolerance follows the iterate (inexact SQP):
``qp.eps_factor`` × the max violation (at a feasible iterate, × the last predicted decrease),
clipped to ``qp.eps``; a negative predicted decrease at a feasible iterate means the QP was
solved too loosely, and it is solved again a hundred times tighter.

Stopping rules (``termination``), as checked in each iteration. Every ``solved`` needs the max
scaled violation ≤ ``tol``.

1. Stationary (``solved``): the hard QP predicts a merit decrease ≤ ``ftol``·J̃ (J̃ taken as at
   least 1e-3). A stationary point a hair outside ``tol`` first gets up to three minimum-norm
   Newton corrections onto the rows.
2. Plateau (``solved``, as rule 1, corrections included): the last ``plateau_iterations``
   iterates were feasible to 100·``tol`` and together lowered Σu² by less than
   ``plateau_ftol`` (relative). The model knows the rows' curvature only as far as the BFGS
   estimate has seen it (the Gauss–Newton model, not at all): creeping along curved active
   rows it can keep predicting more than ``ftol``, so this rule watches the actual decrease
   over a window instead of the predicted one.
3. Rejected small step (``solved``): at a feasible iterate the line search rejects a hard step
   whose predicted decrease was at most ``reject_ftol``·J̃. Rule 1 has already taken every
   prediction ≤ ``ftol``·J̃, so this rule covers (``ftol``, ``reject_ftol``]: gains inside the
   model's error, where Δ would otherwise shrink tenfold per rejected step until rule 1 held
   at the same point. It is off when ``reject_ftol`` ≤ ``ftol``.
4. ``stalled``: a step is rejected with Δ at ``trust_region.radius_min``.
5. ``infeasible``: ``stall_iterations`` restoration steps, with no better restoration step
   between them, each cut ½‖v‖₂² by less than ``stall_progress`` (relative): a stationary
   point of the violation. Only restoration steps count, so it never competes with rules 1–3,
   which judge hard steps.
6. ``max_iter``: ``max_iter`` iterations done.

Rules 1–3 answer one question, whether Z is stationary, from three sides: the model's
prediction (1), the actual progress (2) and the line search's verdict on a small prediction
(3). ``ftol`` sets where a solve normally ends; ``plateau_ftol`` and ``reject_ftol`` bound the
tail where the model is less accurate than ``ftol``. Rules 4–6 end solves that failed.
"""

from __future__ import annotations

from flipkit.solvers.compiled import SQPWorkspace
from flipkit.solvers.result import SolveResult
from flipkit.solvers.sqp_options import (QPOptions, RestorationOptions, SQPOptions,
                                         TerminationOptions, TrustRegionOptions)
from flipkit.solvers.sqp_solver import SQPSolver, Step, StepRequest
from flipkit.transcription.nlp import NLP

__all__ = ["QPOptions", "RestorationOptions", "SQPOptions", "SQPSolver", "SQPWorkspace",
           "SolveResult", "Step", "StepRequest", "TerminationOptions", "TrustRegionOptions",
           "solve_sqp"]


def solve_sqp(nlp: NLP, x0=None, options: SQPOptions = SQPOptions(), raise_on_failure=True,
              *, workspace: SQPWorkspace | None = None) -> SolveResult:
    """Solve ``nlp`` from ``x0`` with a :class:`~flipkit.solvers.sqp_solver.SQPSolver` of
    ``options`` in ``workspace``: one solve, for callers that hold no solver.

    Args:
        nlp: The NLP.
        x0: Start point, unscaled (default ``nlp.x0``).
        options: The settings (:class:`~flipkit.solvers.sqp_options.SQPOptions`).
        raise_on_failure: Raise :class:`~flipkit.errors.NoSolutionFound` unless solved;
            False returns the result whatever its status.
        workspace: The compiled subproblems to solve in, the caller's (one solve at a time
            per workspace); default a new one, compiled for this solve alone. Its state for
            ``nlp``'s structure is reset on entry, so the result does not depend on what the
            workspace solved before.

    Returns:
        The result: final point, status, iterations, log.

    Raises:
        NoSolutionFound: Not converged to a feasible point (carries the NLP, status, the
            worst constraint group and its violation, and the result).
    """
    return SQPSolver(options, workspace).solve(nlp, x0, raise_on_failure)
