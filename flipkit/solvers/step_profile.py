"""Why an interior-point peer takes the iterations it takes: how often it regularised its
Hessian and how often it cut its primal step below half.

An interior-point method regularises the Hessian of the Lagrangian (adds δ I) when the KKT
matrix has the wrong inertia, i.e. when the problem is not convex along its constraints
there. Its line search then often takes short primal steps. Both cost iterations. IPOPT
reports them per iteration in its statistics (``regularization_size``, ``alpha_pr``).
FATROP does not: it prints them in its iteration table (columns ``lg(rg)``, "-" when it did
not regularise, and ``alpha_pr``, with a one-letter suffix).
:func:`~flipkit.solvers.stdout_redirect.captured_stdout` collects that table, and
:func:`fatrop_profile` reads it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

SHORT_STEP = 0.5  # a primal step length below this counts as cut short
_ROW = re.compile(r"^\s*\d+\s+[-+0-9.eE]+\s")  # a row of FATROP's iteration table
_NUMBER = re.compile(r"[-+0-9.eE]+")


@dataclass(frozen=True)
class StepProfile:
    """Counts over one solve's iterations (the start, iteration 0, not counted).

    Attributes:
        iterations: Iterations. regularised: Iterations whose Hessian was regularised.
        short_steps: Iterations whose primal step length was below :data:`SHORT_STEP`.
    """

    iterations: int
    regularised: int
    short_steps: int


def ipopt_profile(stats: dict) -> StepProfile | None:
    """From IPOPT's statistics (``casadi.Function.stats()``); ``None`` without them."""
    it = stats.get("iterations")
    if not it:
        return None
    reg, alpha = it["regularization_size"][1:], it["alpha_pr"][1:]
    return StepProfile(len(alpha), sum(r > 0 for r in reg), sum(a < SHORT_STEP for a in alpha))


def fatrop_profile(text: str) -> StepProfile | None:
    """From FATROP's printed iteration table (``print_level`` ≥ 5); ``None`` without one."""
    rows = [line.split() for line in text.splitlines() if _ROW.match(line)]
    rows = [r for r in rows[1:] if len(r) >= 10]  # row 0 is the start point
    if not rows:
        return None
    alpha = [float(_NUMBER.match(r[8]).group()) for r in rows]
    return StepProfile(len(rows), sum(r[6] != "-" for r in rows),
                       sum(a < SHORT_STEP for a in alpha))


__all__ = ["SHORT_STEP", "StepProfile", "fatrop_profile", "ipopt_profile"]
