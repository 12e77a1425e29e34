"""The SQP's settings (:func:`flipkit.solvers.sqp.solve_sqp`), validated on construction.

What each setting does to the iteration, and what its default was measured against, is in
:mod:`flipkit.solvers.sqp`'s docstring and the attributes below.
"""

from __future__ import annotations

from dataclasses import dataclass

from flipkit.errors import ConfigError

__all__ = ["SQPOptions"]


@dataclass(frozen=True)
class SQPOptions:
    """Settings (lengths in scaled variable units).

    Attributes:
        tol: Feasibility tolerance on the max scaled violation.
        ftol: Predicted merit decrease, relative to J̃ (at least 1e-3), below which Z is
            stationary; a stationary Z a hair outside gets Newton corrections onto the rows
            (see the module docstring for what 1e-3 rather than 1e-4 costs and saves).
        reject_ftol: A feasible Z whose hard step the line search rejects (the rows' curvature,
            which the model ignores, undoes the predicted decrease) is stationary to the
            model's accuracy when that prediction is at most ``reject_ftol``·J̃: the trust box
            would otherwise shrink tenfold per iteration until ``ftol`` is met at the same Z
            (measured, session 12: 1–3 such iterations at the end of a Table I flip).
        stall_iterations, stall_progress: Locally infeasible — status ``infeasible`` — after
            this many consecutive restoration steps that each cut the summed violation by
            less than this fraction (a stationary point of the violation: measured, a scoop
            at the grill's corner spent 100 iterations and 23 s at 5.6e-3 without it).
        plateau_iterations, plateau_ftol: Z is also stationary when the last
            ``plateau_iterations`` iterates were feasible to 100 tol and together lowered Σu²
            by less than ``plateau_ftol`` (relative); it then gets the Newton corrections and
            is ``solved`` once within tol: the Gauss–Newton model ignores the rows'
            curvature and creeps along curved active rows such as the flip's landing
            (measured at Table I loc 6: feasible after 11 iterations, then 0.3–1 % per 10
            iterations for 90 more, ending 1 % above IPOPT's exact-Hessian optimum). A window
            of 4 rather than 8 (session 10, Table I pickup-and-flip chains): from the atlas,
            median 32 → 27 SQP iterations, Σu² within ±0.11 %; from cold starts, 49 → 41,
            within ±0.8 % (either sign: the paths part earlier).
        condense: Solve the hard subproblem in condensed form (:mod:`flipkit.solvers.condensed_qp`);
            False solves the full-space QP of :mod:`flipkit.solvers.full_qp` (slower, same solution).
        max_iter: Cap on SQP iterations (QP solves).
        trust0, trust_min, trust_max: Initial, smallest and largest trust box Δ.
        prox, prox_range: Initial Levenberg–Marquardt weight μ of ½μ‖d‖² and its range.
        eta: Sufficient-decrease fraction of the predicted merit decrease.
        good_ratio: actual/predicted decrease of a full step above which μ falls and Δ grows.
        backtracks: Halvings of the step tried before the step is rejected.
        rho_min: Smallest ℓ1 penalty.
        slack_reg, restoration_prox: The elastic (restoration) step minimises
            ½σ‖s‖² + ½μ_r‖d‖², a Levenberg–Marquardt step on the violation.
        restoration_trust: The restoration step's box |d|∞ ≤ this (∩ the variable bounds)
            while the trust box is at its largest, ``trust_max``; after the trust box has
            shrunk, the restoration keeps it. A cold guess clipped to the bounds (the flip's
            wrist roll in 0.6 s exceeds the velocity and acceleration limits) is inconsistent
            by O(1): its linearised equality rows need steps of 1.0–3.3 (measured, ten cold
            Table I chains), so in a box of 1 the condensed restoration QP was infeasible and
            the full-space one took 100–130 ms; in a box of 4 every restoration of those
            chains was condensed (20 ms each).
        restoration_exit: The restoration phase (see :mod:`flipkit.solvers.sqp`) ends when
            the max violation is down to this fraction of its value when the phase began; 0
            ends it after every step (each iteration tries the hard QP first). Measured
            (session 13) on 35 cold pickup-and-flip chains at the atlas grid's points shifted
            by (2, 3) cm: ADMM iterations 1.98 M (0) → 1.38 M (0.1), 1.47 M (0.3), 1.88 M (0.5);
            SQP iterations 1371, 1400, 1361, 1367; process CPU 41.4, 35.4, 34.5, 42.4 s; all
            35 solved each time; chains from the atlas unchanged (no restoration phase).
        qp_eps, qp_eps_factor: OSQP tolerance = factor × violation (at a feasible iterate:
            × last predicted decrease), clipped to the (min, max) range (inexact SQP).
        qp_max_iter: OSQP iteration caps of the three tries of the hard QP. A subproblem
            that needs more than 2 000 condensed ADMM iterations is usually solved in a few
            hundred after μ×10 (measured: flip iteration 2, 10 000 + 220 → 2 000 + 220).
    """

    tol: float = 1e-6
    ftol: float = 1e-3
    reject_ftol: float = 1e-2
    max_iter: int = 100
    trust0: float = 1.0
    trust_min: float = 1e-6
    trust_max: float = 1.0
    prox: float = 1e-3
    prox_range: tuple[float, float] = (1e-5, 1.0)
    eta: float = 0.1
    good_ratio: float = 0.5
    backtracks: int = 5
    rho_min: float = 1e-3
    slack_reg: float = 1.0
    restoration_prox: float = 1e-4
    restoration_trust: float = 4.0
    restoration_exit: float = 0.3
    qp_eps: tuple[float, float] = (1e-9, 1e-4)
    qp_eps_factor: float = 0.1
    qp_max_iter: tuple[int, int, int] = (2000, 10000, 10000)
    condense: bool = True
    stall_iterations: int = 5
    stall_progress: float = 1e-2
    plateau_iterations: int = 4
    plateau_ftol: float = 1e-2

    def __post_init__(self):
        if not (0 < self.trust_min <= self.trust0 <= self.trust_max <= self.restoration_trust):
            raise ConfigError("need 0 < trust_min <= trust0 <= trust_max <= restoration_trust")
        if not (0 < self.eta < 1) or self.tol <= 0 or self.ftol <= 0 or self.max_iter < 1:
            raise ConfigError("need 0 < eta < 1, tol > 0, ftol > 0 and max_iter >= 1")
        if self.reject_ftol < 0:
            raise ConfigError("need reject_ftol >= 0")
        if not (0 < self.prox_range[0] <= self.prox <= self.prox_range[1]):
            raise ConfigError("need 0 < prox_range[0] <= prox <= prox_range[1]")
        if not (0 < self.qp_eps[0] <= self.qp_eps[1]):
            raise ConfigError("need 0 < qp_eps[0] <= qp_eps[1]")
        if not 0 <= self.restoration_exit < 1:
            raise ConfigError("need 0 <= restoration_exit < 1")
        if self.stall_iterations < 1 or not (0 <= self.stall_progress < 1):
            raise ConfigError("need stall_iterations >= 1 and 0 <= stall_progress < 1")
        if self.plateau_iterations < 2 or not (0 <= self.plateau_ftol < 1):
            raise ConfigError("need plateau_iterations >= 2 and 0 <= plateau_ftol < 1")
