"""The SQP's settings (:func:`flipkit.solvers.sqp.solve_sqp`), in four groups, each validated on
construction.

* :class:`TerminationOptions`: when a solve ends, and with which status;
* :class:`TrustRegionOptions`: how a step is sized and accepted (trust box, Levenberg–Marquardt
  weight, line search, ℓ1 penalty);
* :class:`RestorationOptions`: the least-squares steps taken where the linearisation is
  infeasible;
* :class:`QPOptions`: the subproblem's form and OSQP's tolerance and iteration caps.

:class:`SQPOptions` holds one of each. Change one setting with :func:`dataclasses.replace`::

    SQPOptions(termination=TerminationOptions(max_iter=2))
    replace(o, qp=replace(o.qp, condense=False))

Lengths are in scaled variable units (every variable divided by ``nlp.x_scale``), violations
in scaled constraint units (``nlp.c_scale``); J̃ is the scaled cost ``obj_scale``·Σu². How the
stopping rules relate is in :mod:`flipkit.solvers.sqp` and ``docs/sqp.md``; how the defaults
were chosen, in ``docs/history.md``.

Raises (every class, on construction):
    ConfigError: A setting outside its valid range; the one-line message names the setting
        and the range.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

from flipkit.errors import ConfigError

__all__ = ["QPOptions", "RestorationOptions", "SQPOptions", "TerminationOptions",
           "TrustRegionOptions"]


def _require(ok: bool, name: str, valid: str, value) -> None:
    """Raise :class:`ConfigError` naming ``name``, its valid range and ``value`` unless ``ok``
    (``ok`` is False for NaN: every test is written as the valid range)."""
    if not ok:
        raise ConfigError(f"{name} must be {valid}, got {value!r}")


def _is_int(value) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


@dataclass(frozen=True)
class TerminationOptions:
    """When a solve ends. Every ``solved`` verdict needs the max scaled violation ≤ ``tol``.

    Attributes:
        tol: Feasibility tolerance on the max scaled violation (scaled constraint units);
            > 0.
        ftol: Stationarity: the hard QP's predicted merit decrease, relative to J̃ (J̃ taken
            as at least 1e-3), at or below which the iterate is stationary (dimensionless);
            > 0. A stationary iterate a hair outside ``tol`` gets up to three Newton
            corrections onto the rows first.
        reject_ftol: A feasible iterate whose hard step the line search rejects is solved
            when that step's predicted decrease was at most ``reject_ftol``·J̃ (the rows'
            curvature, which the model ignores, undid a small predicted gain); ≥ 0; 0 (or
            any value ≤ ``ftol``) switches the rule off.
        plateau_iterations: Window (iterations) of the plateau rule: a stationary iterate is
            also one after ``plateau_iterations`` iterates feasible to 100·``tol`` that
            together lowered Σu² by less than ``plateau_ftol``; ≥ 2.
        plateau_ftol: Relative decrease of Σu² over that window (dimensionless); in [0, 1).
        stall_iterations: Status ``infeasible`` after this many consecutive restoration
            steps that each cut ½‖v‖₂² by less than ``stall_progress`` (a stationary point
            of the violation); ≥ 1.
        stall_progress: Relative decrease of ½‖v‖₂² below which a restoration step counts
            as stalled (dimensionless); in [0, 1).
        max_iter: Cap on SQP iterations (status ``max_iter``); ≥ 1.
    """

    tol: float = 1e-6
    ftol: float = 1e-3
    reject_ftol: float = 1e-2
    plateau_iterations: int = 4
    plateau_ftol: float = 1e-2
    stall_iterations: int = 5
    stall_progress: float = 1e-2
    max_iter: int = 100

    def __post_init__(self):
        _require(self.tol > 0, "termination.tol", "> 0", self.tol)
        _require(self.ftol > 0, "termination.ftol", "> 0", self.ftol)
        _require(self.reject_ftol >= 0, "termination.reject_ftol", ">= 0", self.reject_ftol)
        _require(_is_int(self.plateau_iterations) and self.plateau_iterations >= 2,
                 "termination.plateau_iterations", "an integer >= 2", self.plateau_iterations)
        _require(0 <= self.plateau_ftol < 1, "termination.plateau_ftol", "in [0, 1)",
                 self.plateau_ftol)
        _require(_is_int(self.stall_iterations) and self.stall_iterations >= 1,
                 "termination.stall_iterations", "an integer >= 1", self.stall_iterations)
        _require(0 <= self.stall_progress < 1, "termination.stall_progress", "in [0, 1)",
                 self.stall_progress)
        _require(_is_int(self.max_iter) and self.max_iter >= 1, "termination.max_iter",
                 "an integer >= 1", self.max_iter)


@dataclass(frozen=True)
class TrustRegionOptions:
    """How a hard step is sized and accepted.

    Attributes:
        radius0: Initial trust box Δ, |d|∞ ≤ Δ (scaled variable units); in
            [``radius_min``, ``radius_max``].
        radius_min: Smallest Δ: a step rejected there ends the solve as ``stalled``
            (scaled variable units); > 0.
        radius_max: Largest Δ (scaled variable units); ≥ ``radius0``, and at most the
            restoration box :attr:`RestorationOptions.radius`. Where the hard QP is
            infeasible in a shrunken box it is solved in this one.
        prox: Initial Levenberg–Marquardt weight μ of ½μ‖d‖² (in units of the scaled
            cost's Hessian); in ``prox_range``.
        prox_range: (smallest, largest) μ; 0 < smallest ≤ largest. μ is divided by 4 after a
            full, well predicted step, multiplied by 4 after a shortened or rejected one, and
            multiplied by 10 (up to the largest) when OSQP runs out of iterations.
        eta: Sufficient-decrease fraction of the predicted merit decrease (dimensionless);
            in (0, 1).
        good_ratio: actual/predicted decrease of a full step at or above which μ falls and
            Δ may double (dimensionless); > 0.
        backtracks: Halvings of the step tried before it is rejected; ≥ 0.
        second_order_correction: Before judging a full step that raised the violation and
            fell short of its prediction, try a minimum-norm Newton correction at its end
            (holding the subproblem's active rows). Off by default: with the rows' curvature
            in the model (:attr:`QPOptions.quasi_newton`) it costs more evaluations than it
            saves iterations.
        rho_min: Smallest ℓ1 penalty ρ of the merit J̃ + ρ‖v‖₁ (scaled cost per scaled
            violation); > 0.
    """

    radius0: float = 1.0
    radius_min: float = 1e-6
    radius_max: float = 1.0
    prox: float = 1e-3
    prox_range: tuple[float, float] = (1e-5, 1.0)
    eta: float = 0.1
    good_ratio: float = 0.5
    backtracks: int = 5
    second_order_correction: bool = False
    rho_min: float = 1e-3

    def __post_init__(self):
        _require(self.radius_min > 0, "trust_region.radius_min", "> 0", self.radius_min)
        _require(self.radius_min <= self.radius0 <= self.radius_max, "trust_region.radius0",
                 f"in [radius_min, radius_max] = [{self.radius_min!r}, {self.radius_max!r}]",
                 self.radius0)
        _require(len(self.prox_range) == 2 and 0 < self.prox_range[0] <= self.prox_range[1],
                 "trust_region.prox_range", "(smallest, largest) with 0 < smallest <= largest",
                 self.prox_range)
        _require(self.prox_range[0] <= self.prox <= self.prox_range[1], "trust_region.prox",
                 f"in prox_range = [{self.prox_range[0]!r}, {self.prox_range[1]!r}]", self.prox)
        _require(0 < self.eta < 1, "trust_region.eta", "in (0, 1)", self.eta)
        _require(self.good_ratio > 0, "trust_region.good_ratio", "> 0", self.good_ratio)
        _require(_is_int(self.backtracks) and self.backtracks >= 0, "trust_region.backtracks",
                 "an integer >= 0", self.backtracks)
        _require(isinstance(self.second_order_correction, bool),
                 "trust_region.second_order_correction", "True or False",
                 self.second_order_correction)
        _require(self.rho_min > 0, "trust_region.rho_min", "> 0", self.rho_min)


@dataclass(frozen=True)
class RestorationOptions:
    """The restoration step where the linearisation is infeasible: minimise
    ½σ‖s‖² + ½μ_r‖d‖² over the step d and slacks s, a Levenberg–Marquardt step on the
    violation, judged by the ½‖v‖₂² it removes.

    Attributes:
        radius: The restoration box |d|∞ ≤ ``radius`` (∩ the variable bounds) while the
            trust box is at its largest; after the trust box has shrunk, the restoration
            keeps it (scaled variable units); ≥ :attr:`TrustRegionOptions.radius_max`.
        exit: A restoration phase (the steps after an accepted restoration step, restoration
            alone) lasts until the max violation is down to ``exit`` × its value when the
            phase began (dimensionless); in [0, 1); 0 ends it after every step.
        prox: μ_r, the weight of ½μ_r‖d‖² (in units of σ); > 0.
        slack_reg: σ, the weight of ½σ‖s‖² (per scaled violation squared); > 0.
    """

    radius: float = 4.0
    exit: float = 0.3
    prox: float = 1e-4
    slack_reg: float = 1.0

    def __post_init__(self):
        _require(self.radius > 0, "restoration.radius", "> 0", self.radius)
        _require(0 <= self.exit < 1, "restoration.exit", "in [0, 1)", self.exit)
        _require(self.prox > 0, "restoration.prox", "> 0", self.prox)
        _require(self.slack_reg > 0, "restoration.slack_reg", "> 0", self.slack_reg)


@dataclass(frozen=True)
class QPOptions:
    """The subproblem and OSQP.

    Attributes:
        condense: Solve the hard and restoration subproblems in condensed form
            (:mod:`flipkit.solvers.condensed_qp`); False solves the full-space QPs of
            :mod:`flipkit.solvers.full_qp` (slower; the condensed form's QP without
            ``quasi_newton``).
        eps: (smallest, largest) OSQP tolerance (scaled units); 0 < smallest ≤ largest.
        eps_factor: OSQP tolerance = ``eps_factor`` × the max violation (at a feasible
            iterate: × the last predicted decrease), clipped to ``eps`` (inexact SQP:
            loose far from a solution, tight near it); > 0.
        max_iter: OSQP iteration caps of the three tries of the hard QP (the third also caps
            the hard QP in the largest box; the first, the condensed restoration QP); three
            integers ≥ 1.
        quasi_newton: Add a damped BFGS estimate of the rows' curvature in the condensed
            null space to the Gauss–Newton model (:mod:`flipkit.solvers.reduced_hessian`);
            with ``condense`` only (the full-space form keeps the Gauss–Newton model).
    """

    condense: bool = True
    eps: tuple[float, float] = (1e-9, 1e-4)
    eps_factor: float = 0.1
    max_iter: tuple[int, int, int] = (2000, 10000, 10000)
    quasi_newton: bool = True

    def __post_init__(self):
        _require(isinstance(self.condense, bool), "qp.condense", "True or False", self.condense)
        _require(isinstance(self.quasi_newton, bool), "qp.quasi_newton", "True or False",
                 self.quasi_newton)
        _require(len(self.eps) == 2 and 0 < self.eps[0] <= self.eps[1], "qp.eps",
                 "(smallest, largest) with 0 < smallest <= largest", self.eps)
        _require(self.eps_factor > 0 and math.isfinite(self.eps_factor), "qp.eps_factor",
                 "finite and > 0", self.eps_factor)
        _require(len(self.max_iter) == 3 and all(_is_int(n) and n >= 1 for n in self.max_iter),
                 "qp.max_iter", "three integers >= 1", self.max_iter)


@dataclass(frozen=True)
class SQPOptions:
    """Every SQP setting, by group; the defaults are the planner's.

    Attributes:
        termination: When a solve ends (:class:`TerminationOptions`).
        trust_region: Step size and acceptance (:class:`TrustRegionOptions`).
        restoration: Steps where the linearisation is infeasible
            (:class:`RestorationOptions`).
        qp: The subproblem and OSQP (:class:`QPOptions`).

    Raises:
        ConfigError: A group of the wrong type, or ``trust_region.radius_max`` above
            ``restoration.radius``.
    """

    termination: TerminationOptions = field(default_factory=TerminationOptions)
    trust_region: TrustRegionOptions = field(default_factory=TrustRegionOptions)
    restoration: RestorationOptions = field(default_factory=RestorationOptions)
    qp: QPOptions = field(default_factory=QPOptions)

    def __post_init__(self):
        for name, kind in (("termination", TerminationOptions),
                           ("trust_region", TrustRegionOptions),
                           ("restoration", RestorationOptions), ("qp", QPOptions)):
            value = getattr(self, name)
            _require(isinstance(value, kind), name, f"a {kind.__name__}", value)
        _require(self.trust_region.radius_max <= self.restoration.radius,
                 "trust_region.radius_max",
                 f"<= restoration.radius = {self.restoration.radius!r}",
                 self.trust_region.radius_max)
