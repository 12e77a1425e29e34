"""The reference plans that a restructuring must leave unchanged, array for array.

``python -m tests.plan_identity`` writes ``tests/data/plan_identity.npz`` from the code as it
is; ``tests/test_plan_identity.py`` plans the same motions and compares every array. Re-write
the reference only with a change that is meant to change plans, and say so in its commit.

The reference also records the floating-point kernels it was made with (:func:`numerics`).
A plan repeats to the last bit only on the same kernels: numpy picks its SIMD loops (AVX2 or
AVX-512, with different rounding in reductions and transcendental functions) and OpenBLAS
its core at run time, from the CPU. The SQP's path follows those bits, and where a segment's
NLP is flat or has two local optima close together the solution moves with them (measured
with numpy's AVX-512 and its AVX2 loops on one machine: seven of the twelve motions within
3e-4 rad, three Table I chains 0.13–0.61 rad apart, one with a flip 0.085 s longer, their
∫Σu² dt within 3.3 %).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from flipkit.config import TABLE1_LOCATIONS

REFERENCE = Path(__file__).parent / "data" / "plan_identity.npz"
NUMERICS = "__numerics__"  # the reference's entry naming its floating-point kernels
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


def numerics() -> str:
    """The floating-point kernels plans depend on: numpy's version and the CPU features its
    SIMD dispatch sees, scipy's version, and each BLAS library's version and core."""
    import scipy
    from numpy._core._multiarray_umath import __cpu_features__
    from threadpoolctl import threadpool_info

    blas = sorted({f"{i['internal_api']} {i['version']} {i.get('architecture')}"
                   for i in threadpool_info() if i["user_api"] == "blas"
                   and any(lib in Path(i["filepath"]).parent.name for lib in ("numpy", "scipy"))})
    return json.dumps({"numpy": np.__version__, "scipy": scipy.__version__,
                       "cpu": sorted(k for k, v in __cpu_features__.items() if v),
                       "blas": blas}, sort_keys=True)


def effort(key: str, arrays_: dict) -> float:
    """A motion's ∫ Σ u² dt over its segments (N²·m²·s, trapezoid over the nodes)."""
    total = 0.0
    for name in arrays_:
        if name.startswith(f"{key}/") and name.endswith("/u"):
            t = np.asarray(arrays_[name[:-2] + "/t"], float)
            total += float(np.trapezoid(np.sum(np.asarray(arrays_[name]) ** 2, axis=1), t))
    return total


def main() -> None:
    data = {NUMERICS: np.array(numerics())}
    for key, plan in motions():
        print(key, plan.status, flush=True)
        data.update(arrays(key, plan))
    np.savez_compressed(REFERENCE, **data)
    print(f"wrote {REFERENCE} ({len(data)} arrays)")


if __name__ == "__main__":
    main()
