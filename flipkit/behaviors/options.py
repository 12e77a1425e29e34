"""Transcription options of a segment (:class:`SegmentOptions`). The task choices that the
subbehaviours share (the scoop's press into the grill, the landing radii, the release node,
the friction safety factor, the braking room at a moving segment end) are
:mod:`flipkit.config.task`'s, imported here for the behaviour layer."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flipkit.errors import ConfigError
from flipkit.model.contact import make_cone
from flipkit.model.singular import SINGULARITY_MARGIN

from flipkit.config.task import (BRAKING_FRACTION, FLIGHT_MARGIN, MU_PLAN,  # noqa: F401
                                 MU_SAFETY, R_LAND, R_LAND_RANGE, R_SCENARIO,
                                 RELEASE_FRACTION,
                                 RELEASE_PRESS, SCOOP_ANGLE_BAND, SCOOP_LATERAL_BAND,
                                 SCOOP_PRESS, SCOOP_TIP_BAND, T_STRETCH)


@dataclass(frozen=True)
class SegmentOptions:
    """Transcription options.

    Attributes:
        N: Intervals per segment (paper: 20, i.e. 21 nodes).
        epsilon: Output convergence rate ε of eq. (18) (1/s).
        cone: Friction-cone form, ``physical`` (eq. 5) or ``paper`` (eq. 20).
        r_land: Flip: radius (m) of the disc about the target spot where the burger's centre
            must land (:class:`~flipkit.transcription.constraints.flight.Landing`).
        r_scenario: Flip: radius (m) within which the landing of every scenario of the
            burger's place on the blade must come down (:attr:`~flipkit.behaviors.spec.Task.scenarios`).
        robust: Flip: the planners land every scenario of the scoop's outcome spread
            (:class:`~flipkit.config.ScoopUncertainty`), not only the predicted one.
        release_fraction: Flip: the release node is ⌈release_fraction · N⌉; the cone holds up
            to it, the flying burger clears the blade after it.
        mu_plan: Friction coefficient the cones of the segments that carry the burger are
            planned with (:data:`~flipkit.config.task.MU_PLAN`: the least sticky burger of
            the sourced range); a burger whose nominal μ × mu_safety is lower gets that.
        mu_safety: The scoop's cone (it limits the braking under the burger) is planned with
            the nominal μ × mu_safety.
        release_press: Flip: specific force (m/s²) that still presses the burger onto the
            blade one node before the release, at its place and at every scenario's
            (:data:`~flipkit.config.task.RELEASE_PRESS`); 0 leaves the release to the cone.
        landing: Flip: impose the release, flight and landing (default). ``False`` gives the
            paper's flip (26) alone, cone on i ≤ 0.6 N — a baseline whose burgers miss
            (``flipkit verify`` then fails its ``landing`` group).
        stretch: Allow the duration up to T_STRETCH × the upper duration bound (the
            planner's second attempt at a segment infeasible within its bound).
        arm_clearance: Impose the whole arm's space limits (coal distances to the cell's
            boxes). ``False`` leaves them out: the problem that exact-derivative solvers
            (FATROP, exact-Hessian IPOPT; :mod:`flipkit.transcription.ocp_graph`) and the SQP
            can all be given, for the solver comparison of ``bench``.
        singularity_margin: Keep q3 and q5 this far (rad) from the elbow and wrist
            singularities, on the home configuration's side (:mod:`flipkit.model.singular`);
            0 lets the plan cross them.
    """

    N: int = 20
    epsilon: float = 10.0
    cone: str = "physical"
    r_land: float = R_LAND
    r_scenario: float = R_SCENARIO
    robust: bool = True
    release_fraction: float = RELEASE_FRACTION
    landing: bool = True
    mu_plan: float = MU_PLAN
    mu_safety: float = MU_SAFETY
    release_press: float = RELEASE_PRESS
    stretch: bool = False
    arm_clearance: bool = True
    singularity_margin: float = SINGULARITY_MARGIN

    def __post_init__(self):
        if self.epsilon <= 0 or not np.isfinite(self.epsilon):
            raise ConfigError(f"epsilon must be positive, got {self.epsilon!r}")
        lo, hi = R_LAND_RANGE
        if not (np.isfinite(self.r_land) and lo <= self.r_land <= hi):
            raise ConfigError(f"r_land must be in [{lo:g}, {hi:g}] m, got {self.r_land!r}: below "
                              f"{lo:g} m is within the landing's spread, its prediction and "
                              "check agree only to that")
        if not (np.isfinite(self.r_scenario) and self.r_land <= self.r_scenario <= hi):
            raise ConfigError(f"r_scenario must be in [r_land, {hi:g}] m, got {self.r_scenario!r}")
        if not (np.isfinite(self.mu_safety) and 0 < self.mu_safety <= 1):
            raise ConfigError(f"mu_safety must be in (0, 1], got {self.mu_safety!r}")
        if not (np.isfinite(self.mu_plan) and 0 < self.mu_plan <= 2):
            raise ConfigError(f"mu_plan must be in (0, 2], got {self.mu_plan!r}")
        if not (np.isfinite(self.release_press) and 0 <= self.release_press <= 9.81):
            raise ConfigError(f"release_press must be in [0, 9.81] m/s², got "
                              f"{self.release_press!r}")
        if not (np.isfinite(self.release_fraction) and 0.3 <= self.release_fraction <= 0.9):
            raise ConfigError(f"release_fraction must be in [0.3, 0.9], got "
                              f"{self.release_fraction!r}")
        make_cone(self.cone, 0.5)  # validates the name
        if not (np.isfinite(self.singularity_margin) and 0 <= self.singularity_margin < 1.5):
            raise ConfigError(f"singularity_margin must be in [0, 1.5) rad, got "
                              f"{self.singularity_margin!r}")

    def cone_mu(self, mu: float, carries_burger: bool) -> float:
        """Friction coefficient of a segment's planned cone for a burger of nominal ``mu``:
        :attr:`mu_plan` (capped at ``mu`` × :attr:`mu_safety`) when the segment carries the
        burger, ``mu`` × :attr:`mu_safety` for the scoop's braking cone."""
        braking = float(mu) * self.mu_safety
        return min(self.mu_plan, braking) if carries_burger else braking

    def release_node(self) -> int:
        """The flip's release node r = ⌈release_fraction · N⌉."""
        return int(np.ceil(self.release_fraction * self.N - 1e-9))
