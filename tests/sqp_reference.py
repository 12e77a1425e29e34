"""The fixed SQP problem whose iteration log is kept under version control.

Regenerate (after an intended change of the solver) with::

    .venv/bin/python tests/sqp_reference.py

How the committed log changed, and why: docs/history.md ("The SQP reference log").
"""

import json
from pathlib import Path

from flipkit.behaviors.models import Models
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.config import CellConfig
from flipkit.model.ik import solve_pose
from flipkit.solvers.sqp import solve_sqp

LOG_PATH = Path(__file__).parent / "data" / "sqp_translate_log.json"
START, GOAL = (0.64, -0.33, 0.15), (0.75, 0.0, 0.15)


def reference_nlp():
    models = Models(CellConfig())
    q_start = solve_pose(models.loaded, START, (0.0, 0.0, 0.0))
    # the NLP the committed log was written on: the cone at the nominal μ × 0.8
    return transcribe("translate", models, q_start, goal=flat_pose(GOAL),
                      options=SegmentOptions(mu_plan=0.4))


def run():
    nlp = reference_nlp()
    return nlp, solve_sqp(nlp)


def log_rows(result):
    return [{"iter": r["iter"], "objective": r["objective"], "violation": r["violation"],
             "merit": r["merit"], "step": r["step"], "qp_status": r["qp_status"]}
            for r in result.log]


if __name__ == "__main__":
    _, res = run()
    LOG_PATH.write_text(json.dumps({"status": res.status, "iterations": res.iterations,
                                    "objective": res.objective, "log": log_rows(res)}, indent=1))
    print(f"wrote {LOG_PATH}: {res.iterations} iterations, objective {res.objective:.6f}")
