"""Where an SQP iteration's milliseconds go, on a flip segment.

    python -m bench.profile [--location K] [--atlas] [--out FILE]

Plans pickup-and-flip at Table I location K (default 7, (0.73, −0.13)) — from cold starts, or
warm-started from the package's atlas (``--atlas``, as ``flipkit plan flip`` plans) — once to
warm up (cvxpy compiles each subproblem once per process), then again under :mod:`cProfile`, and
reports the flip segment's SQP time split into disjoint parts, in ms per SQP iteration:

* ``evaluate``: constraint values and Jacobians of every block (NLP.evaluate), trial points
  of the line search included — the model's maths plus the Python around it;
* ``condense``: the condensed QP's data (basis, sparse LU of E_B, Z, T, Cholesky);
* ``cvxpy``: cvxpy mapping the Parameters to OSQP's matrices (``get_problem_data``) and
  unpacking the result;
* ``osqp``: OSQP's own setup and ADMM (C);
* ``newton``: the minimum-norm Newton corrections (a sparse LU of the full Jacobian);
* ``other``: the rest (SQP bookkeeping, working-set checks, merit, NumPy glue).

The numbers depend on the machine: the output names it.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats

from flipkit.config import TABLE1_LOCATIONS
from bench.bench import machine
from flipkit.planning.planners import planner
from flipkit.planning.planners.atlas import default_atlas
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.solvers import sqp

# part -> (file suffix, function name) whose cumulative time it is; the parts do not nest
PARTS = {
    "evaluate": (("transcription/nlp.py", "evaluate"),),
    "condense": (("solvers/condensed_qp.py", "update"),),
    "cvxpy": (("cvxpy/problems/problem.py", "get_problem_data"),
              ("cvxpy/problems/problem.py", "unpack_results")),
    "osqp": (("~", "<built-in method osqp.ext_builtin.solve>"),
             ("osqp/interface.py", "setup"), ("osqp/interface.py", "update")),
    "newton": (("solvers/iterate.py", "newton_correction"),),
}
TOTAL = ("solvers/sqp.py", "solve_sqp")


def _cumulative(stats: pstats.Stats, where: tuple) -> float:
    """Summed cumulative time (s) of the functions matching (file suffix, name)."""
    total = 0.0
    for (filename, _line, name), (_cc, _nc, _tt, ct, _callers) in stats.stats.items():
        if any(filename.endswith(f) and name == n for f, n in where):
            total += ct
    return total


def profile_flip(location, segment: str = "flip", atlas=None) -> dict:
    """Profile the SQP of one segment of ``plan_flip(location, atlas=atlas)``.

    Returns:
        ``{"location", "segment", "atlas", "iterations", "sqp_s", "parts_ms_per_iteration":
        {part: ms}, "solve_s_unprofiled"}``; ``parts`` sum to the SQP's time per iteration.
    """
    caches = PlannerCaches()  # every plan below, compiled by the warm-up
    planner.plan_flip(location, atlas=atlas, caches=caches)  # warm-up: compile every structure
    plain = planner.plan_flip(location, atlas=atlas, caches=caches)
    plain_s = next(s.solver.wall_time_s for s in plain.segments if s.name == segment)
    profiler, calls = cProfile.Profile(), []
    original = sqp.solve_sqp

    def traced(nlp, *args, **kwargs):  # profile only the chosen segment's solve
        if nlp.name != segment:
            return original(nlp, *args, **kwargs)
        profiler.enable()
        try:
            result = original(nlp, *args, **kwargs)
        finally:
            profiler.disable()
        calls.append(result)
        return result

    sqp.solve_sqp = traced
    try:
        planner.plan_flip(location, atlas=atlas, caches=caches)
    finally:
        sqp.solve_sqp = original
    stats = pstats.Stats(profiler)
    total = _cumulative(stats, (TOTAL,))
    its = sum(r.iterations for r in calls)
    parts = {name: _cumulative(stats, where) for name, where in PARTS.items()}
    parts["other"] = total - sum(parts.values())
    return {"location": tuple(location), "segment": segment, "atlas": atlas is not None,
            "iterations": its,
            "sqp_s": total, "solve_s_unprofiled": plain_s,
            "parts_ms_per_iteration": {k: 1e3 * v / max(its, 1) for k, v in parts.items()}}


def format_profile(result: dict) -> str:
    """The profile as a text table (ms per iteration and share of the total)."""
    parts = result["parts_ms_per_iteration"]
    per_it = sum(parts.values())
    lines = [machine(),
             f"segment {result['segment']} at p^b = {result['location']}"
             f"{' from the atlas' if result.get('atlas') else ', cold'}: "
             f"{result['iterations']} SQP iterations, {result['sqp_s']:.2f} s under cProfile "
             f"({result['solve_s_unprofiled']:.2f} s without), {per_it:.1f} ms per iteration",
             f"{'part':<10}{'ms/iteration':>14}{'share':>8}"]
    lines += [f"{k:<10}{v:14.1f}{v / per_it:8.0%}" for k, v in parts.items()]
    return "\n".join(lines)


def main(argv=None) -> int:
    """Command-line entry point (see the module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m bench.profile",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--location", type=int, default=7, metavar="K",
                        help=f"Table I location 1..{len(TABLE1_LOCATIONS)} (default 7)")
    parser.add_argument("--atlas", action="store_true",
                        help="warm-start the chain from the package's atlas (default: cold)")
    parser.add_argument("--out", metavar="FILE", help="also write the table to FILE")
    args = parser.parse_args(argv)
    if not 1 <= args.location <= len(TABLE1_LOCATIONS):
        parser.error(f"--location must be 1..{len(TABLE1_LOCATIONS)}")
    atlas = None
    if args.atlas:
        atlas = default_atlas()
        if atlas is None:
            parser.error("the package's atlas does not serve the default options; "
                         "rebuild it with `flipkit atlas build`")
    text = format_profile(profile_flip(TABLE1_LOCATIONS[args.location - 1], atlas=atlas))
    print(text)
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
