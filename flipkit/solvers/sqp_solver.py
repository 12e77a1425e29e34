"""The SQP as an object that owns its state: :class:`SQPSolver` holds its settings and a
workspace of compiled subproblems, and solves one NLP after another in it.

The algorithm (model, globalisation, subproblem failures, stopping rules) is described in
:mod:`flipkit.solvers.sqp` and ``docs/sqp.md``. This module splits it into the pieces one
iteration goes through:

* :class:`StepRequest` — what the subproblem at an iterate is asked (gradient, Hessian
  diagonal, step box, tolerance, the fallback boxes, the rows' curvature);
* :meth:`SQPSolver.step` — the hard QP (with its retries), the hard QP in the largest box,
  or a restoration QP; returns a :class:`Step`;
* :class:`SolveState` — everything one solve carries from iteration to iteration (the
  iterate, ρ, Δ, μ, the restoration phase, the log).

A solver's workspace (:class:`~flipkit.solvers.compiled.SQPWorkspace`) compiles each NLP
structure's subproblems once (cvxpy) and keeps their OSQP solvers set up; every solve resets
the workspace's state for its NLP's structure on entry, so a result never depends on what the
solver solved before. One solver serves one solve at a time.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from threadpoolctl import ThreadpoolController

from flipkit.errors import ConfigError, NoSolutionFound
from flipkit.solvers.compiled import SQPWorkspace
from flipkit.solvers.iterate import Iterate, newton_correction
from flipkit.solvers.reduced_hessian import ReducedHessian
from flipkit.solvers.result import SolveResult, Status
from flipkit.solvers.sqp_options import SQPOptions
from flipkit.solvers.subproblem import QPSolution, Subproblem
from flipkit.solvers.threads import single_threaded_blas
from flipkit.transcription.nlp import NLP

__all__ = ["SQPSolver", "SolveState", "Step", "StepRequest"]

Box = tuple[np.ndarray, np.ndarray]


@dataclass(frozen=True)
class StepRequest:
    """The subproblem at one iterate, in scaled units (lengths in units of ``nlp.x_scale``).

    Attributes:
        p: The iterate.
        grad: Gradient of the scaled cost (n,).
        hess: The cost's Hessian diagonal, scaled (n,), without the proximal weight.
        mu: Proximal (Levenberg–Marquardt) weight μ added to ``hess`` in the hard QP.
        box: (d_lo, d_hi), the variable bounds within the trust box |d|∞ ≤ Δ.
        eps: OSQP's absolute and relative tolerance.
        wide: The variable bounds within the largest trust box, for a hard QP infeasible in
            ``box``; None (Δ at its largest): no such retry.
        restore: Half-width of the restoration QP's box (∩ the variable bounds); None: ``box``.
        restoring: In the restoration phase: the restoration QP alone.
        curvature: The rows' reduced curvature M (r × r) for the condensed hard QP, or None.
    """

    p: Iterate
    grad: np.ndarray
    hess: np.ndarray
    mu: float
    box: Box
    eps: float
    wide: Box | None = None
    restore: float | None = None
    restoring: bool = False
    curvature: np.ndarray | None = None


@dataclass
class Step:
    """A subproblem's answer: the solution, the subproblem that gave it, the proximal weight
    it was solved with, the QPs tried (1: the hard QP at once) and their ADMM iterations."""

    sol: QPSolution
    qp: Subproblem
    mu: float
    tries: int
    admm: int

    @property
    def hard(self) -> bool:
        """A step of the hard QP (not of a restoration QP)."""
        return not self.qp.elastic


@dataclass
class SolveState:
    """What one solve carries from iteration to iteration (scaled units).

    Attributes:
        nlp: The NLP. point: Z (unscaled) → its projected :class:`Iterate`.
        hess: Scaled Hessian diagonal of the cost. p: The current iterate.
        rho: ℓ1 penalty ρ. trust: Trust radius Δ. mu: Proximal weight μ.
        tighten: Factor on the next QP tolerance (< 1 after a too loosely solved QP).
        pred: The last predicted merit decrease. entry: The max violation where the
            restoration phase began (None: not in it). stalls: Consecutive restoration steps
            that barely reduced ½‖v‖₂². rows: The rows' curvature estimate (or None).
        it: Iterations done. qp_iters: ADMM iterations in all. log: One dict per iteration.
        status: The status so far.
    """

    nlp: NLP
    point: Callable[[np.ndarray], Iterate]
    hess: np.ndarray
    p: Iterate
    rho: float
    trust: float
    mu: float
    rows: ReducedHessian | None
    tighten: float = 1.0
    pred: float = math.inf
    entry: float | None = None
    stalls: int = 0
    it: int = 0
    qp_iters: int = 0
    log: list = field(default_factory=list)
    status: Status = Status.MAX_ITER
    t0: float = field(default_factory=time.perf_counter)

    def correct(self, q: Iterate, side=None) -> Iterate:
        """``q`` after a minimum-norm Newton correction onto its rows (``side``: the active
        rows held at their bounds, see :func:`~flipkit.solvers.iterate.newton_correction`)."""
        return self.point(q.x + self.nlp.x_scale * newton_correction(self.nlp, q, side))

    def result(self) -> SolveResult:
        """The result as it stands."""
        p, nlp = self.p, self.nlp
        return SolveResult(x=p.x, status=self.status, iterations=self.it,
                           wall_time_s=time.perf_counter() - self.t0,
                           objective=nlp.objective(p.x), max_violation=p.v_max,
                           log=self.log, qp_iterations=self.qp_iters)


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


class SQPSolver:
    """The SQP of :mod:`flipkit.solvers.sqp` with its settings and compiled subproblems.

    Build one and solve many NLPs with it: each NLP structure's subproblems are compiled
    (cvxpy) on its first solve and reused; within a solve each OSQP solver is set up once
    and then updated. Results do not depend on the order of the solves.

    Args:
        options: The settings (:class:`~flipkit.solvers.sqp_options.SQPOptions`).
        workspace: The compiled subproblems to solve in (default a new one, this solver's
            own). A workspace serves one solve at a time: solvers running concurrently in
            threads need one each.

    Raises:
        ConfigError: ``options`` is not an :class:`~flipkit.solvers.sqp_options.SQPOptions`.
    """

    def __init__(self, options: SQPOptions = SQPOptions(), workspace: SQPWorkspace | None = None):
        if not isinstance(options, SQPOptions):
            raise ConfigError(f"options: expected SQPOptions, got {type(options).__name__}")
        self.options = options
        self.workspace = SQPWorkspace() if workspace is None else workspace
        self._blas = None  # the threadpoolctl controller of single_threaded_blas, on first use

    # ------------------------------------------------------------------ public
    def solve(self, nlp: NLP, x0=None, raise_on_failure: bool = True) -> SolveResult:
        """Solve ``nlp`` from ``x0``, BLAS on one thread (:mod:`flipkit.solvers.threads`).

        Args:
            nlp: The NLP.
            x0: Start point, unscaled (default ``nlp.x0``).
            raise_on_failure: Raise :class:`NoSolutionFound` unless solved; False returns
                the result whatever its status.

        Returns:
            The result: final point, status, iterations, log.

        Raises:
            NoSolutionFound: Not converged to a feasible point (carries the NLP, status, the
                worst constraint group and its violation, and the result).
        """
        if self._blas is None:
            self._blas = ThreadpoolController()
        with single_threaded_blas(self._blas):
            result = self._run(nlp, x0)
        if result.status != Status.SOLVED and raise_on_failure:
            group, amount = nlp.worst_group(result.x)
            raise NoSolutionFound(nlp, result.status, group, amount, result)
        return result

    def step(self, nlp: NLP, r: StepRequest) -> Step:
        """The step at ``r.p``: the hard QP (if OSQP runs out of iterations — not infeasible —
        μ is raised tenfold, better conditioned for ADMM and a shorter step, and it is tried
        again); if it is infeasible, the hard QP in the box ``r.wide``, if given; else the
        restoration QP. In the restoration phase (``r.restoring``), the restoration QP alone."""
        if r.restoring:
            return self._restoration(nlp, r, r.mu, admm=0, tries=1)
        hard = self._hard(nlp, r)
        if hard.sol.status == "optimal":
            return hard
        admm = hard.admm
        if r.wide is not None:
            wide = self._hard_in_wide_box(nlp, r, hard)
            if wide.sol.status == "optimal":
                return wide
            admm = wide.admm
        return self._restoration(nlp, r, hard.mu, admm=admm, tries=hard.tries + 2)

    # ------------------------------------------------------------------ subproblems
    def _extra(self, r: StepRequest) -> dict:
        """The hard QP's curvature argument (the condensed form's only)."""
        return {} if r.curvature is None else {"curvature": r.curvature}

    def _hard(self, nlp: NLP, r: StepRequest) -> Step:
        """The hard QP in the trust box, up to three tries with μ raised tenfold."""
        o, p = self.options, r.p
        admm, mu, sol, qp = 0, r.mu, None, None
        attempt = 0
        for attempt in range(3):
            qp = self.workspace.get(nlp, "condensed" if o.qp.condense else "full")
            qp.update(nlp, p.cs, p.jac, r.grad, r.hess + mu, *r.box, **self._extra(r))
            sol = qp.solve(eps=r.eps, max_iter=o.qp.max_iter[attempt])
            admm += sol.iterations
            if "infeasible" in sol.status and attempt == 0:
                # A warm start from the previous subproblem's duals can fake an infeasibility
                # certificate: confirm it cold. A later try starts from this subproblem's own
                # previous try, whose verdicts a cold confirmation did not reverse: not worth
                # its CPU time.
                qp.cold()
                sol = qp.solve(eps=r.eps, max_iter=o.qp.max_iter[attempt])
                admm += sol.iterations
            if sol.status == "optimal" or "infeasible" in sol.status:
                break
            mu = min(10.0 * mu, o.trust_region.prox_range[1])
        return Step(sol, qp, mu, attempt + 1, admm)

    def _hard_in_wide_box(self, nlp: NLP, r: StepRequest, hard: Step) -> Step:
        """The hard QP in the largest box Δ_max ∩ the variable bounds, after the trust box
        gave no step (infeasible there, or no verdict from OSQP in its three tries: ADMM
        detects infeasibility slowly, and how slowly depends on the null-space basis). It is
        usually feasible there and much cheaper than the elastic QP; the line search then
        shortens the step. Without Δ_max, in the variable bounds alone, a step can reach a
        region where the NLP is declared infeasible."""
        p, qp = r.p, hard.qp
        qp.update(nlp, p.cs, p.jac, r.grad, r.hess + hard.mu, *r.wide, **self._extra(r))
        qp.cold()
        sol = qp.solve(eps=r.eps, max_iter=self.options.qp.max_iter[-1])
        return Step(sol, qp, hard.mu, hard.tries + 1, hard.admm + sol.iterations)

    def _restoration(self, nlp: NLP, r: StepRequest, mu: float, admm: int, tries: int) -> Step:
        """A least-squares (Levenberg–Marquardt) step on the rows: condensed (the equalities
        hard) unless they and the box are incompatible, then in full space (every row
        elastic). ``mu``, ``admm``, ``tries``: the proximal weight, ADMM iterations and count
        of QPs (this one included) of the attempts before it."""
        o, p = self.options, r.p
        box = r.box
        if r.restore is not None:
            box = (np.maximum((nlp.x_lb - p.x) / nlp.x_scale, -r.restore),
                   np.minimum((nlp.x_ub - p.x) / nlp.x_scale, r.restore))
        sol, qp = None, None
        for form in (("condensed_elastic", "elastic") if o.qp.condense else ("elastic",)):
            qp = self.workspace.get(nlp, form)
            qp.update(nlp, p.cs, p.jac, 0 * r.grad, np.full(nlp.n, o.restoration.prox), *box,
                      o.restoration.slack_reg)
            sol = qp.solve(eps=r.eps, max_iter=o.qp.max_iter[0] if form != "elastic" else None)
            admm += sol.iterations
            if sol.status == "optimal":
                break
            tries += 1
        return Step(sol, qp, mu, tries, admm)

    # ------------------------------------------------------------------ the loop
    def _start(self, nlp: NLP, x0) -> SolveState:
        """The solve's state at ``x0``, the workspace reset for ``nlp``'s structure (no warm
        start from another solve)."""
        t0 = time.perf_counter()
        self.workspace.reset(nlp)
        o, D = self.options, nlp.x_scale
        jscale = nlp.c_scale[nlp.jac_rows] * D[nlp.jac_cols]
        point = lambda x: Iterate(nlp, nlp.project(x), jscale)  # noqa: E731  (x unscaled)
        rows = (ReducedHessian(self.workspace.get(nlp, "condensed"))  # the rows' curvature
                if o.qp.condense and o.qp.quasi_newton else None)
        tr = o.trust_region
        return SolveState(nlp=nlp, point=point,
                          hess=nlp.hessian_diagonal() * nlp.obj_scale * D**2,
                          p=point(nlp.x0 if x0 is None else x0), rho=tr.rho_min,
                          trust=tr.radius0, mu=tr.prox, rows=rows, t0=t0)

    def _run(self, nlp: NLP, x0) -> SolveResult:
        """The SQP loop; returns the result whatever its status."""
        s = self._start(nlp, x0)
        if not (np.all(np.isfinite(s.p.c)) and np.all(np.isfinite(s.p.jac))):
            s.status = Status.INVALID_NUMBER_DETECTED  # no model to start from
            result = s.result()
            result.objective, result.max_violation = nlp.objective(s.p.x), math.inf
            return result
        while s.it < self.options.termination.max_iter:
            if self._iteration(s):
                break
        return s.result()

    def _request(self, s: SolveState) -> StepRequest:
        """The subproblem at the current iterate."""
        o, nlp, p = self.options, s.nlp, s.p
        stop, tr, D = o.termination, o.trust_region, nlp.x_scale
        theta = p.v_max if p.v_max > stop.tol else s.pred  # the violation, else the decrease
        wide = (np.maximum((nlp.x_lb - p.x) / D, -tr.radius_max),
                np.minimum((nlp.x_ub - p.x) / D, tr.radius_max)) if s.trust < tr.radius_max else None
        return StepRequest(
            p=p, grad=nlp.gradient(p.x) * nlp.obj_scale * D, hess=s.hess, mu=s.mu,
            box=(np.maximum((nlp.x_lb - p.x) / D, -s.trust),
                 np.minimum((nlp.x_ub - p.x) / D, s.trust)),
            eps=float(np.clip(o.qp.eps_factor * theta * s.tighten, *o.qp.eps)),
            wide=wide, restore=None if wide is not None else o.restoration.radius,
            restoring=s.entry is not None and p.v_max > o.restoration.exit * s.entry,
            curvature=None if s.rows is None else s.rows.curvature())

    def _stationary(self, s: SolveState, step: Step, inexact: bool) -> bool:
        """Stopping rules 1 and 2: the hard QP, solved tightly enough (not ``inexact``),
        predicts no more than ``ftol``·J̃, or the last iterates form a plateau of Σu² at a
        (nearly) feasible point."""
        stop, nlp, p = self.options.termination, s.nlp, s.p
        recent = s.log[-stop.plateau_iterations:]
        return step.hard and ((not inexact and s.pred <= stop.ftol * max(p.f, 1e-3)) or (
            len(recent) == stop.plateau_iterations
            and all(r["violation"] <= 100 * stop.tol for r in recent)
            and recent[0]["objective"] - nlp.objective(p.x)
            < stop.plateau_ftol * recent[0]["objective"]))

    def _onto_rows(self, s: SolveState, side) -> None:
        """A stationary point a hair outside ``tol`` (the Gauss–Newton tail converges linearly
        on curved active rows): up to three Newton corrections onto the violated rows, first
        holding the subproblem's active rows at their bounds, as the line search's correction
        does (see newton_correction), else not: the tail then takes a few iterations fewer."""
        for _ in range(3):
            q = s.correct(s.p, side)
            if q.v.sum() >= s.p.v.sum():
                q = s.correct(s.p)
            if q.v.sum() >= s.p.v.sum():
                break
            s.p = q
            if s.p.v_max <= self.options.termination.tol:
                break

    def _search(self, s: SolveState, step: Step, side):
        """The line search along the step: on φ for a hard step, on ½‖v‖₂² for a restoration
        step (judged by the violation it removes, whatever Σu² does). Returns (trial, step
        length, ratio, accepted)."""
        nlp, p, sol = s.nlp, s.p, step.sol
        if step.hard:
            merit, decrease = (lambda q: q.merit(s.rho)), s.pred
        else:
            merit, decrease = _square_violation, _square_violation(p) - 0.5 * float(
                np.sum(_linearised_violation(nlp, p, sol.d, total=False) ** 2))
        if decrease <= 0:
            return None, 1.0, 0.0, False
        return _line_search(self.options, p, nlp.x_scale * sol.d, decrease, merit, s.point,
                            lambda q: s.correct(q, side))

    def _iteration(self, s: SolveState) -> bool:
        """One SQP iteration on ``s``; True when the solve ends (``s.status`` says how)."""
        o, nlp = self.options, s.nlp
        stop, tr = o.termination, o.trust_region
        s.it += 1
        r = self._request(s)
        v_before = s.p.v_max
        step = self.step(nlp, r)
        s.qp_iters += step.admm
        s.mu, sol, hard = step.mu, step.sol, step.hard
        with_rows = hard and s.rows is not None and step.qp is s.rows.qp
        s.rho, s.pred = _descent_model(nlp, s.p, sol, r.grad, s.hess, s.rho,
                                       s.rows.model_term(sol.d) if with_rows else 0.0)
        # A negative predicted decrease at a feasible point means the QP was solved too
        # loosely (d = 0 does better): not a stationary point — solve it again, tighter.
        inexact = hard and s.pred < 0 and s.p.v_max <= stop.tol and r.eps > o.qp.eps[0]
        s.tighten = 0.01 * s.tighten if inexact else 1.0
        stationary = self._stationary(s, step, inexact)
        side = np.sign(sol.multipliers) * (nlp.c_lo != nlp.c_hi) if hard else None  # active rows
        if stationary and s.p.v_max > stop.tol:
            self._onto_rows(s, side)
        trial, length, ratio, accepted = None, 1.0, 0.0, False
        if stationary and s.p.v_max <= stop.tol:
            s.status = Status.SOLVED
        elif sol.status in ("optimal", "optimal_inaccurate") and (s.pred > 0 or not hard):
            trial, length, ratio, accepted = self._search(s, step, side)
        d_len = float(np.abs(sol.d).max(initial=0.0))
        if (hard and not accepted and s.status != Status.SOLVED and s.p.v_max <= stop.tol
                and 0 < s.pred <= stop.reject_ftol * max(s.p.f, 1e-3)):
            s.status = Status.SOLVED  # feasible, and the model's small gain is not real
        if s.status != Status.SOLVED and not inexact:
            s.trust, s.mu = _adapt(o, accepted, length, ratio, d_len, s.trust, s.mu)
        if not hard:  # restoration: count the steps that barely reduce the violation
            gain = _square_violation(s.p) - _square_violation(trial) if accepted else 0.0
            s.stalls = s.stalls + 1 if gain < stop.stall_progress * _square_violation(s.p) else 0
        # The restoration phase: entered by an accepted restoration step, left when the
        # violation is down to restoration.exit × its value at entry (or a step is rejected).
        s.entry = (s.entry if s.entry is not None else v_before) if accepted and not hard else None
        if accepted and with_rows:  # the rows' curvature along the step, at the QP's multipliers
            lam, moved, D = sol.multipliers, trial.x - s.p.x, nlp.x_scale
            s.rows.update(moved / D, s.hess * moved / D + (trial.J.T @ lam - s.p.J.T @ lam),
                          s.hess)
        if accepted:
            s.p = trial
        s.log.append({"iter": s.it, "objective": nlp.objective(s.p.x), "violation": s.p.v_max,
                      "merit": float(s.p.merit(s.rho)), "pred": float(s.pred),
                      "ratio": float(ratio), "step": length if accepted else 0.0,
                      "trust": s.trust, "prox": s.mu, "rho": s.rho, "qp_iters": step.admm,
                      "qp_tries": step.tries, "qp_status": sol.status,
                      "polished": sol.polished, "elastic": step.qp.elastic})
        if s.status == Status.SOLVED:
            return True
        if s.trust <= tr.radius_min and not accepted:
            s.status = Status.STALLED
            return True
        if s.stalls >= stop.stall_iterations:
            s.status = Status.INFEASIBLE
            return True
        return False
