"""``flipkit schedule`` once its arguments passed :mod:`flipkit.cli.schedule` (which sets
``MUJOCO_GL`` before this module imports MuJoCo): read the cook order, plan its motions,
write the timeline, the plans and the Gantt chart, simulate the cook (``--simulate``, and
its ``--film``), report."""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import sys
import warnings
from pathlib import Path

import matplotlib

from flipkit import figures
from flipkit.cli.common import write_json
from flipkit.config import CellConfig
from flipkit.errors import FlipkitError
from flipkit.experiments.sweep import make_executor
from flipkit.figures.draw import plot_schedule
from flipkit.fileio import replace_with
from flipkit.planning.kitchen import motions
from flipkit.planning.kitchen.clearance import CookConflictError, clear_cook, cook_meetings
from flipkit.planning.kitchen.cook import check_cook, table_spots
from flipkit.planning.kitchen.cpsat_process import Child
from flipkit.planning.kitchen.durations import plan_model, representative_order
from flipkit.planning.kitchen.optimal import schedule_cook_cpsat
from flipkit.planning.kitchen.prefetch import PrefetchPlanners
from flipkit.planning.kitchen.schedule import format_timeline, schedule_cook
from flipkit.planning.kitchen.stream import stream_order
from flipkit.planning.kitchen.table import assign_spots
from flipkit.planning.kitchen.throughput import run_stream, stream_report
from flipkit.planning.kitchen.windows import WindowsBrokenError, worst_break
from flipkit.planning.planners.atlas import default_atlas
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.simulation.cook import simulate_cook
from flipkit.simulation.cook_film import FILM_FPS, write_cook_film


def _safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)[:40] or "burger"


def _planners(order, kinds, cell, args, atlas, spots, executor, caches):
    """The real planners, prefetching in ``executor``'s workers when there is one; what is
    planned in this process uses ``caches``."""
    if executor is None:
        return motions.default_planners(kinds, cell, args.solver, atlas, caches)
    return PrefetchPlanners(order, kinds, cell.robot.q_home, spots, executor, cell,
                            args.solver, atlas, caches)


def run(args: argparse.Namespace) -> int:
    """Read (or make the stream), plan, schedule, check the windows, write, report."""
    warnings.filterwarnings("ignore", message="Solution may be inaccurate")
    cell = CellConfig()
    kinds = ("flip",) if args.flip_only else ("flip", "serve")
    stream = args.stream is not None
    burgers = (stream_order(args.stream, args.minutes, args.seed, cell, args.windows)
               if stream else args.order)  # the cook order read by flipkit.cli.schedule
    atlas = None if args.no_atlas else default_atlas(cell)
    caches = PlannerCaches()  # every motion and re-plan this process plans, one after another
    timeline_path, plans = Path(args.json), Path(args.plans)  # --plans checked there too
    workers = (os.cpu_count() or 1) if args.workers is None else args.workers
    pool = make_executor(workers=workers) if workers > 1 else contextlib.nullcontext()
    # the workers, and the CP-SAT child that answers every schedule of the run, end with it
    with pool as executor, Child() as child:
        if stream and not args.plan:
            return _modelled_stream(args, cell, atlas, executor, timeline_path, caches, child)
        order = check_cook(burgers, cell)
        spots = [a.spot for a in assign_spots(order, table_spots(cell), args.dwell)]
        planners = _planners(order, kinds, cell, args, atlas, spots, executor, caches)
        if executor is None:
            planners = motions.cached_planners(planners)
        common = dict(kinds=kinds, cell=cell, windows=args.windows, dwell_s=args.dwell)
        lands, headings = {}, {}
        try:
            if args.policy == "cpsat":
                def cpsat(lands, headings):
                    return schedule_cook_cpsat(burgers, planners, cell.robot.q_home, **common,
                                               lands=lands, headings=headings,
                                               time_limit_s=args.time_limit, seed=args.seed,
                                               child=child)

                timeline, lands, headings = clear_cook(cpsat, cell, atlas=atlas)
            else:
                timeline = schedule_cook(burgers, planners, cell.robot.q_home, **common,
                                         progress=not args.no_progress)
                met = cook_meetings(timeline, cell) if timeline.ok else []
                if met:
                    raise CookConflictError(f"{met[0][0].describe()}; the greedy schedule "
                                            f"lands every burger where it was picked up; "
                                            f"--policy cpsat moves landings out of the way")
        except CookConflictError as exc:  # refused before any motion runs: nothing written
            print(f"flipkit: error: {args.policy}: {exc}", file=sys.stderr)
            return 1
    breach = worst_break(timeline.burgers, args.windows)
    if timeline.ok and breach is not None:  # refused before any motion runs: nothing written
        why = ("the greedy schedule; --policy cpsat searches the others"
               if args.policy == "greedy" else _cpsat_why(timeline.solver))
        print(f"flipkit: error: {WindowsBrokenError(breach, args.policy, why)}",
              file=sys.stderr)
        return 1
    try:
        plans.mkdir(parents=True, exist_ok=True)
        for k, m in enumerate(timeline.motions, 1):
            if m.plan is None:
                continue
            path = plans / f"{k:02d}_{m.kind}_{_safe(m.burger)}.json"
            m.plan.to_json(path)
            try:
                m.plan_file = str(path.resolve().relative_to(timeline_path.resolve().parent))
            except ValueError:
                m.plan_file = str(path.resolve())
    except OSError as exc:
        raise FlipkitError(f"{plans}: cannot write plans ({exc.strerror or exc})") from None
    doc = timeline.to_dict()
    doc["clearance"] = {"landings_moved": {b: [round(v, 4) for v in xy]
                                           for b, xy in sorted(lands.items())},
                        "headings_turned_deg": {b: round(math.degrees(psi), 2)
                                                for b, psi in sorted(headings.items())}}
    if stream:
        doc["stream"] = stream_report(timeline, args.policy, args.stream,
                                      args.minutes).to_dict()
    sim = None
    if getattr(args, "simulate", False) and timeline.ok:  # a failed schedule is not simulated
        sense = (motions.serve_replanner(cell, args.solver, atlas, caches) if args.sense
                 else None)
        blade = motions.blade_replanner(args.solver, caches) if args.sense else None
        sim = simulate_cook(timeline, mode=args.mode, film_fps=FILM_FPS if args.film else 0.0,
                            sense_serve=sense, sense_blade=blade, seed=args.seed)
        doc["simulation"] = sim.to_dict()
    write_json(timeline_path, doc)
    if args.figure:
        _figure(doc, args.figure)
    if not stream:
        print(format_timeline(timeline))
    late = doc["max_lateness_s"]
    # a failed plan leaves the schedule unjudged: the windows and the meetings are checked only
    # on a schedule of solved motions (clear_cook returns a failed one unchecked)
    checks = (f"windows {args.windows.describe()} met; {_moved(lands, headings)}" if timeline.ok else
              "windows and meetings with other burgers not checked: a motion failed to plan")
    print(f"flipkit schedule: {len(timeline.burgers)} burgers, {len(timeline.motions)} "
          f"motions ({'+'.join(kinds)}), {doc['status']}, policy {args.policy}"
          f"{_solver_note(timeline.solver)}; planning {doc['planning_time_s']:.1f}"
          f" s, min slack {doc['slack_s']['min']:.1f} s, max lateness flip "
          f"{_s(late['flip'])}, serve {_s(late['serve'])}; {checks}; wrote {timeline_path}")
    for b in timeline.burgers:
        if b.failure:
            print(f"flipkit: error: burger {b.burger.burger}: {b.failure}", file=sys.stderr)
    if sim is not None:
        return _report_simulation(sim, args)
    return 0 if timeline.ok else 1


def _report_simulation(sim, args: argparse.Namespace) -> int:
    """One line per simulated burger and a summary; the film; exit 0 all flipped and served."""
    def s(v):
        return "-" if v is None else f"{v:+.3f}"
    for b in sim.burgers:
        off = "-" if b.flip is None else "{:.1f}".format(100 * max(map(abs, b.flip.offset)))
        dist = "-" if b.serve is None else f"{100 * b.serve.distance:.1f}"
        print(f"simulated {b.burger}: flipped {'yes' if b.flipped else 'no'} (landing off "
              f"{off} cm, {s(b.deviation_s['flip'])} s from its mark), served "
              f"{'yes' if b.served else 'no'} ({dist} cm from its spot, "
              f"{s(b.deviation_s['serve'])} s from its mark), knocked {1000 * b.knocked_m:.1f} "
              f"mm{'' if b.ok else '; ' + b.failure}")
    for r in sim.sensed:
        print(f"sensed serve {r['burger']}: seen at ({r['sensed_xy'][0]:.3f}, "
              f"{r['sensed_xy'][1]:.3f}), planned for ({r['planned_xy'][0]:.3f}, "
              f"{r['planned_xy'][1]:.3f}); " + (f"re-planned in {r['wall_s']:.2f} s"
                                                if r["replanned"] else
                                                f"scheduled serve ran: {r['why']}"))
    for r in sim.sensed_blade:
        seen = r["on_blade_sensed"]
        print(f"sensed serve {r['serve']} on the blade {r['lead_s']:.2f} s before the carry's "
              f"end: seen at ({seen[0]:+.3f}, {seen[1]:+.3f}) m; "
              + (f"re-planned in {r['wall_s']:.2f} s, the arm held {r['pause_s']:.2f} s"
                 if r["replanned"] else f"scheduled serve ran: {r['why']}"))
    film = ""
    if args.film:
        replace_with(args.film, lambda tmp: write_cook_film(sim, tmp,
                                                            progress=not args.no_progress))
        film = f"; wrote {args.film}"
    ok = sum(b.ok for b in sim.burgers)
    near = ("-" if sim.min_distance_m == float("inf") else f"{100 * sim.min_distance_m:.1f} cm")
    print(f"flipkit schedule: simulated ({sim.mode}) {ok} of {len(sim.burgers)} burgers "
          f"flipped and served; closest lying burgers {near}; stepped {sim.stepped_s:.1f} s, "
          f"skipped {sim.skipped_s:.1f} s idle, wall {sim.wall_s:.1f} s{film}")
    bad = [b for b in sim.burgers if not b.ok]
    if bad:
        print(f"flipkit: error: simulated cook: {len(bad)} of {len(sim.burgers)} burgers not "
              f"flipped and served; burger {bad[0].burger}: {bad[0].failure}", file=sys.stderr)
        return 1
    return 0


def _modelled_stream(args, cell, atlas, executor, timeline_path: Path, caches, child) -> int:
    """A stream scheduled on the durations of representative plans: report and JSON."""
    rep, rep_spots = representative_order(cell)
    model = plan_model(_planners(rep, ("flip", "serve"), cell, args, atlas, rep_spots,
                                 executor, caches), cell.robot.q_home, cell)
    timeline, report = run_stream(args.stream, args.minutes, model, policy=args.policy,
                                  windows=args.windows, dwell_s=args.dwell, seed=args.seed,
                                  cell=cell, time_limit_s=args.time_limit, child=child)
    doc = timeline.to_dict()
    doc["stream"], doc["motion_model"] = report.to_dict(), model.to_dict()
    write_json(timeline_path, doc)
    print(f"flipkit schedule: stream of {report.n_burgers} burgers ({args.stream:g} per hour "
          f"for {args.minutes:g} min), durations modelled on {model.source}; "
          f"{report.summary()}{_solver_note(timeline.solver)}; wrote {timeline_path}")
    breach = worst_break(timeline.burgers, args.windows)
    if breach is not None:
        print(f"flipkit: error: {WindowsBrokenError(breach, args.policy, 'in this stream')}",
              file=sys.stderr)
        return 1
    return 0


def _moved(lands: dict, headings: dict) -> str:
    if not lands and not headings:
        return "no motion meets another burger"
    return ("no motion meets another burger with " + ", ".join(
        [f"{b} landed at ({x:.3f}, {y:.3f})" for b, (x, y) in sorted(lands.items())]
        + [f"{b} scooped at {math.degrees(psi):.0f} deg" for b, psi in sorted(headings.items())]))


def _cpsat_why(solver: dict | None) -> str:
    if solver and solver.get("proved_infeasible"):
        return ("CP-SAT proved that no schedule keeps every event in its window, and no "
                "schedule breaks them by less")
    return (f"CP-SAT found no schedule within the windows in its {solver['time_limit_s']:g} s "
            f"(status {solver['status']}); --time-limit gives it longer") if solver else ""


def _solver_note(solver: dict | None) -> str:
    return "" if not solver else (f" (CP-SAT {solver['status']} in "
                                  f"{solver['wall_s']:.2f} s)")


def _s(v) -> str:
    return "-" if v is None else f"{v:.2f} s"


def _figure(doc: dict, path) -> None:
    """Draw the Gantt chart of ``doc`` to ``path``."""
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # the figure is optional: pyplot only for --figure

    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.PAGE_WIDTH, 0.35 * len(doc["burgers"]) + 1.6),
                               layout="constrained")
        plot_schedule(ax, doc)
        try:
            replace_with(path, lambda tmp: fig.savefig(
                tmp, metadata={"CreationDate": None} if str(path).endswith(".pdf") else None))
        except ValueError as exc:
            raise FlipkitError(f"cannot write figure {path}: {exc}") from None
        finally:
            plt.close(fig)
