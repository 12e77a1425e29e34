"""Time of the goal pre-check (:func:`flipkit.model.goal_check.check_goal`).

    python -m bench.goal_check_bench [--repeat R]

Prints, per goal, the verdict and the median wall time (ms) of R checks, then the medians over
the issue's two known-infeasible translate goals (refused) and over the six Table I
translate-like goals (the key points of ``flipkit.experiments.speed.TRANSLATE_KEY_POINTS``,
paper Fig. 6, each from the previous one; accepted). Each check starts from the README's
translate start (or the previous key point), as ``flipkit plan translate`` does. The models
(robot, shapes) are built once, as the planner caches them; their build time and the first
(cold) check are printed apart.
"""

from __future__ import annotations

import argparse
import statistics
import time

from flipkit.config import CellConfig
from flipkit.errors import UnreachableError
from flipkit.model.collision import ArmShapes
from flipkit.model.goal_check import check_goal
from flipkit.model.ik import solve_pose
from flipkit.model.robot import Robot

FLAT = (0.0, 0.0, 0.0)
README_START = (0.64, -0.33, 0.15)  # m: README's `flipkit plan translate --from`
KNOWN_BAD = ((1.10, 0.0, 0.30), (0.70, -0.20, 0.10))  # m: goals out of reach, refused
# m: flipkit.experiments.speed.TRANSLATE_KEY_POINTS (not imported: that module loads the solvers)
KEY_POINTS = ((0.65, -0.30, 0.15), (0.80, -0.10, 0.15), (0.70, 0.10, 0.15),
              (0.45, 0.74, 0.19), (0.32, 0.62, 0.20), (0.50, 0.52, 0.20))


def time_check(robot, shapes, cell, start, goal, repeat: int) -> tuple[float, str]:
    """Median wall time (s) of ``repeat`` checks of ``goal`` from the IK start at ``start``,
    and the verdict (``ok <shape>/<box> <clearance cm>`` or the refusal)."""
    q0 = solve_pose(robot, start, FLAT, robot.q_home)
    times, verdict = [], ""
    for _ in range(repeat):
        t = time.perf_counter()
        try:
            got = check_goal(robot, shapes, cell, goal, FLAT, q_start=q0)
            verdict = f"ok: branch {got.branch}, {got.shape}/{got.box} {got.clearance * 100:.1f} cm"
        except UnreachableError as exc:
            verdict = f"refused: {exc}"
        times.append(time.perf_counter() - t)
    return statistics.median(times), verdict


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=21, help="checks per goal (default 21)")
    args = ap.parse_args(argv)
    t = time.perf_counter()
    cell = CellConfig()
    robot, shapes = Robot(cell, with_burger=True), ArmShapes(Robot(cell), cell)
    print(f"models (robot, loaded robot, shapes) built in {time.perf_counter() - t:.3f} s")
    t = time.perf_counter()
    cold = time_check(robot, shapes, cell, README_START, KNOWN_BAD[0], 1)[0]
    print(f"first check in the process: {cold * 1e3:.1f} ms (with the start IK)")
    rows = [("known bad", README_START, g) for g in KNOWN_BAD]
    rows += [("Table I", KEY_POINTS[k - 1], g) for k, g in enumerate(KEY_POINTS)]
    medians: dict = {}
    for group, start, goal in rows:
        s, verdict = time_check(robot, shapes, cell, start, goal, args.repeat)
        medians.setdefault(group, []).append(s)
        print(f"{group:9s} {start} -> {goal}: {s * 1e3:6.2f} ms  {verdict}")
    for group, ts in medians.items():
        print(f"median over {group} goals ({len(ts)}): {statistics.median(ts) * 1e3:.2f} ms "
              f"(worst {max(ts) * 1e3:.2f} ms; {args.repeat} checks each)")


if __name__ == "__main__":
    main()
