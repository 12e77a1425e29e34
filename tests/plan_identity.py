"""The reference plans that a restructuring must leave unchanged, array for array.

``python -m tests.plan_identity`` writes ``tests/data/plan_identity.npz`` from the code as it
is; ``tests/test_plan_identity.py`` plans the same motions and compares every array. Re-write
the reference only with a change that is meant to change plans, and say so in its commit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flipkit.config import TABLE1_LOCATIONS

REFERENCE = Path(__file__).parent / "data" / "plan_identity.npz"
FIELDS = ("t", "q", "qd", "qdd", "u", "alpha")
SERVE = ((0.75, 0.0, 0.073), (0.40, 0.60))  # a burger and a table spot (the README's)
TRANSLATE = ((0.60, -0.20, 0.30), (0.80, 0.20, 0.30))  # start and goal (m)


def motions():
    """(key, plan) of every reference motion: the ten Table I chains, a serve, a translate."""
    from flipkit.planning.planners.planner import plan_flip, plan_translate
    from flipkit.planning.planners.serve import plan_serve

    for k, loc in enumerate(TABLE1_LOCATIONS):
        yield f"table1_{k}", plan_flip(loc, solver="sqp")
    yield "serve", plan_serve(*SERVE, solver="sqp")
    yield "translate", plan_translate(*TRANSLATE, solver="sqp")


def arrays(key: str, plan) -> dict:
    """The plan's arrays by ``key/segment index/name/field`` and its status."""
    out = {f"{key}/status": np.array(plan.status)}
    for i, seg in enumerate(plan.segments):
        for f in FIELDS:
            out[f"{key}/{i}/{seg.name}/{f}"] = np.asarray(getattr(seg, f), float)
        out[f"{key}/{i}/{seg.name}/T"] = np.array(float(seg.T))
    return out


def main() -> None:
    data = {}
    for key, plan in motions():
        print(key, plan.status, flush=True)
        data.update(arrays(key, plan))
    np.savez_compressed(REFERENCE, **data)
    print(f"wrote {REFERENCE} ({len(data)} arrays)")


if __name__ == "__main__":
    main()
