"""The replan latency of sense-plan-act: ``replan_flip`` after the scoop, timed alone.

In sense-plan-act the arm holds at rest after the scoop while the planner re-plans the flip
for where the camera saw the burger on the blade
(:func:`~flipkit.planning.planners.planner.replan_flip`). This benchmark takes the sensed
places of a ``flipkit validate --replan --json`` run (or makes one: Table I, position mode,
open loop otherwise as validated), plans each location as the validation did (from the
package's atlas), and times ``replan_flip`` for every sensed place in this process, one
after the other on an otherwise idle machine. It prints the median and the worst, and how
many places the robust plan already served as it was (no solve: the place lies in its
scenarios' hull, or its own flight lands it within ``r_scenario``). A place the camera saw
off the blade (its error reaches past the blade's edge) is refused by the planner; it is
recorded as refused and counted apart, not timed.

With ``--contingencies`` it also prepares each plan's contingency flips
(:class:`~flipkit.planning.planners.contingency.Contingencies`, one after the other in this
process, timed) and times the re-plan that uses them at the same places: kept, handed a
contingency, or solved.

Run as ``python -m bench.bench replan [--validate FILE] [--contingencies]``.
"""

from __future__ import annotations

import json
import time
from concurrent.futures import ProcessPoolExecutor
from functools import partial

import numpy as np

from flipkit.config import TABLE1_LOCATIONS
from flipkit.errors import ConfigError, FlipkitError
from flipkit.experiments.trials import validate_locations
from flipkit.planning.planners.atlas import default_atlas
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.contingency import Contingencies
from flipkit.planning.planners.planner import covers, plan_flip, replan_flip

TARGET_S = 0.15  # s, the latency the sense-plan-act cycle is to stay within


def sensed_places(result: dict) -> list[tuple[tuple, list]]:
    """``[(location, [sensed (x, y) ...]) ...]`` from a validate result with ``replan``."""
    out = []
    for entry in result["locations"]:
        sensed = [row["replan"]["sensed_on_blade"] for row in entry.get("landings", ())
                  if row.get("replan") and row["replan"].get("sensed_on_blade") is not None]
        if sensed:
            out.append((tuple(entry["location"]), sensed))
    if not out:
        raise FlipkitError("the validate result records no sensed place on the blade: run "
                           "`flipkit validate --replan --json FILE` first")
    return out


def run_validation(trials: int = 3, seed: int = 3) -> dict:
    """Table I, ``trials`` per location, position mode, sense-plan-act, two workers."""
    with ProcessPoolExecutor(2) as pool:
        return validate_locations(TABLE1_LOCATIONS, trials, seed=seed, mode="position",
                                  replan=True, executor=pool, progress=False)


def _timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return out, time.perf_counter() - t0


def bench_replan(result: dict, contingencies: bool = False) -> dict:
    """Time ``replan_flip`` at every sensed place of ``result`` (and, with
    ``contingencies``, the re-plan through each plan's :class:`Contingencies`); print;
    return the rows and the summary."""
    atlas, rows, prepared = default_atlas(), [], []
    caches = PlannerCaches()  # every plan and re-plan here, one after another, as a cell's
    print(f"{'location (m)':<24}{'sensed (mm)':>16}{'in hull':>9}{'kept':>6}{'replan s':>10}"
          f"{'status':>8}" + (f"{'with contingencies':>20}{'s':>7}" if contingencies else ""))
    for loc, places in sensed_places(result):
        plan = plan_flip(loc, atlas=atlas, caches=caches)
        if plan.status != "solved":
            print(f"{str(loc):<24} plan failed: {plan.failure}")
            continue
        landing = plan.segment("flip").landing
        extra = Contingencies.prepare(plan, caches=caches) if contingencies else None
        if extra is not None:
            prepared.append({"location": loc, "time_s": extra.wall_time_s,
                             "solved": len(extra.flips), "failed": len(extra.failed)})
        for xy in places:
            try:
                new, dt = _timed(partial(replan_flip, caches=caches), plan, xy)
            except ConfigError as exc:  # the camera saw the burger off the blade: refused
                rows.append({"location": loc, "sensed": list(xy), "refused": str(exc)})
                print(f"{str(loc):<24} sensed {xy} refused: {exc}", flush=True)
                continue
            row = {"location": loc, "sensed": list(xy), "covered": covers(landing, xy),
                   "kept": new is plan, "time_s": dt, "status": new.status}
            line = (f"{'(' + ', '.join(f'{v:.3f}' for v in loc) + ')':<24}"
                    f"{f'({1e3 * xy[0]:.1f}, {1e3 * xy[1]:.1f})':>16}{str(row['covered']):>9}"
                    f"{str(row['kept']):>6}{dt:10.3f}{new.status:>8}")
            if extra is not None:
                got, dt_c = _timed(extra, plan, xy)
                how = ("kept" if got is plan else "contingency"
                       if any(got is p for _, p in extra.flips) else "solved")
                row.update(contingency_time_s=dt_c, contingency_how=how,
                           contingency_status=got.status)
                line += f"{how:>20}{dt_c:7.3f}"
            rows.append(row)
            print(line, flush=True)
    refused = sum("refused" in r for r in rows)
    rows, all_rows = [r for r in rows if "refused" not in r], rows
    times = np.array([r["time_s"] for r in rows])
    solved = np.array([r["time_s"] for r in rows if not r["kept"]])
    summary = {"replans": len(rows), "refused": refused,
               "covered": int(sum(r["covered"] for r in rows)),
               "kept": int(sum(r["kept"] for r in rows)),
               "solved_ok": int(sum(r["status"] == "solved" for r in rows)),
               "median_s": float(np.median(times)), "worst_s": float(times.max()),
               "median_solving_s": float(np.median(solved)) if solved.size else None,
               "within_target": int(np.sum(times <= TARGET_S)), "target_s": TARGET_S}
    if contingencies:
        with_c = np.array([r["contingency_time_s"] for r in rows])
        prep = np.array([p["time_s"] for p in prepared])
        summary["contingencies"] = {
            "prepare_median_s": float(np.median(prep)), "prepare_worst_s": float(prep.max()),
            "median_s": float(np.median(with_c)), "worst_s": float(with_c.max()),
            "served": {h: sum(r["contingency_how"] == h for r in rows)
                       for h in ("kept", "contingency", "solved")},
            "solved_ok": int(sum(r["contingency_status"] == "solved" for r in rows)),
            "within_target": int(np.sum(with_c <= TARGET_S)),
            "prepared": prepared}
        c = summary["contingencies"]
        made = sum(p["solved"] for p in prepared)
        print(f"with contingencies ({made} of {made + sum(p['failed'] for p in prepared)} "
              f"solved over {len(prepared)} plans, each plan's prepared in a median "
              f"{c['prepare_median_s']:.2f} s, worst {c['prepare_worst_s']:.2f} s, one after "
              f"the other): {c['served']['kept']} kept, {c['served']['contingency']} handed a "
              f"contingency, {c['served']['solved']} solved; latency median "
              f"{c['median_s']:.3f} s, worst {c['worst_s']:.3f} s; "
              f"{c['within_target']}/{len(rows)} within {TARGET_S} s")
    print(f"{summary['replans']} replans: {summary['kept']} kept the robust plan (no solve; "
          f"{summary['covered']} inside its scenarios' hull), {summary['solved_ok']} solved; "
          f"latency median {summary['median_s']:.3f} s, "
          f"worst {summary['worst_s']:.3f} s, median when solving "
          f"{summary['median_solving_s'] or float('nan'):.3f} s; "
          f"{summary['within_target']}/{len(rows)} within {TARGET_S} s; {refused} sensed "
          f"place(s) off the blade refused")
    return {"rows": all_rows, "summary": summary}


def load_result(path: str) -> dict:
    """A validate JSON, or a one-line FlipkitError."""
    try:
        with open(path, encoding="utf-8") as fh:
            return json.load(fh)
    except (OSError, ValueError) as exc:
        raise FlipkitError(f"{path}: cannot read a validate result ({exc})") from None
