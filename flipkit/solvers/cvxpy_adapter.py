"""Everything flipkit reads of cvxpy beyond stating a problem, in one module.

The SQP's subproblems are stated in cvxpy (Variables, Parameters, a DPP Problem). To solve
them many times with one OSQP object, flipkit needs cvxpy's compiled problem, and cvxpy's
public API gives it through ``Problem.get_problem_data(cp.OSQP)``: the QP data, the solving
chain and its inverse data (which ``Problem.unpack_results`` takes back). What that API
does not make public, and this module reads all the same, is

* the parametrised program under ``data[cvxpy.settings.PARAM_PROB]``: the sparse tensors
  that map the parameter vector to the cone program's data (:class:`AffineProgram`);
* cvxpy's names of OSQP's statuses (its OSQP interface's ``STATUS_MAP``);
* a sparse Parameter's pattern (``sparse_idx``), and the setters ``save_value`` /
  ``save_dual_value`` that ``unpack_results`` itself uses.

These are written against cvxpy :data:`CVXPY_VERSION`, the version ``environment.lock``
pins; ``tests/test_cvxpy_adapter.py`` checks both, and :class:`~flipkit.solvers.param_map.ParameterMap`
and :class:`~flipkit.solvers.solution_map.SolutionMap` check their use of them against
cvxpy's own public results when they are built, so a change in cvxpy fails there and not in
a plan.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import cvxpy as cp
import numpy as np
import scipy.sparse as sp
from cvxpy.reductions.solvers.qp_solvers.osqp_qpif import OSQP as _CvxpyOSQP

__all__ = ["AffineProgram", "CVXPY_VERSION", "affine_program", "osqp_form", "problem_data",
           "sparsity", "status_name", "store_dual", "store_value"]

CVXPY_VERSION = "1.9.3"
"""The cvxpy release this adapter is written against (``environment.lock``'s pin)."""


def problem_data(problem: cp.Problem):
    """cvxpy's compiled problem for OSQP at the parameters' current values: (data, chain,
    inverse data), as ``problem.get_problem_data(cp.OSQP)`` returns them. The chain and the
    inverse data do not depend on the values (DPP)."""
    with warnings.catch_warnings():  # cvxpy reads sparse parameters through `.value`
        warnings.filterwarnings("ignore", "Reading from a sparse", RuntimeWarning)
        return problem.get_problem_data(cp.OSQP)


def osqp_form(data: dict):
    """(P upper triangle, A, q, l, u) for OSQP from cvxpy's QP data (``A x = b``, ``F x ≤ g``)."""
    A = sp.vstack([data["A"], data["F"]]).tocsc()
    b, g = data["b"], data["G"]
    l = np.concatenate([b, np.full(g.shape, -np.inf)])
    return sp.triu(data["P"], format="csc"), A, data["q"], l, np.concatenate([b, g])


@dataclass(frozen=True)
class AffineProgram:
    """cvxpy's parametrised cone program: its data as linear maps of the parameter vector p
    (every parameter flattened in Fortran order at its column, then a constant 1).

    Attributes:
        columns: First column in p of each parameter, by parameter id.
        size: Length of p (the constant included).
        n: Variables of the cone program. n_eq: Its equality (zero-cone) rows, first.
        A: [A | b] of the cone program, flattened column-major, as a sparse (m·(n+1) × size)
            tensor; its m rows are ``A.shape[0] // (n + 1)``.
        P: P flattened column-major, (n·n × size). q: [q; constant] (≥ n rows × size).
    """

    columns: dict
    size: int
    n: int
    n_eq: int
    A: sp.spmatrix
    P: sp.spmatrix
    q: sp.spmatrix


def affine_program(data: dict) -> AffineProgram:
    """The :class:`AffineProgram` in ``data`` (from :func:`problem_data`)."""
    prog = data[cp.settings.PARAM_PROB]
    columns = {pid: col for pid, col in prog.param_id_to_col.items() if pid != -1}
    return AffineProgram(columns=columns, size=prog.total_param_size + 1, n=prog.x.size,
                         n_eq=prog.cone_dims.zero, A=prog.A, P=prog.P, q=prog.q)


def sparsity(prm: cp.Parameter):
    """The (rows, cols) pattern of a sparse Parameter, or None for a dense one."""
    return prm.sparse_idx


def status_name(status: int) -> str:
    """cvxpy's name (``"optimal"``, ``"infeasible"``, …) of an OSQP status value."""
    return _CvxpyOSQP.STATUS_MAP[int(status)]


def store_value(var: cp.Variable, value: np.ndarray) -> None:
    """Set a variable's value as ``Problem.unpack_results`` does."""
    var.save_value(value)


def store_dual(con: cp.Constraint, value: np.ndarray) -> None:
    """Set a constraint's dual value as ``Problem.unpack_results`` does."""
    con.save_dual_value(value)
