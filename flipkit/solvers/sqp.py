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
to a workspace
(:class:`~flipkit.solvers.compiled.SQPWorkspace`, the caller's or the process's default), reset
for the NLP's structure on entry so that no solve warm-starts from another. μ regularises the
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

import math
import time

import numpy as np

from flipkit.errors import NoSolutionFound
from flipkit.solvers.iterate import Iterate, newton_correction
from flipkit.transcription.nlp import NLP
from flipkit.solvers.compiled import DEFAULT_WORKSPACE, SQPWorkspace
from flipkit.solvers.reduced_hessian import ReducedHessian
from flipkit.solvers.subproblem import QPSolution
from flipkit.solvers.threads import single_threaded_blas
from flipkit.solvers.result import SolveResult, Status
from flipkit.solvers.sqp_options import (QPOptions, RestorationOptions, SQPOptions,
                                         TerminationOptions, TrustRegionOptions)

__all__ = ["DEFAULT_WORKSPACE", "QPOptions", "RestorationOptions", "SQPOptions", "SQPWorkspace",
           "SolveResult", "TerminationOptions", "TrustRegionOptions", "solve_sqp"]


def _subproblem(nlp: NLP, o: SQPOptions, p: Iterate, grad, hess, mu: float, d_lo, d_hi,
                eps: float, wide=None, restore=None, restoring: bool = False, *,
                workspace: SQPWorkspace, curvature=None):
    """The step at p: the hard QP (if OSQP runs out of iterations — not infeasible — μ is
    raised tenfold, better conditioned for ADMM and a shorter step, and it is tried again);
    if it is infeasible, the hard QP in the box ``wide`` (the variable bounds within the largest
    trust region), if given; else the restoration QP, in the box ±``restore`` ∩ the variable
    bounds (default the step box). ``restoring``: in the restoration phase, the restoration QP
    alone. ``curvature``: the rows' reduced curvature M for the hard QP (condensed form,
    :mod:`flipkit.solvers.reduced_hessian`). The compiled QPs are ``workspace``'s. Returns
    (solution, QP object, μ, tries, ADMM iterations)."""
    admm, attempt, sol = 0, -1, None
    extra = {} if curvature is None else {"curvature": curvature}  # the condensed form's only
    for attempt in range(0 if restoring else 3):
        qp = workspace.get(nlp, "condensed" if o.qp.condense else "full")
        qp.update(nlp, p.cs, p.jac, grad, hess + mu, d_lo, d_hi, **extra)
        sol = qp.solve(eps=eps, max_iter=o.qp.max_iter[attempt])
        admm += sol.iterations
        if "infeasible" in sol.status and attempt == 0:
            # A warm start from the previous subproblem's duals can fake an infeasibility
            # certificate: confirm it cold. A later try starts from this subproblem's own
            # previous try, whose verdicts a cold confirmation did not reverse: not worth its
            # CPU time.
            qp.cold()
            sol = qp.solve(eps=eps, max_iter=o.qp.max_iter[attempt])
            admm += sol.iterations
        if sol.status == "optimal" or "infeasible" in sol.status:
            break
        mu = min(10.0 * mu, o.trust_region.prox_range[1])
    if sol is not None and sol.status == "optimal":
        return sol, qp, mu, attempt + 1, admm
    if wide is not None and not restoring:
        # Infeasible within a shrunken trust box, or no verdict from OSQP in its three tries
        # (ADMM detects infeasibility slowly, and how slowly depends on the null-space
        # basis). Then the hard QP in the largest box Δ_max ∩ the variable bounds (the line
        # search then shortens the step): it is usually feasible there and much cheaper than
        # the elastic QP. Without Δ_max, in the variable bounds alone, a step can reach a
        # region where the NLP is declared infeasible.
        qp.update(nlp, p.cs, p.jac, grad, hess + mu, *wide, **extra)
        qp.cold()
        sol = qp.solve(eps=eps, max_iter=o.qp.max_iter[-1])
        admm += sol.iterations
        if sol.status == "optimal":
            return sol, qp, mu, attempt + 2, admm
    # Restoration: a least-squares (Levenberg–Marquardt) step on the rows, condensed (the
    # equalities hard) unless they and the box are incompatible, then in full space.
    tries, box = 1 if restoring else attempt + 3, (d_lo, d_hi)
    if restore is not None:
        box = (np.maximum((nlp.x_lb - p.x) / nlp.x_scale, -restore),
               np.minimum((nlp.x_ub - p.x) / nlp.x_scale, restore))
    for form in (("condensed_elastic", "elastic") if o.qp.condense else ("elastic",)):
        qp = workspace.get(nlp, form)
        qp.update(nlp, p.cs, p.jac, 0 * grad, np.full(nlp.n, o.restoration.prox), *box,
                  o.restoration.slack_reg)
        sol = qp.solve(eps=eps, max_iter=o.qp.max_iter[0] if form != "elastic" else None)
        admm += sol.iterations
        if sol.status == "optimal":
            break
        tries += 1
    return sol, qp, mu, tries, admm


def _line_search(o: SQPOptions, p: Iterate, d, pred: float, merit, point, correct):
    """Backtracking on ``merit`` (a function of an iterate: φ for a hard step, ½‖v‖₂² for a
    restoration step) from p along d, with a second-order correction of a poorly predicted,
    infeasible full step. Returns (trial, step, ratio, accepted)."""
    step, ratio, trial = 1.0, 0.0, None
    for _ in range(o.trust_region.backtracks + 1):
        trial = point(p.x + step * d)
        if (o.trust_region.second_order_correction and step == 1.0 and trial.v.sum() > p.v.sum()
                and merit(p) - merit(trial) < 0.75 * pred):
            # Second-order correction: the full step's curvature error on the rows (cone,
            # blade heights, landing) removed by a minimum-norm Newton step at Z + d that
            # holds the subproblem's active rows at their bounds.
            soc = correct(trial)
            if merit(soc) < merit(trial):
                trial = soc
        actual = merit(p) - merit(trial)
        ratio = actual / (step * pred)
        if actual >= o.trust_region.eta * step * pred:
            return trial, step, ratio, True
        step *= 0.5
    return trial, step, ratio, False


def _adapt(o: SQPOptions, accepted: bool, step: float, ratio: float, d_len: float,
           trust: float, mu: float) -> tuple[float, float]:
    """New (Δ, μ): μ relaxed after a full step the model predicted well and raised when the
    step had to be shortened or was rejected; Δ doubled after a full, well predicted step
    that used at least half of it, shrunk to the accepted length, or to a tenth of the
    rejected one."""
    t = o.trust_region
    good = accepted and step == 1.0 and ratio >= t.good_ratio
    if good:
        mu = max(mu / 4.0, t.prox_range[0])
    elif not accepted or step < 1.0:
        mu = min(mu * 4.0, t.prox_range[1])
    if good and d_len >= 0.5 * trust:
        trust = min(2.0 * trust, t.radius_max)
    elif accepted and step < 1.0:
        trust = max(step * d_len, t.radius_min)
    elif not accepted:  # never wider than before: a rejected step from the largest box
        # (wide, longer than Δ) reset Δ to a tenth of its own length, the same Δ at the
        # same point each time, and the SQP repeated one iteration to max_iter
        trust = max(0.1 * min(d_len, trust), t.radius_min) if d_len > 0 else 0.1 * trust
    return trust, mu


def _linearised_violation(nlp: NLP, p: Iterate, d, total: bool = True):
    """‖v‖₁ of the rows linearised at p after the (scaled) step d, or (``total=False``) the
    rows' violations."""
    c_lin = p.cs + p.J @ d
    v = np.maximum(np.maximum(nlp.c_scale * nlp.c_lo - c_lin, c_lin - nlp.c_scale * nlp.c_hi), 0.0)
    return float(v.sum()) if total else v


def _square_violation(p: Iterate) -> float:
    """½‖v‖₂², the restoration's merit (the elastic QP is its Levenberg–Marquardt model)."""
    return 0.5 * float(p.v @ p.v)


def _descent_model(nlp: NLP, p: Iterate, sol: QPSolution, grad, hess, rho: float, extra=0.0):
    """(ρ, pred): ρ ≥ twice the largest multiplier and large enough for d to descend on φ
    (elastic steps have no informative multipliers); pred = φ(p) − model(d), the model's cost
    change gᵀd + ½dᵀHd plus ``extra`` (the rows' curvature term ½wᵀMw of the step)."""
    d = sol.d
    rho = max(rho, 2.0 * float(np.abs(sol.multipliers).max(initial=0.0)))
    lin_v = _linearised_violation(nlp, p, d)
    model_f = grad @ d + 0.5 * d @ (hess * d) + extra
    reduction = float(p.v.sum()) - lin_v
    if model_f > 0 and reduction > 0:
        rho = max(rho, 2.0 * model_f / reduction)
    return rho, p.merit(rho) - (p.f + model_f + rho * lin_v)


def solve_sqp(nlp: NLP, x0=None, options: SQPOptions = SQPOptions(), raise_on_failure=True,
              *, workspace: SQPWorkspace | None = None) -> SolveResult:
    """Solve ``nlp`` from ``x0``, BLAS on one thread (:mod:`flipkit.solvers.threads`).

    Args:
        nlp: The NLP.
        x0: Start point, unscaled (default ``nlp.x0``).
        options: The settings (:class:`~flipkit.solvers.sqp_options.SQPOptions`).
        raise_on_failure: Raise :class:`NoSolutionFound` unless solved; False returns the
            result whatever its status.
        workspace: The compiled subproblems to solve with, owned by the caller (one solve at
            a time per workspace); default :data:`~flipkit.solvers.compiled.DEFAULT_WORKSPACE`,
            the process's. Its state for ``nlp``'s structure is reset on entry, so the
            result does not depend on what the workspace solved before.

    Returns:
        The result: final point, status, iterations, log.

    Raises:
        NoSolutionFound: Not converged to a feasible point (carries the NLP, status, the
            worst constraint group and its violation, and the result).
    """
    with single_threaded_blas():
        result = _solve(nlp, x0, options, DEFAULT_WORKSPACE if workspace is None else workspace)
    if result.status != Status.SOLVED and raise_on_failure:
        group, amount = nlp.worst_group(result.x)
        raise NoSolutionFound(nlp, result.status, group, amount, result)
    return result


def _solve(nlp: NLP, x0, options: SQPOptions, workspace: SQPWorkspace) -> SolveResult:
    """The SQP loop of :func:`solve_sqp`; returns the result whatever its status."""
    t0 = time.perf_counter()
    workspace.reset(nlp)  # no warm start from another solve in this workspace
    o, D = options, nlp.x_scale
    stop, tr = o.termination, o.trust_region
    Jscale = nlp.c_scale[nlp.jac_rows] * D[nlp.jac_cols]
    hess = nlp.hessian_diagonal() * nlp.obj_scale * D**2
    point = lambda x: Iterate(nlp, nlp.project(x), Jscale)  # noqa: E731  (x unscaled)
    correct = lambda q: point(q.x + D * newton_correction(nlp, q))  # noqa: E731
    p = point(nlp.x0 if x0 is None else x0)
    rho, trust, mu, tighten = tr.rho_min, tr.radius0, tr.prox, 1.0
    log, qp_iters, status, it, pred, stalls = [], 0, Status.MAX_ITER, 0, np.inf, 0
    entry = None  # the violation where the restoration phase began (None: not in it)
    rows = (ReducedHessian(workspace.get(nlp, "condensed"))  # the rows' curvature, estimated
            if o.qp.condense and o.qp.quasi_newton else None)
    if not (np.all(np.isfinite(p.c)) and np.all(np.isfinite(p.jac))):  # no model to start from
        return SolveResult(x=p.x, status=Status.INVALID_NUMBER_DETECTED, iterations=0,
                           wall_time_s=time.perf_counter() - t0, objective=nlp.objective(p.x),
                           max_violation=math.inf, log=log, qp_iterations=0)
    while it < stop.max_iter:
        it += 1
        grad = nlp.gradient(p.x) * nlp.obj_scale * D
        d_lo = np.maximum((nlp.x_lb - p.x) / D, -trust)
        d_hi = np.minimum((nlp.x_ub - p.x) / D, trust)
        theta = p.v_max if p.v_max > stop.tol else pred  # resolve the violation, else the decrease
        eps = float(np.clip(o.qp.eps_factor * theta * tighten, *o.qp.eps))
        wide = (np.maximum((nlp.x_lb - p.x) / D, -tr.radius_max),
                np.minimum((nlp.x_ub - p.x) / D, tr.radius_max)) if trust < tr.radius_max else None
        restore = None if wide is not None else o.restoration.radius  # Δ at its largest
        restoring = entry is not None and p.v_max > o.restoration.exit * entry
        v_before = p.v_max
        sol, qp, mu, tries, admm = _subproblem(
            nlp, o, p, grad, hess, mu, d_lo, d_hi, eps, wide, restore, restoring,
            workspace=workspace, curvature=None if rows is None else rows.curvature())
        qp_iters += admm
        hard = not qp.elastic
        with_rows = hard and rows is not None and qp is rows.qp
        rho, pred = _descent_model(nlp, p, sol, grad, hess, rho,
                                   rows.model_term(sol.d) if with_rows else 0.0)
        step, ratio, accepted = 1.0, 0.0, False
        # A negative predicted decrease at a feasible point means the QP was solved too
        # loosely (d = 0 does better): not a stationary point — solve it again, tighter.
        inexact = hard and pred < 0 and p.v_max <= stop.tol and eps > o.qp.eps[0]
        tighten = 0.01 * tighten if inexact else 1.0
        stationary = hard and not inexact and pred <= stop.ftol * max(p.f, 1e-3)
        recent = log[-stop.plateau_iterations:]
        stationary = stationary or (  # a plateau: feasible to 100 tol, Σu² no longer falling
            hard and len(recent) == stop.plateau_iterations
            and all(r["violation"] <= 100 * stop.tol for r in recent)
            and recent[0]["objective"] - nlp.objective(p.x)
            < stop.plateau_ftol * recent[0]["objective"])
        side = np.sign(sol.multipliers) * (nlp.c_lo != nlp.c_hi) if hard else None  # active rows
        held = lambda q: point(q.x + D * newton_correction(nlp, q, side))  # noqa: E731
        if stationary and p.v_max > stop.tol:
            # Stationary but a hair outside (the Gauss–Newton tail converges linearly on
            # curved active rows): Newton corrections onto the violated rows, first holding
            # the subproblem's active rows at their bounds, as the line search's correction
            # does (see newton_correction), else not: the tail then takes a few iterations
            # fewer.
            for _ in range(3):
                q = held(p)
                if q.v.sum() >= p.v.sum():
                    q = correct(p)
                if q.v.sum() >= p.v.sum():
                    break
                p = q
                if p.v_max <= stop.tol:
                    break
        if stationary and p.v_max <= stop.tol:
            status = Status.SOLVED
        elif sol.status in ("optimal", "optimal_inaccurate") and (pred > 0 or not hard):
            if hard:
                merit, decrease = (lambda q: q.merit(rho)), pred
            else:  # restoration: judged by the violation it removes, whatever Σu² does
                merit, decrease = _square_violation, _square_violation(p) - 0.5 * float(
                    np.sum(_linearised_violation(nlp, p, sol.d, total=False) ** 2))
            if decrease > 0:
                trial, step, ratio, accepted = _line_search(o, p, D * sol.d, decrease, merit,
                                                            point, held)
        d_len = float(np.abs(sol.d).max(initial=0.0))
        if (hard and not accepted and status != Status.SOLVED and p.v_max <= stop.tol
                and 0 < pred <= stop.reject_ftol * max(p.f, 1e-3)):
            status = Status.SOLVED  # feasible, and the model's small gain is not real
        if status != Status.SOLVED and not inexact:
            trust, mu = _adapt(o, accepted, step, ratio, d_len, trust, mu)
        if not hard:  # restoration: count the steps that barely reduce the violation
            gain = _square_violation(p) - _square_violation(trial) if accepted else 0.0
            stalls = stalls + 1 if gain < stop.stall_progress * _square_violation(p) else 0
        # The restoration phase: entered by an accepted restoration step, left when the
        # violation is down to restoration.exit × its value at entry (or a step is rejected).
        entry = (entry if entry is not None else v_before) if accepted and not hard else None
        if accepted and with_rows:  # the rows' curvature along the step, at the QP's multipliers
            lam, moved = sol.multipliers, trial.x - p.x
            rows.update(moved / D, hess * moved / D + (trial.J.T @ lam - p.J.T @ lam), hess)
        if accepted:
            p = trial
        log.append({"iter": it, "objective": nlp.objective(p.x), "violation": p.v_max,
                    "merit": float(p.merit(rho)), "pred": float(pred), "ratio": float(ratio),
                    "step": step if accepted else 0.0, "trust": trust, "prox": mu, "rho": rho,
                    "qp_iters": admm, "qp_tries": tries, "qp_status": sol.status,
                    "polished": sol.polished, "elastic": qp.elastic})
        if status == Status.SOLVED:
            break
        if trust <= tr.radius_min and not accepted:
            status = Status.STALLED
            break
        if stalls >= stop.stall_iterations:
            status = Status.INFEASIBLE
            break
    return SolveResult(x=p.x, status=status, iterations=it, wall_time_s=time.perf_counter() - t0,
                       objective=nlp.objective(p.x), max_violation=p.v_max,
                       log=log, qp_iterations=qp_iters)
