"""OSQP's solution onto a compiled cvxpy problem's variables and constraint duals, without
cvxpy's unpacking on every solve.

``Problem.unpack_results`` inverts the whole reduction chain at each solve, a noticeable
share of an SQP iteration on the small condensed subproblems. For an OSQP solution that chain only selects, reshapes and negates: every
entry of a variable is one entry of OSQP's primal vector x, every entry of a constraint's dual
is plus or minus one entry of its dual vector y. :class:`SolutionMap` finds that signed
selection once, by unpacking coded vectors through cvxpy itself, then applies it; the values
it stores are those cvxpy would store, bit for bit. If cvxpy does anything else than select
and negate, building the map raises, so a change in cvxpy is caught there and not in a plan
(:class:`~flipkit.solvers.osqp_driver.OSQPDriver` then unpacks through cvxpy).
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import cvxpy as cp
import numpy as np

from flipkit.errors import SolverError
from flipkit.solvers.cvxpy_adapter import status_name, store_dual, store_value
from flipkit.solvers.osqp_status import SOLVED, OSQPStatus, PolishStatus


class SolutionMap:
    """Where each variable entry and constraint dual entry of ``problem`` lies in OSQP's x and y.

    Args:
        problem: A compiled (DPP) cvxpy problem. chain, inverse: Its solving chain and
            inverse data for OSQP (``get_problem_data``). n, m: Lengths of OSQP's x and y.

    Raises:
        SolverError: cvxpy's unpacking is not a signed selection of x and y.
    """

    def __init__(self, problem: cp.Problem, chain, inverse, n: int, m: int):
        codes_x = np.arange(1.0, n + 1.0)  # distinct exact codes: entry k of x is k + 1,
        codes_y = np.arange(n + 1.0, n + m + 1.0)  # entry k of y is n + k + 1
        info = SimpleNamespace(status_val=int(OSQPStatus.OSQP_SOLVED), status="solved",
                               obj_val=0.0, run_time=0.0, iter=0, setup_time=0.0,
                               solve_time=0.0, polish_time=0.0,
                               status_polish=int(PolishStatus.OSQP_POLISH_NOT_PERFORMED),
                               obj_val_polish=0.0)
        probe = SimpleNamespace(x=codes_x, y=codes_y, info=info, prim_inf_cert=None,
                                dual_inf_cert=None)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            problem.unpack_results(probe, chain, inverse)
        self.variables = [(v, self._index(v.value, 1, n, v.name())) for v in problem.variables()]
        self.duals = []
        for con in problem.constraints:
            code = np.asarray(con.dual_value, float)
            index = self._index(np.abs(code), n + 1, m, f"the dual of constraint {con.id}")
            self.duals.append((con, index, np.sign(code)))

    @staticmethod
    def _index(code, first: int, size: int, what: str) -> np.ndarray:
        code = np.asarray(code, float)
        index = code - first
        if not (np.all(index == np.round(index)) and np.all((index >= 0) & (index < size))):
            raise SolverError(f"cvxpy's unpacking of {what} is not a selection of OSQP's "
                              "solution: unpack through cvxpy instead")
        return index.astype(np.int64)

    def apply(self, res) -> str:
        """Store a solved OSQP result's (:data:`~flipkit.solvers.osqp_status.SOLVED`) values on the variables and duals, as
        ``unpack_results`` would; return cvxpy's name of the status."""
        if res.info.status_val not in SOLVED:
            raise SolverError(f"no solution to map: OSQP status {res.info.status!r}")
        for var, index in self.variables:
            store_value(var, res.x[index])
        for con, index, sign in self.duals:
            store_dual(con, sign * res.y[index])
        return status_name(res.info.status_val)


__all__ = ["SolutionMap"]
