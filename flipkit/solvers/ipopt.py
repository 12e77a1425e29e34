"""IPOPT cross-check of the SQP: the same collocation NLP handed to CasADi's bundled IPOPT.

The solver consumes only the :class:`~flipkit.transcription.nlp.NLP` interface, in the scaled units the
SQP uses (:mod:`flipkit.solvers.sqp`):

    z = x / x_scale,   c̃(z) = c_scale ⊙ c(x_scale ⊙ z),   J̃(z) = obj_scale · Σ u_i².

The constraints reach IPOPT through two :class:`casadi.Callback` objects: one returns c̃(z),
the other — handed to CasADi by ``get_jacobian`` — the sparse Jacobian ∂c̃/∂z on the NLP's
fixed pattern (``jac_rows``, ``jac_cols``). The constraint callback also declares that
pattern (``get_jac_sparsity``): without it CasADi takes ∂c̃/∂z as dense, and IPOPT's KKT
matrix fills in, its factorisation many times dearer per iteration. Both
callbacks read from a one-point cache, so c and its Jacobian at the same z cost one
:meth:`NLP.evaluate`. The objective is quadratic in the torques and is written as a CasADi
expression, so its gradient is exact.

Differences from the paper's setup (Sec. IV.C: IPOPT with the HSL linear solver ma57):

* the linear solver is MUMPS, the one bundled with CasADi;
* IPOPT gets no second derivatives of the constraints — the NLP interface provides first
  derivatives only — so it runs with ``hessian_approximation = "limited-memory"``, i.e. an
  L-BFGS approximation of the Hessian of the Lagrangian, not the exact one. Expect more
  iterations than an exact-Hessian IPOPT would need; the optimum is the same.

A solve is reported ``"solved"`` only if IPOPT returns a success status *and* the maximum
scaled violation, recomputed here from :meth:`NLP.evaluate` at the returned point (clipped to
the variable bounds, which IPOPT relaxes by ``bound_relax_factor``), is at most
:attr:`IpoptOptions.constr_viol_tol` — the same criterion as the SQP's ``tol``. Runs are
deterministic: IPOPT and MUMPS use no randomisation, so the same problem, start point and
options give bit-identical iterates on a given machine (the BLAS build and thread count
may change the last digits elsewhere).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from flipkit.errors import NoSolutionFound
from flipkit.transcription.nlp import NLP
from flipkit.solvers.threads import single_threaded_blas
from flipkit.solvers.result import SolveResult, Status

#: IPOPT return statuses treated as convergence (the violation is checked independently).
IPOPT_SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


@dataclass(frozen=True)
class IpoptOptions:
    """IPOPT settings (all tolerances in the scaled units of the module docstring).

    Attributes:
        tol: IPOPT's overall convergence tolerance on the scaled NLP error (KKT residual).
        constr_viol_tol: Largest scaled constraint violation at convergence; also the
            threshold of the independent feasibility check (as the SQP's ``tol``).
        acceptable_tol: Looser KKT tolerance of IPOPT's "acceptable" termination.
        acceptable_iter: Consecutive acceptable iterates that end the solve.
        max_iter: Cap on IPOPT iterations.
        max_wall_time: Cap on the wall-clock time of the solve (s).
        lbfgs_memory: Number of correction pairs kept by the L-BFGS Hessian approximation.
        linear_solver: IPOPT linear solver (the bundled build has ``mumps``).
        print_level: IPOPT verbosity (0 = silent, 5 = IPOPT's default iteration table).
        extra: Further IPOPT options as ``(name, value)`` pairs, applied last.
    """

    tol: float = 1e-8
    constr_viol_tol: float = 1e-6
    acceptable_tol: float = 1e-6
    acceptable_iter: int = 15
    max_iter: int = 3000
    max_wall_time: float = 300.0
    lbfgs_memory: int = 20
    linear_solver: str = "mumps"
    print_level: int = 0
    extra: tuple = ()

    def ipopt_dict(self) -> dict:
        """The options as the ``ipopt`` sub-dictionary of :func:`casadi.nlpsol`."""
        opts = {
            "tol": self.tol,
            "constr_viol_tol": self.constr_viol_tol,
            "acceptable_tol": self.acceptable_tol,
            "acceptable_constr_viol_tol": self.constr_viol_tol,
            "acceptable_iter": self.acceptable_iter,
            "max_iter": self.max_iter,
            "max_wall_time": self.max_wall_time,
            "hessian_approximation": "limited-memory",
            "limited_memory_max_history": self.lbfgs_memory,
            "linear_solver": self.linear_solver,
            "print_level": self.print_level,
            "sb": "yes",  # no IPOPT banner
        }
        opts.update(dict(self.extra))
        return opts


@dataclass
class IpoptResult(SolveResult):
    """A :class:`~flipkit.solvers.result.SolveResult` with IPOPT's own return status.

    Attributes:
        return_status: IPOPT's ``return_status`` string (e.g. ``"Solve_Succeeded"``);
            ``status`` is ``"solved"`` or, on failure, this string (or
            ``"violation_above_tol"`` when IPOPT claimed success on an infeasible point).
        evaluations: Calls of :meth:`NLP.evaluate` made for IPOPT (one per distinct
            point; c and its Jacobian at the same point share one).
    """

    return_status: str = ""
    evaluations: int = 0


class _EvalCache:
    """One-point cache of :meth:`NLP.evaluate` in scaled units.

    Args:
        nlp: The problem.
    """

    def __init__(self, nlp: NLP):
        self.nlp = nlp
        self.key: bytes | None = None
        self.c_scaled = np.zeros(nlp.m)
        self.jac_scaled = np.zeros(len(nlp.jac_rows))
        self.evaluations = 0
        self._jscale = nlp.c_scale[nlp.jac_rows] * nlp.x_scale[nlp.jac_cols]

    def at(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Scaled constraints c̃(z) (m,) and Jacobian entries (nnz,) in pattern order."""
        z = np.ascontiguousarray(z, dtype=float).ravel()
        key = z.tobytes()
        if key != self.key:
            c, jac = self.nlp.evaluate(z * self.nlp.x_scale)
            self.c_scaled = self.nlp.c_scale * c
            self.jac_scaled = jac * self._jscale
            self.key = key
            self.evaluations += 1
        return self.c_scaled, self.jac_scaled


class _JacobianCallback(ca.Callback):
    """CasADi function (z, c̃ nominal) ↦ ∂c̃/∂z, sparse on the NLP's pattern.

    Args:
        name, inames, onames, opts: As passed by CasADi to ``get_jacobian``.
        cache: Shared evaluation cache. sparsity: Column-compressed pattern of ∂c̃/∂z.
        order: Permutation taking pattern-order entries to the sparsity's nonzero order.
    """

    def __init__(self, name, inames, onames, opts, cache: _EvalCache, sparsity: ca.Sparsity,
                 order: np.ndarray):
        ca.Callback.__init__(self)
        self.cache, self.sparsity, self.order = cache, sparsity, order
        self.inames, self.onames = list(inames), list(onames)
        self.construct(name, opts)

    def get_n_in(self):
        return 2

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return self.inames[i]

    def get_name_out(self, i):
        return self.onames[i]

    def get_sparsity_in(self, i):
        nlp = self.cache.nlp
        # The nominal output c̃ is not needed: declare it structurally empty.
        return ca.Sparsity.dense(nlp.n, 1) if i == 0 else ca.Sparsity(nlp.m, 1)

    def get_sparsity_out(self, i):
        return self.sparsity

    def eval(self, arg):
        _, jac = self.cache.at(np.asarray(arg[0]))
        return [ca.DM(self.sparsity, jac[self.order])]


class _ConstraintCallback(ca.Callback):
    """CasADi function z ↦ c̃(z) with an analytic sparse Jacobian.

    Args:
        name: Function name. cache: Shared evaluation cache.
    """

    def __init__(self, name: str, cache: _EvalCache):
        ca.Callback.__init__(self)
        self.cache = cache
        nlp = cache.nlp
        # Column-major (CasADi CCS) order of the pattern entries; the pattern has no
        # duplicate (row, col) pairs by construction of the blocks (checked).
        key = nlp.jac_cols.astype(np.int64) * nlp.m + nlp.jac_rows.astype(np.int64)
        self.order = np.argsort(key, kind="stable")
        if np.any(np.diff(key[self.order]) == 0):
            raise ValueError(f"NLP {nlp.name!r}: duplicate entries in the Jacobian pattern")
        rows, cols = nlp.jac_rows[self.order], nlp.jac_cols[self.order]
        colind = np.searchsorted(cols, np.arange(nlp.n + 1)).astype(int).tolist()
        self.sparsity = ca.Sparsity(nlp.m, nlp.n, colind, rows.astype(int).tolist())
        self._jacobian = None  # keeps the Jacobian callback alive
        self.construct(name, {})

    def get_n_in(self):
        return 1

    def get_n_out(self):
        return 1

    def get_sparsity_in(self, i):
        return ca.Sparsity.dense(self.cache.nlp.n, 1)

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(self.cache.nlp.m, 1)

    def eval(self, arg):
        c, _ = self.cache.at(np.asarray(arg[0]))
        return [ca.DM(c)]

    def has_jac_sparsity(self, oind, iind):
        return True

    def get_jac_sparsity(self, oind, iind, symmetric):
        # Without it CasADi assumes a dense ∂c̃/∂z and IPOPT's KKT matrix fills in.
        return self.sparsity

    def has_jacobian(self):
        return True

    def get_jacobian(self, name, inames, onames, opts):
        self._jacobian = _JacobianCallback(name, inames, onames, opts, self.cache,
                                           self.sparsity, self.order)
        return self._jacobian


def _iteration_log(stats: dict) -> list[dict]:
    """IPOPT's per-iteration statistics as a list of dicts (scaled units).

    Keys: ``iter``, ``objective`` (scaled J̃), ``inf_pr`` (primal infeasibility), ``inf_du``
    (dual infeasibility), ``mu`` (barrier parameter), ``d_norm`` (step, ∞-norm, scaled),
    ``alpha_pr``, ``alpha_du`` (primal and dual step lengths), ``regularization`` (Hessian
    regularisation δ_w, 0 when none). Keys IPOPT did not record are left out.
    """
    it = stats.get("iterations") or {}
    names = {"obj": "objective", "inf_pr": "inf_pr", "inf_du": "inf_du", "mu": "mu",
             "d_norm": "d_norm", "alpha_pr": "alpha_pr", "alpha_du": "alpha_du",
             "regularization_size": "regularization"}
    cols = {new: list(it[old]) for old, new in names.items() if old in it}
    count = min((len(v) for v in cols.values()), default=0)
    return [{"iter": k, **{name: float(v[k]) for name, v in cols.items()}} for k in range(count)]


def _inconsistent_bounds(nlp: NLP) -> tuple[str, float] | None:
    """(group, gap) of the widest crossed bound pair (lower > upper), or ``None``.

    The gap is in scaled units: (lb − ub)/x_scale for variables (group ``bounds``),
    c_scale·(lo − hi) for constraint rows (group: the block's name). IPOPT cannot be called
    with crossed bounds (CasADi rejects the problem), so this is checked first.
    """
    gaps = {"bounds": float(((nlp.x_lb - nlp.x_ub) / nlp.x_scale).max(initial=0.0))}
    c_gap = nlp.c_scale * (nlp.c_lo - nlp.c_hi)
    for name, rows in nlp.block_slices.items():
        gaps[name] = float(c_gap[rows].max(initial=0.0))
    group = max(gaps, key=gaps.get)
    return (group, gaps[group]) if gaps[group] > 0 else None


def solve_ipopt(nlp: NLP, x0=None, options: IpoptOptions = IpoptOptions(),
                raise_on_failure: bool = True) -> IpoptResult:
    """Solve ``nlp`` with IPOPT (L-BFGS Hessian, MUMPS) from ``x0`` (default ``nlp.x0``), BLAS
    on one thread (:mod:`flipkit.solvers.threads`).

    Args:
        nlp: The collocation NLP.
        x0: Start point in unscaled units (n,); clipped to the variable bounds.
        options: IPOPT settings.
        raise_on_failure: Raise instead of returning a result whose status is not
            ``"solved"``.

    Returns:
        The result: ``x`` unscaled and inside the bounds, ``objective`` the unscaled Σu²
        (N²·m²), ``max_violation`` the max scaled violation of constraints and bounds at
        ``x``, ``iterations`` IPOPT's iteration count (``stats()["iter_count"]``),
        ``wall_time_s`` the wall time of the whole call (s, including building the CasADi
        problem), ``log`` IPOPT's per-iteration statistics (see :func:`_iteration_log`),
        ``solver`` ``"ipopt"``, ``return_status`` IPOPT's own status string.

    Raises:
        NoSolutionFound: IPOPT did not report success, or the returned point violates a
            constraint by more than ``options.constr_viol_tol`` (scaled), or a lower bound
            exceeds its upper bound (status ``"inconsistent_bounds"``, IPOPT not called).
            The exception carries the NLP, the status, the worst constraint group and its
            violation, and the result.
    """
    with single_threaded_blas():
        return _solve_ipopt(nlp, x0, options, raise_on_failure)


def _solve_ipopt(nlp: NLP, x0, options: IpoptOptions, raise_on_failure: bool) -> IpoptResult:
    """The body of :func:`solve_ipopt`."""
    t0 = time.perf_counter()
    D = nlp.x_scale
    x_start = np.clip(np.array(nlp.x0 if x0 is None else x0, float), nlp.x_lb, nlp.x_ub)
    crossed = _inconsistent_bounds(nlp)
    if crossed is not None:
        c, _ = nlp.evaluate(x_start)
        result = IpoptResult(x=x_start, status=Status.INCONSISTENT_BOUNDS, iterations=0,
                             wall_time_s=time.perf_counter() - t0,
                             objective=nlp.objective(x_start),
                             max_violation=max(float(nlp.scaled_violation(c).max(initial=0.0)),
                                               crossed[1]),
                             solver="ipopt", return_status="not_called", evaluations=1)
        if raise_on_failure:
            raise NoSolutionFound(nlp, result.status, crossed[0], crossed[1], result)
        return result
    cache = _EvalCache(nlp)
    constraints = _ConstraintCallback(f"c_{nlp.name}", cache)

    z = ca.MX.sym("z", nlp.n)
    u_scale = D[nlp.u_index]
    u = z[nlp.u_index.tolist()] * ca.DM(u_scale)
    f = nlp.obj_scale * ca.sumsqr(u)
    problem = {"x": z, "f": f, "g": constraints(z)}
    solver = ca.nlpsol(f"ipopt_{nlp.name}", "ipopt", problem,
                       {"ipopt": options.ipopt_dict(), "print_time": False,
                        "verbose_init": False})
    sol = solver(x0=x_start / D, lbx=nlp.x_lb / D, ubx=nlp.x_ub / D,
                 lbg=nlp.c_scale * nlp.c_lo, ubg=nlp.c_scale * nlp.c_hi)
    stats = solver.stats()
    return_status = str(stats.get("return_status", "unknown"))

    x = np.clip(np.asarray(sol["x"], float).ravel() * D, nlp.x_lb, nlp.x_ub)
    c, _ = nlp.evaluate(x)
    violation = float(nlp.scaled_violation(c).max(initial=0.0))
    if return_status in IPOPT_SUCCESS:
        status = (Status.SOLVED if violation <= options.constr_viol_tol
                  else Status.VIOLATION_ABOVE_TOL)
    else:
        status = Status.from_ipopt(return_status)
    result = IpoptResult(x=x, status=status, iterations=int(stats.get("iter_count", 0)),
                         wall_time_s=time.perf_counter() - t0, objective=nlp.objective(x),
                         max_violation=violation, solver="ipopt", log=_iteration_log(stats),
                         return_status=return_status, evaluations=cache.evaluations)
    if status != Status.SOLVED and raise_on_failure:
        group, amount = nlp.worst_group(x)
        raise NoSolutionFound(nlp, status, group, amount, result)
    return result


__all__ = ["IPOPT_SUCCESS", "IpoptOptions", "IpoptResult", "solve_ipopt"]
