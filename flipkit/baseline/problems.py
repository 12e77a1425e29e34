"""The baseline's compiled convex problems, kept by whoever runs the baseline many times.

Each end-effector optimisation states its subproblem once per shape (subbehaviour, sample
grid, cone samples, and for the fixed QP its duration and degree) as a cvxpy problem with
Parameters (DPP); cvxpy compiles it on its first solve, and later solves only set the
Parameters. :class:`CompiledProblems` holds them by key for as long as its holder keeps it:
:func:`flipkit.baseline.run_baseline` makes one per call unless it is given one, so a sweep
over burger locations that passes the same one compiles each problem once. Clarabel starts
every solve from nothing, so a result does not depend on what was solved before.
"""

from __future__ import annotations

from typing import Callable

__all__ = ["CompiledProblems"]


class CompiledProblems:
    """cvxpy problems by key, each built by its ``build`` on first use and then reused.

    Serves one solve at a time: a problem's Parameters hold the values of the solve under
    way, so threads running the baseline at once need one each.
    """

    def __init__(self):
        self._built: dict = {}

    def get(self, key: tuple, build: Callable):
        """The problem of ``key``, built by ``build()`` the first time it is asked for."""
        if key not in self._built:
            self._built[key] = build()
        return self._built[key]

    def __len__(self) -> int:
        return len(self._built)
