"""The fixed SQP problem whose iteration log is kept under version control.

Regenerate (after an intended change of the solver) with::

    .venv/bin/python tests/sqp_reference.py

History of the committed log:

* session 8: 11 → 8 iterations, Σu² 11 009.76 → 11 010.12 (+3e-5 relative). The minimum-norm
  Newton correction now moves only variables strictly inside their bounds (before, it moved
  variables at a bound, the projection clipped them back, and the correction of a stationary
  point a hair outside failed), so the solve stops three iterations earlier.
* session 9: the same 8 iterations, Σu² 11 010.12 → 13 263.85 (+20 %). The NLP changed, not the
  solver: q3 and q5 are now kept 0.2 rad from the elbow and wrist singularities
  (``SegmentOptions.singularity_margin``; with 0 the translate costs 11 025.43), and the
  joint limits hold between the nodes (``InterpolantLimits``; +0.14 %).
* session 12: 8 → 7 iterations, Σu² 13 263.85 → 13 267.01 (+2.4e-4 relative; IPOPT's optimum
  13 263.66). The SQP's stationarity test ``ftol`` went from 1e-4 to 1e-3 of Σu² (the last
  iteration bought 2.4e-4 of Σu²); the first six iterations are unchanged.
"""

import json
from pathlib import Path

from flipkit.behaviors.models import Models
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.config import CellConfig
from flipkit.model.ik import solve_pose
from flipkit.solvers.sqp import solve_sqp

LOG_PATH = Path(__file__).parent / "data" / "sqp_translate_log.json"
START, GOAL = (0.64, -0.33, 0.15), (0.75, 0.0, 0.15)


def reference_nlp():
    models = Models(CellConfig())
    q_start = solve_pose(models.loaded, START, (0.0, 0.0, 0.0))
    return transcribe("translate", models, q_start, goal=flat_pose(GOAL))


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
