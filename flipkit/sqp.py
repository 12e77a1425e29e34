"""SQP with an exact-ℓ1 merit line search and Levenberg–Marquardt damping.

Merit φ(Z) = J̃(Z) + ρ ‖v(Z)‖₁, v the scaled constraint violation. Each iteration linearises
the constraints at Z_k and solves the convex subproblem (:mod:`flipkit.qp`, cvxpy + OSQP):
all linearised constraints hard, a proximal term ½μ‖d‖² and a step cap |d| ≤ Δ (scaled
units). If they are incompatible with the bounds, the *elastic* subproblem (ℓ1-penalised
slacks on every row) gives the step instead,
so an infeasible linearisation still yields a step. The step is accepted by backtracking
on φ (Armijo, η = 1e-4); ρ is kept above twice the largest equality multiplier (exactness)
and never below 10; μ acts as an inverse trust radius: ×10 when the full step's actual
merit decrease is under 0.1 of the predicted one, ×0.3 when it is over 0.5.
Converged: max scaled violation ≤ tol and predicted merit decrease ≤ ftol·max(1, J̃),
confirmed by an accurate QP solve. Curvature: the cost's exact Hessian plus partitioned
damped-BFGS blocks per node for the constraints; a Gauss–Newton restoration step precedes
the elastic QP when the linearisation is infeasible.

Why this globalisation rather than TrajOpt's penalty trust region: with every equality
softened by slacks the subproblem is LP-like and OSQP (ADMM) needs thousands of iterations
per solve; hard equalities plus the proximal term make it strongly convex and OSQP then
converges in tens to hundreds of iterations, warm-started.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import NoSolutionFound
from .nlp import NLP
from .qp import subproblem_for


@dataclass(frozen=True)
class SQPOptions:
    """Settings.

    Attributes:
        tol: Feasibility tolerance on the max scaled violation.
        ftol: Relative predicted merit decrease below which the iterate is stationary.
        rho0: Smallest ℓ1 penalty. step_cap: Bound Δ on |d| (scaled units).
        prox0, prox_min, prox_max: Levenberg–Marquardt weight μ of ½μ‖d‖² (scaled units).
        slack_reg: ½σ‖s‖² on the slacks (keeps the QP strongly convex).
        armijo: Sufficient-decrease fraction η. min_step: Smallest line-search step.
        max_iter: Cap on SQP iterations.
        accept_ratio: Smallest actual/predicted merit decrease for a full (or corrected) step.
        curvature: Constraint curvature in the subproblem: ``"bfgs"`` (partitioned damped
            BFGS on the per-node (q, q̇, q̈) blocks), ``"dynamics"`` (finite-difference
            Hessian of the dynamics rows only) or ``"none"``.
        bfgs_init: Initial diagonal of the BFGS blocks (scaled units).
        final_qp_eps: OSQP tolerance of the confirming solve at an apparently stationary point.
    """

    tol: float = 1e-6
    ftol: float = 1e-6
    rho0: float = 10.0
    step_cap: float = 1.0
    prox0: float = 1e-3
    prox_min: float = 1e-4
    prox_max: float = 1e4
    slack_reg: float = 1e3
    armijo: float = 1e-4
    min_step: float = 1e-2
    max_iter: int = 300
    accept_ratio: float = 0.1
    curvature: str = "bfgs"
    bfgs_init: float = 1e-4
    final_qp_eps: float = 1e-8


@dataclass
class SolveResult:
    """Outcome of a solve: iterate, status, statistics and the iteration log."""

    x: np.ndarray
    status: str
    iterations: int
    wall_time_s: float
    objective: float
    max_violation: float
    solver: str = "sqp"
    log: list = field(default_factory=list)
    qp_iterations: int = 0

    @property
    def success(self) -> bool:
        return self.status == "solved"


def _correction_residual(nlp: NLP, c: np.ndarray):
    """Scaled residuals c − bound and the rows to pull onto their bounds (equalities and
    violated inequalities), in the argument order of :func:`_min_norm_correction`."""
    lo, hi = nlp.c_scale * nlp.c_lo, nlp.c_scale * nlp.c_hi
    cs = nlp.c_scale * c
    target = np.where(cs < lo, lo, np.where(cs > hi, hi, cs))
    eq = nlp.c_lo == nlp.c_hi
    target[eq] = lo[eq]
    rows = np.flatnonzero(eq | (cs < lo) | (cs > hi))
    return cs - target, rows


def _min_norm_correction(J: sp.csr_matrix, r: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Δ = −J_Rᵀ (J_R J_Rᵀ)⁻¹ r_R: the least-norm step zeroing the linearised residuals r on
    the rows R (a singular system skips the correction)."""
    JE = J[rows]
    try:
        K = (JE @ JE.T + 1e-12 * sp.identity(len(rows))).tocsc()
        y = spla.spsolve(K, r[rows])
    except RuntimeError:  # singular: skip the correction
        return np.zeros(J.shape[1])
    delta = -(JE.T @ y)
    return np.where(np.isfinite(delta), delta, 0.0)


def _damped_bfgs(B: np.ndarray, s: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Powell-damped BFGS update of a positive definite block (Nocedal & Wright, Proc. 18.2)."""
    Bs = B @ s
    sBs = float(s @ Bs)
    if sBs <= 1e-16:
        return B
    sy = float(s @ y)
    if sy < 0.2 * sBs:
        theta = 0.8 * sBs / (sBs - sy)
        y = theta * y + (1 - theta) * Bs
        sy = float(s @ y)
    return B - np.outer(Bs, Bs) / sBs + np.outer(y, y) / sy


def _psd_quad(H: np.ndarray, d: np.ndarray) -> float:
    """dᵀ H₊ d with H₊ the PSD part of H (what the subproblem uses)."""
    w, V = np.linalg.eigh(0.5 * (H + H.T))
    return float(np.maximum(w, 0.0) @ (V.T @ d) ** 2)


def solve_sqp(nlp: NLP, x0=None, options: SQPOptions = SQPOptions(), raise_on_failure=True
              ) -> SolveResult:
    """Solve ``nlp`` from ``x0`` (default ``nlp.x0``).

    Raises:
        NoSolutionFound: Not converged to a feasible point (carries the NLP, status, the
            worst constraint group and its violation, and the result).
    """
    t0 = time.perf_counter()
    for elastic in (False, True):  # no warm start from another NLP: results must not depend
        subproblem_for(nlp, elastic).reset()  # on what was solved before in this process
    D = nlp.x_scale
    x = np.clip(np.array(nlp.x0 if x0 is None else x0, float), nlp.x_lb, nlp.x_ub)
    Jscale = nlp.c_scale[nlp.jac_rows] * D[nlp.jac_cols]
    hess = nlp.hessian_diagonal() * nlp.obj_scale * D**2
    J_of = lambda jac: sp.csr_matrix((jac * Jscale, (nlp.jac_rows, nlp.jac_cols)),
                                     shape=(nlp.m, nlp.n))

    def point(x):
        c, jac = nlp.evaluate(x)
        return c, jac, nlp.objective(x) * nlp.obj_scale, nlp.scaled_violation(c)

    c, jac, f, v = point(x)
    x_prev = x
    rho, mu = options.rho0, options.prox0
    lam = np.zeros(nlp.m)  # multipliers, raw row units
    eq_rows = np.flatnonzero(nlp.c_lo == nlp.c_hi)
    curvature = None
    log, qp_iters, status, it = [], 0, "max_iter", 0
    while it < options.max_iter:
        it += 1
        grad = nlp.gradient(x) * nlp.obj_scale * D
        J = J_of(jac)  # scaled Jacobian at Z_k, shared by the model, corrections and BFGS
        d_lo = np.maximum((nlp.x_lb - x) / D, -options.step_cap)
        d_hi = np.minimum((nlp.x_ub - x) / D, options.step_cap)
        sol, restored = None, False
        for elastic in (False, True):
            qp = subproblem_for(nlp, elastic)
            qp.update(nlp, nlp.c_scale * c, jac * Jscale, grad, hess + mu, d_lo, d_hi, rho,
                      options.slack_reg, curvature)
            sol = qp.solve()
            qp_iters += sol.iterations
            if sol.status == "optimal":
                break
            if not elastic and v.max(initial=0.0) > options.tol:
                # Restoration (before the slow elastic QP): a Gauss–Newton step onto the
                # equalities, J_E Δ = −c_E, kept if it lowers the violation.
                delta = _min_norm_correction(J, *_correction_residual(nlp, c))
                x_r = np.clip(x + D * delta, nlp.x_lb, nlp.x_ub)
                c_r, jac_r, f_r, v_r = point(x_r)
                if v_r.sum() < 0.5 * v.sum():
                    x, c, jac, f, v = x_r, c_r, jac_r, f_r, v_r
                    restored = True
                    break
        if restored:
            log.append({"iter": it, "objective": nlp.objective(x), "violation": float(v.max(initial=0)),
                        "merit": float(f + rho * v.sum()), "pred": 0.0, "ratio": 0.0, "step": 1.0,
                        "prox": mu, "rho": rho, "qp_iters": sol.iterations,
                        "qp_status": "restoration", "elastic": False})
            x_prev = x
            continue
        if sol.eq_duals is not None and sol.status == "optimal":
            rho = max(rho, 2.0 * float(np.abs(sol.eq_duals).max(initial=0.0)))
            lam_new = np.zeros(nlp.m)  # cvxpy: L = f + yᵀ(expr) for `expr == 0`
            lam_new[eq_rows] = sol.eq_duals * nlp.c_scale[eq_rows] / nlp.obj_scale
        else:
            lam_new = lam
        def model(sol):
            nonlocal rho
            d = sol.d
            c_lin = nlp.c_scale * c + J @ d
            lin_v = np.maximum(np.maximum(nlp.c_scale * nlp.c_lo - c_lin,
                                          c_lin - nlp.c_scale * nlp.c_hi), 0)
            curv = sum(_psd_quad(H, d[b]) for b, H in zip(nlp.curvature_blocks, curvature or []))
            model_f = grad @ d + 0.5 * d @ (hess * d) + 0.5 * curv
            reduction = v.sum() - lin_v.sum()
            if reduction > 0 and model_f > 0:
                # Penalty large enough for the step to be a descent direction of the merit
                # (the equality duals alone miss the inequality multipliers).
                rho = max(rho, 2.0 * model_f / reduction)
            merit = f + rho * v.sum()
            return d, merit, merit - (f + model_f + rho * lin_v.sum())

        d, merit, pred = model(sol)
        if sol.status == "optimal" and pred <= options.ftol * max(1.0, abs(f)):
            # Looks stationary: confirm with an accurate solve (OSQP's 1e-4 tolerance can
            # leave the linearised constraints violated by more than the current iterate).
            sol = qp.solve(eps=options.final_qp_eps)
            qp_iters += sol.iterations
            d, merit, pred = model(sol)
        step, accepted, ratio = 1.0, False, 0.0
        qp_ok = sol.status in ("optimal", "optimal_inaccurate")
        if (sol.status == "optimal" and v.max(initial=0.0) <= options.tol
                and pred <= options.ftol * max(1.0, abs(f))):
            status = "solved"
        elif qp_ok and pred > 0:
            # Second-order correction (Maratos effect): pull the full step back onto the
            # equality constraints by a minimum-norm Newton step, J_E Δ = −c_E(Z + d).
            x_full = np.clip(x + D * d, nlp.x_lb, nlp.x_ub)
            c_full, jac_full, f_full, v_full = point(x_full)
            ratio = (merit - (f_full + rho * v_full.sum())) / pred
            if ratio < options.accept_ratio:
                delta = _min_norm_correction(J, *_correction_residual(nlp, c_full))
                x_soc = np.clip(x + D * (d + delta), nlp.x_lb, nlp.x_ub)
                c_s, jac_s, f_s, v_s = point(x_soc)
                ratio_soc = (merit - (f_s + rho * v_s.sum())) / pred
                if ratio_soc >= options.accept_ratio:
                    x, c, jac, f, v, accepted = x_soc, c_s, jac_s, f_s, v_s, True
                    ratio = ratio_soc
            else:
                x, c, jac, f, v, accepted = x_full, c_full, jac_full, f_full, v_full, True
            step = 1.0 if accepted else 0.25
            while not accepted and step >= options.min_step:
                x_new = np.clip(x + step * D * d, nlp.x_lb, nlp.x_ub)
                c_n, jac_n, f_n, v_n = point(x_new)
                actual = merit - (f_n + rho * v_n.sum())
                if actual >= options.armijo * step * pred:
                    x, c, jac, f, v, accepted = x_new, c_n, jac_n, f_n, v_n, True
                    break
                step *= 0.25
        if accepted and options.curvature == "dynamics":
            lam = lam_new
            curvature = [nlp.obj_scale * np.outer(D[b], D[b]) * H
                         for b, H in zip(nlp.curvature_blocks, nlp.lagrangian_curvature(x, lam))]
        elif accepted and options.curvature == "bfgs" and sol.eq_duals is not None:
            # Partitioned damped BFGS on the per-node blocks (q, q̇, q̈): the constraint part
            # of the Lagrangian gradient, J̃ᵀỹ with this step's multipliers, at both ends.
            y_eq = np.zeros(nlp.m)
            y_eq[eq_rows] = sol.eq_duals
            g_new, g_old = J_of(jac).T @ y_eq, J.T @ y_eq
            s_all = (x - x_prev) / D
            if curvature is None:
                curvature = [options.bfgs_init * np.eye(len(b)) for b in nlp.curvature_blocks]
            curvature = [_damped_bfgs(B, s_all[b], (g_new - g_old)[b])
                         for B, b in zip(curvature, nlp.curvature_blocks)]
        x_prev = x
        # Levenberg–Marquardt update from the full step's agreement with the model.
        if status != "solved":
            if ratio < 0.1:
                mu = min(mu * 10.0, options.prox_max * 10)
            elif ratio > 0.5:
                mu = max(mu * 0.3, options.prox_min)
        log.append({"iter": it, "objective": nlp.objective(x), "violation": float(v.max(initial=0)),
                    "merit": float(f + rho * v.sum()), "pred": float(pred), "ratio": float(ratio),
                    "step": step if accepted else 0.0, "prox": mu, "rho": rho, "qp_iters": sol.iterations,
                    "qp_status": sol.status, "elastic": bool(sol is not None and qp.elastic)})
        if status == "solved":
            break
        if mu > options.prox_max:
            # Before giving up: a few minimum-norm Newton corrections onto the equalities
            # (feasibility polishing) — the iterate is usually stationary but a hair outside.
            x_c, c_c, jac_c = x, c, jac
            for _ in range(3):
                delta = _min_norm_correction(J_of(jac_c), *_correction_residual(nlp, c_c))
                x_c = np.clip(x_c + D * delta, nlp.x_lb, nlp.x_ub)
                c_c, jac_c, f_c, v_c = point(x_c)
                if v_c.max(initial=0.0) <= options.tol:
                    x, c, jac, f, v, status = x_c, c_c, jac_c, f_c, v_c, "solved"
                    break
            if status != "solved":
                status = "stalled"
            break
    result = SolveResult(x=x, status=status, iterations=it, wall_time_s=time.perf_counter() - t0,
                         objective=nlp.objective(x), max_violation=float(v.max(initial=0.0)),
                         log=log, qp_iterations=qp_iters)
    if status != "solved" and raise_on_failure:
        group, amount = nlp.worst_group(x)
        raise NoSolutionFound(nlp, status, group, amount, result)
    return result
