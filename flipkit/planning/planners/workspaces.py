"""The planners' SQP workspaces: one per thread, kept for the thread's life.

A workspace (:class:`~flipkit.solvers.compiled.SQPWorkspace`) holds each NLP structure's
compiled subproblems and their OSQP solvers. Compiling a subproblem (cvxpy's
canonicalisation) costs more than many of its solves, and every ``plan_*`` call makes a new
:class:`~flipkit.planning.planners.chain.Planner`, so the planners share a workspace between
the calls of one thread instead of compiling per plan.
A workspace serves one solve at a time, hence one per thread: threads planning at once (a
cell that plans while it executes) never share one. A planner given its own workspace uses
that one instead.
"""

from __future__ import annotations

import threading
from typing import Callable

__all__ = ["thread_workspace"]

_local = threading.local()


def thread_workspace(make: Callable):
    """This thread's workspace, made by ``make`` on first use.

    Args:
        make: Builds the workspace (:class:`~flipkit.solvers.compiled.SQPWorkspace`). The
            caller passes it, so that importing the planners does not load the solvers
            (cvxpy): they are loaded by the first solve.
    """
    workspace = getattr(_local, "workspace", None)
    if workspace is None:
        workspace = _local.workspace = make()
    return workspace
