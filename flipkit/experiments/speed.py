"""The speed comparisons' common ground: the paper's time budgets, the six translates between
the key points of the paper's Fig. 6 as NLPs, the solvers compared on them, and the warm-up
that compiles a structure's subproblems before anything is timed.

The figures (``translate``, ``solve_times``, ``solve_scaling``, ``defects``),
:mod:`flipkit.experiments.scaling` and the benchmarks of the repository's ``bench/`` use them.
"""

from __future__ import annotations

import time

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors.models import Models
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.config import CellConfig
from flipkit.model.ik import solve_pose
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.solvers.sqp import SQPOptions, SQPWorkspace, TerminationOptions, solve_sqp

# Key points of the translate experiment (paper Fig. 6: three on the grill, three on the
# table), blade-centre positions (m) with the spatula flat, yaw 0. Grill: h_g = 0.072 m,
# area x 0.60–0.88, y −0.50–0.16 -> blade 7.8 cm above it. Table: 0.10 m, area x 0.20–0.55,
# y 0.45–0.80 -> blade 9–10 cm above it. All reachable; the order (grill, then the table point
# farthest from it, ending at the one nearest) lets IK from each point find the next. The table
# points are 2 cm above where a chain planned without the arm's 2 cm space margin would put
# them: there it brings the arm into contact with a box of the cell, and the translate from
# (0.32, 0.62) to (0.50, 0.52) has no solution with the margin.
TRANSLATE_KEY_POINTS = (
    (0.65, -0.30, 0.15), (0.80, -0.10, 0.15), (0.70, 0.10, 0.15),
    (0.45, 0.74, 0.19), (0.32, 0.62, 0.20), (0.50, 0.52, 0.20),
)
PAPER_PER_TRAJECTORY_S = 20.0  # Sec. I: < 20 s per trajectory
PAPER_FIVE_BURGERS_S = 90.0  # Sec. I: 4–5 burgers within 90 s
PAPER_EE_OPT_S = 1.0  # Sec. I: the end-effector optimisation takes < 1 s


# The translate comparison's solvers: the SQP and IPOPT (L-BFGS, callbacks) on the NLP, FATROP,
# exact-Hessian IPOPT and CasADi's sqpmethod on its stage-wise graph (flipkit.solvers.exact);
# labels for the table.
TRANSLATE_SOLVERS = {"sqp": "SQP", "fatrop": "FATROP", "ipopt_exact": "IPOPT exact",
                     "sqpmethod": "sqpmethod", "ipopt": "IPOPT L-BFGS"}


def translate_nlps(cell: CellConfig, options: SegmentOptions,
                   caches: PlannerCaches | None = None) -> list:
    """The six translate segments between :data:`TRANSLATE_KEY_POINTS`, each to the next,
    as NLPs built with ``options`` (each start pose by IK from q_home), with the models and
    patterns of ``caches`` (default: the cell's models, built for these NLPs)."""
    models = Models(cell) if caches is None else caches.models(cell)
    patterns = None if caches is None else caches.patterns
    robot = models.for_segment("translate")
    pts, nlps = TRANSLATE_KEY_POINTS, []
    for k, a in enumerate(pts):
        q0 = solve_pose(robot, a, (0.0, 0.0, 0.0), robot.q_home)
        nlps.append(transcribe("translate", models, q0, goal=flat_pose(pts[(k + 1) % len(pts)]),
                               options=options, patterns=patterns))
    return nlps


def warm_up(nlps, caches: PlannerCaches) -> float:
    """Compile the elastic (restoration) QPs of each distinct structure (cvxpy, once per
    workspace) and run one SQP iteration on it, which compiles the condensed hard QP;
    returns the time (s). The workspace is ``caches``'s, which the solves and planners
    given the same ``caches`` then use."""
    t0, seen, workspace = time.perf_counter(), set(), caches.workspace(SQPWorkspace)
    for nlp in nlps:
        if nlp.structure_key not in seen:
            seen.add(nlp.structure_key)
            for form in ("elastic", "condensed_elastic"):
                workspace.get(nlp, form).compile()
            solve_sqp(nlp, options=SQPOptions(termination=TerminationOptions(max_iter=1)),
                      raise_on_failure=False, workspace=workspace)
    return time.perf_counter() - t0


def warm_flip(caches: PlannerCaches, cell: CellConfig, location) -> float:
    """:func:`warm_up` on the five segment structures of a flip at ``location``, built along
    their initial guesses with ``caches``'s models: what a plan made with ``caches`` then
    times is planning, not cvxpy's one-off compile. Returns the time spent (s)."""
    models = caches.models(cell)
    q, qd, nlps = models.bare.q_home, None, []
    for name in FLIP_NAMES:
        nlp = transcribe(name, models, q, qd, location=location, patterns=caches.patterns)
        nlps.append(nlp)
        nodes = nlp.layout.nodes(nlp.x0)
        q, qd = nodes[-1, 0], nodes[-1, 1]
    return warm_up(nlps, caches)

