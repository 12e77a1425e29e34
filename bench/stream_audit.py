"""Every command stream of a set of plans, checked as written against the arm profile.

``python -m bench.stream_audit`` plans the Table I flips, the five "more"
locations, three serves and the six translates between the paper's key points (from the
package's atlas where it serves), writes each plan's URScript at 125 and 500 Hz, ROS 2 and
CSV at 500 Hz, in the default command and (URScript) the compensated one, and prints one row
per plan and stream: written or refused, the largest joint speed over the published one, the
largest acceleration over its bound, and the blade's largest distance from the verified plan
(:mod:`flipkit.planning.plans.stream_check`).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from flipkit.config import MORE_LOCATIONS, TABLE1_LOCATIONS
from flipkit.errors import FlipkitError
from flipkit.experiments.speed import TRANSLATE_KEY_POINTS
from flipkit.planning.planners.atlas import default_atlas
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.planner import plan_flip, plan_translate
from flipkit.planning.planners.serve import plan_serve
from flipkit.planning.plans.export import write_csv
from flipkit.planning.plans.export_ros2 import write_ros2
from flipkit.planning.plans.export_urscript import ServoOptions, write_urscript

SERVE_PAIRS = (((0.75, 0.00, 0.073), (0.40, 0.60)), ((0.69, -0.16, 0.073), (0.30, 0.70)),
               ((0.80, 0.10, 0.073), (0.50, 0.50)))
"""The serve pairs of the serve trials (burger, table spot), m."""

STREAMS = (("urscript", 125.0, "raw"), ("urscript", 500.0, "raw"), ("ros2", 500.0, None),
           ("csv", 500.0, None), ("urscript", 125.0, "compensated"),
           ("urscript", 500.0, "compensated"))
"""(format, rate Hz, command) of each stream audited."""


def plans():
    """(name, plan) of every plan of the audit, in order."""
    atlas, caches = default_atlas(), PlannerCaches()
    for k, loc in enumerate(TABLE1_LOCATIONS, 1):
        yield f"table1_{k}", plan_flip(loc, atlas=atlas, caches=caches)
    for k, loc in enumerate(MORE_LOCATIONS, 1):
        yield f"more_{k}", plan_flip(loc, atlas=atlas, caches=caches)
    for k, (burger, spot) in enumerate(SERVE_PAIRS, 1):
        yield f"serve_{k}", plan_serve(burger, spot, caches=caches)
    pts = TRANSLATE_KEY_POINTS
    for k, (a, b) in enumerate(zip(pts, pts[1:] + pts[:1]), 1):
        yield f"translate_{k}", plan_translate(a, b, caches=caches)


def audit_plan(name: str, plan, where: Path) -> list[dict]:
    """One row per stream of :data:`STREAMS` for ``plan``."""
    rows = []
    for fmt, rate, command in STREAMS:
        checks = []
        out = where / f"{name}_{fmt}_{rate:g}_{command}"
        kw = {"on_check": checks.append, "where": name}
        try:
            if fmt == "urscript":
                write_urscript(plan, out.with_suffix(".script"), rate,
                               ServoOptions(command=command), **kw)
            elif fmt == "ros2":
                write_ros2(plan, out.with_suffix(".yaml"), rate, **kw)
            else:
                write_csv(plan, out.with_suffix(".csv"), rate, **kw)
            c, reason = checks[0], None
            row = {"speed": c.speed_ratio, "accel": c.accel_ratio, "deviation_m": c.deviation_m}
        except FlipkitError as exc:
            reason, row = str(exc).split("nothing written: ")[-1], {}
        rows.append({"plan": name, "format": fmt, "rate": rate, "command": command or "-",
                     "written": reason is None, "reason": reason, **row})
    return rows


def main(argv=None) -> int:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="flipkit-audit-") as tmp:
        print(f"{'plan':13s} {'stream':26s} {'written':7s} {'speed':>6s} {'accel':>6s} "
              f"{'blade mm':>8s}  refused because")
        counts = {}
        for name, plan in plans():
            if plan.status != "solved":
                print(f"{name:13s} plan {plan.status}: {plan.failure}")
                continue
            for r in audit_plan(name, plan, Path(tmp)):
                stream = f"{r['format']} {r['rate']:g} Hz {r['command']}"
                key = (r["format"], r["rate"], r["command"])
                counts[key] = counts.get(key, 0) + int(r["written"])
                if r["written"]:
                    print(f"{name:13s} {stream:26s} {'yes':7s} {r['speed']:6.3f} "
                          f"{r['accel']:6.3f} {1e3 * r['deviation_m']:8.3f}")
                else:
                    print(f"{name:13s} {stream:26s} {'no':7s} {'':6s} {'':6s} {'':8s}  "
                          f"{r['reason']}")
        for (fmt, rate, command), n in counts.items():
            print(f"written: {fmt} {rate:g} Hz {command}: {n}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
