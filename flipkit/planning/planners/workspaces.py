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

__all__ = ["thread_workspace"]

_local = threading.local()


def thread_workspace():
    """This thread's workspace (:class:`~flipkit.solvers.compiled.SQPWorkspace`), made on
    first use; the solvers (cvxpy) are imported then, not when the planners are."""
    workspace = getattr(_local, "workspace", None)
    if workspace is None:
        from flipkit.solvers.compiled import SQPWorkspace

        workspace = _local.workspace = SQPWorkspace()
    return workspace
