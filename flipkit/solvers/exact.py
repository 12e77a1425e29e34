"""FATROP, exact-Hessian IPOPT and CasADi's sqpmethod on the segment NLP as a CasADi OCP.

The peers of the SQP on the very same problem: :class:`~flipkit.transcription.ocp_graph.
OcpGraph` states the segment's NLP — same feasible set, rows, bounds, variable and row
scales, and objective Σ u_i² — in FATROP's stage-wise form (knot states, explicit Simpson
dynamics) with exact first and second derivatives (CasADi's SX algorithmic
differentiation). Each peer is set up as its authors advise (``docs/peers.md``):

* ``fatrop``: FATROP, the structure-exploiting interior-point solver for optimal control
  shipped in CasADi's wheel, with the stage structure given by hand (``structure_detection:
  manual``, the graph's N, nx, nu, ng) as FATROP's CasADi cookbook does. FATROP has no
  automatic scaling: its objective is Σ u_i² · :data:`FATROP_OBJ_SCALE`, of order one at the
  translates' optima.
* ``ipopt``: IPOPT with the exact Hessian of the Lagrangian (MUMPS) on the graph with the
  SQP's objective scale; :mod:`flipkit.solvers.ipopt` is IPOPT with an L-BFGS Hessian
  through callbacks on the numerical NLP.
* ``sqpmethod``: CasADi's SQP with HPIPM, the structure-exploiting (Riccati) interior-point
  QP solver, given the same stage structure (HPIPM's OCP QP has no last control: the graph
  holds u_N as a state of its last stage). The exact Hessian of the Lagrangian is indefinite
  here and ``sqpmethod``'s convexifications did not converge (``docs/peers.md``); it gets the
  house SQP's choice instead, through its documented ``hess_lag`` option: the Gauss–Newton
  Hessian of Σ u_i² plus a proximal term :data:`SQPMETHOD_PROXIMAL` · I.

Building a solver (the graph, its derivatives, optionally JIT-compiled C) is done once per
problem by :class:`ExactSolver`; :meth:`ExactSolver.solve` times the solve alone. A solve is
``"solved"`` only if the solver reports success and the maximum scaled violation recomputed
by :meth:`NLP.evaluate` at the returned point (clipped to the bounds) is at most
``constr_viol_tol`` — the SQP's criterion.
"""

from __future__ import annotations

import contextlib
import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.solvers.names import EXACT_RESULT_NAMES, EXACT_SOLVERS
from flipkit.transcription.nlp import NLP
from flipkit.transcription.ocp_graph import OcpGraph
from flipkit.solvers.result import SolveResult, Status
from flipkit.solvers.step_profile import StepProfile, fatrop_profile, ipopt_profile
from flipkit.solvers.stdout_redirect import captured_stdout

#: FATROP's objective is Σ u_i² (N²·m²) times this, which puts it of order 1 at the translates'
#: optima, the scale FATROP's cookbook asks for; the SQP's own scale, an order of magnitude
#: smaller there, made FATROP fail a translate (docs/peers.md has the scales tried).
FATROP_OBJ_SCALE = 1e-4

#: The proximal term of ``sqpmethod``'s Gauss–Newton Hessian (scaled units): of the values
#: tried, the one with which it converges on the translates (docs/peers.md).
SQPMETHOD_PROXIMAL = 1e-4


@dataclass(frozen=True)
class ExactOptions:
    """Settings of the exact-derivative solvers (tolerances in the scaled units).

    Attributes:
        tol: IPOPT's overall convergence tolerance (its scaled KKT residual).
        fatrop_tol: FATROP's, and ``sqpmethod``'s dual tolerance. FATROP does not scale its
            KKT residual as IPOPT does, so at IPOPT's 1e-8 it reaches IPOPT's optimum (Σu²
            equal to 1e-6) and then iterates to its cap without declaring it. At 1e-6 it
            stops as close to IPOPT's optimum as the SQP does (docs/peers.md).
        constr_viol_tol: Largest scaled violation accepted; also the independent check.
        max_iter: Iteration cap (FATROP, IPOPT).
        sqpmethod_max_iter: ``sqpmethod``'s iteration cap.
        jit: Compile the graph's functions to C before solving (CasADi JIT, ``-O0``: the
            graph's C is too large for an optimising compile, docs/peers.md).
        print_level: Solver verbosity (0 silent).
        step_profile: Record each solve's :class:`~flipkit.solvers.step_profile.StepProfile`
            (``ExactSolver.last_profile``): FATROP then prints its iteration table, which is
            captured and read instead of shown.
    """

    tol: float = 1e-8
    fatrop_tol: float = 1e-6
    constr_viol_tol: float = 1e-6
    max_iter: int = 1000
    sqpmethod_max_iter: int = 200
    jit: bool = False
    print_level: int = 0
    step_profile: bool = False

    def graph_options(self, solver: str) -> dict:
        """The :class:`OcpGraph` settings ``solver`` needs (its objective scale, and whether
        the last stage has a control)."""
        return {"obj_scale": FATROP_OBJ_SCALE if solver == "fatrop" else None,
                "final_control": solver != "sqpmethod"}

    def plugin_options(self, solver: str, graph: OcpGraph) -> dict:
        """The :func:`casadi.nlpsol` options of ``solver`` for ``graph``."""
        common = {"print_time": False}
        if self.jit:
            common.update({"jit": True, "compiler": "shell",
                           "jit_options": {"flags": ["-O0"], "verbose": False}})
        if solver == "fatrop":
            return {**common, **graph.structure, "structure_detection": "manual",
                    "fatrop": {"print_level": 5 if self.step_profile else self.print_level,
                               "max_iter": self.max_iter,
                               "tol": self.fatrop_tol, "constr_viol_tol": self.constr_viol_tol}}
        if solver == "sqpmethod":
            return {**common, "qpsol": "hpipm", "hess_lag": gauss_newton_hessian(graph),
                    "max_iter": self.sqpmethod_max_iter, "tol_pr": self.constr_viol_tol,
                    "tol_du": self.fatrop_tol, "print_header": False,
                    "print_iteration": self.print_level > 0, "print_status": False,
                    "error_on_fail": False,
                    "qpsol_options": {**graph.structure, "error_on_fail": False,
                                      "hpipm": {"iter_max": 100}}}
        return {**common, "ipopt": {"print_level": self.print_level, "sb": "yes",
                                    "linear_solver": "mumps", "tol": self.tol,
                                    "constr_viol_tol": self.constr_viol_tol,
                                    "max_iter": self.max_iter,
                                    "hessian_approximation": "exact"}}


def gauss_newton_hessian(graph: OcpGraph) -> ca.Function:
    """``sqpmethod``'s ``hess_lag``: σ ∇²f + :data:`SQPMETHOD_PROXIMAL` · I (upper triangle),
    the constraints' curvature left out (f = obj_scale · Σ u_i², so ∇²f is constant)."""
    z = graph.problem["x"]
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", graph.problem["g"].numel())
    H = lam_f * ca.hessian(graph.problem["f"], z)[0] + SQPMETHOD_PROXIMAL * ca.SX.eye(graph.n)
    return ca.Function("nlp_hess_l", [z, ca.SX.sym("p", 0), lam_f, lam_g], [ca.triu(H)],
                       ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"])


class ExactSolver:
    """One solver (FATROP, exact-Hessian IPOPT or ``sqpmethod``) built for one segment NLP.

    Args:
        nlp: The NLP (every block with a symbolic form; e.g. built with
            ``SegmentOptions(arm_clearance=False)``).
        solver: One of :data:`EXACT_SOLVERS`.
        options: Settings.
        graph: The NLP's stage-wise graph, when already built (it can be shared), built
            with ``options.graph_options(solver)``.

    Attributes:
        build_time_s: Wall time (s) of building the graph (when not given) and the solver.
        last_profile: The last solve's :class:`~flipkit.solvers.step_profile.StepProfile`
            (IPOPT always; FATROP with ``options.step_profile``), else ``None``.

    Raises:
        InvalidChoiceError: ``solver`` is not one of :data:`EXACT_SOLVERS`.
        NoSymbolicFormError: A block of ``nlp`` has no symbolic form.
        ConfigError: ``graph`` was built with other settings than ``solver`` needs.
    """

    def __init__(self, nlp: NLP, solver: str = "fatrop", options: ExactOptions = ExactOptions(),
                 graph: OcpGraph | None = None):
        if solver not in EXACT_SOLVERS:
            raise InvalidChoiceError("exact-derivative solver", solver, EXACT_SOLVERS)
        t0 = time.perf_counter()
        self.nlp, self.name, self.options = nlp, solver, options
        self.graph = graph or OcpGraph(nlp, **options.graph_options(solver))
        wanted = options.graph_options(solver)
        if (self.graph.obj_scale != (wanted["obj_scale"] or nlp.obj_scale)
                or self.graph.final_control != wanted["final_control"]):
            raise ConfigError(f"segment {nlp.name!r}: the graph is not set up for {solver} "
                              f"(want {wanted})")
        self.function = ca.nlpsol(f"{solver}_{nlp.name}", solver, self.graph.problem,
                                  options.plugin_options(solver, self.graph))
        self.build_time_s = time.perf_counter() - t0
        self.last_profile: StepProfile | None = None

    def solve(self, x0=None, graph: OcpGraph | None = None) -> SolveResult:
        """Solve from ``x0`` (unscaled; default ``nlp.x0``, clipped to the bounds).

        Args:
            x0: Start point of the NLP (unscaled).
            graph: Solve this graph's NLP instead (its own bounds and start), with the solver
                built for this one: their :attr:`OcpGraph.key` must be equal (e.g. two
                translates between different poses).

        Returns:
            The result: ``x`` the unscaled NLP point (inside the bounds), ``objective`` the
            unscaled Σu² (N²·m²), ``iterations`` the solver's count, ``wall_time_s`` the solve
            alone (s), ``solver`` from :data:`EXACT_RESULT_NAMES`; status ``"solved"``, or
            IPOPT's own failure status, ``"fatrop_failed"`` (FATROP or ``sqpmethod``), or
            ``"violation_above_tol"``.

        Raises:
            ConfigError: ``graph`` is not the same graph as this solver's (up to bounds).
        """
        g = self.graph if graph is None else graph
        if g.key != self.graph.key:
            raise ConfigError(f"segment {g.nlp.name!r}: its graph differs from the one this "
                              f"{self.name} solver was built for")
        nlp = g.nlp
        x_start = np.clip(np.array(nlp.x0 if x0 is None else x0, float), nlp.x_lb, nlp.x_ub)
        capture = self.options.step_profile and self.name == "fatrop"
        with captured_stdout() if capture else contextlib.nullcontext([]) as printed:
            t0 = time.perf_counter()
            sol = self.function(x0=g.from_nlp_point(x_start), lbx=g.lbx, ubx=g.ubx,
                                lbg=g.lbg, ubg=g.ubg)
            wall = time.perf_counter() - t0
        stats = self.function.stats()
        self.last_profile = (fatrop_profile("".join(printed)) if capture
                             else ipopt_profile(stats) if self.name == "ipopt" else None)
        x = np.clip(g.to_nlp_point(sol["x"]), nlp.x_lb, nlp.x_ub)
        violation = float(nlp.scaled_violation(nlp.constraints(x)).max(initial=0.0))
        if stats.get("success", False):
            status = (Status.SOLVED if violation <= self.options.constr_viol_tol
                      else Status.VIOLATION_ABOVE_TOL)
        elif self.name in ("ipopt", "sqpmethod"):  # sqpmethod reports IPOPT's status names
            status = Status.from_ipopt(str(stats.get("return_status", "")))
        else:
            status = Status.FATROP_FAILED
        return SolveResult(x=x, status=status, iterations=int(stats.get("iter_count", 0)),
                           wall_time_s=wall, objective=nlp.objective(x), max_violation=violation,
                           solver=EXACT_RESULT_NAMES[self.name])


def solve_exact(nlp: NLP, solver: str = "fatrop", x0=None,
                options: ExactOptions = ExactOptions()) -> SolveResult:
    """Build :class:`ExactSolver` for ``nlp`` and solve from ``x0``; ``wall_time_s`` counts the
    solve alone (the build time is the solver's ``build_time_s``)."""
    return ExactSolver(nlp, solver, options).solve(x0)


__all__ = ["EXACT_SOLVERS", "ExactOptions", "ExactSolver", "solve_exact"]
