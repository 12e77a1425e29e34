"""The cook-window scheduler: one arm flips and serves every burger of a cook order.

Every burger is dropped at ``t_drop``, must land on its second side at its 90 s mark
(``t_drop`` + 90 s) and leave the grill once its second side has cooked 60 s
(``flip_time`` + 60 s, which is its 150 s mark when it was flipped on time). The arm is one
resource; each burger needs two motions on it, a flip and then a serve
(:mod:`flipkit.planning.kitchen.motions`).

Policy — earliest deadline first, one arm, no early starts:

1. The pending motions are the flips of all burgers not yet flipped and the serves of the
   burgers already flipped. The next motion is the pending one whose burger event is due
   first (a flip's landing mark, a serve's lift-off mark; ties: the burger dropped first).
2. It is planned from the configuration the previous motion ended at (at rest; the first
   from ``q_start``; an end within 1e-6 rad of ``q_start`` is taken as ``q_start`` itself,
   the rest configuration every motion returns to, to the solver's tolerance), which gives its duration and the time from its start to the event.
3. It starts when the arm is free, but never so early that its event comes before the mark
   (so no side is cooked shorter than 90 s / 60 s), never before its plan exists (below),
   and a serve never lifts off before its table spot is free (the spots are assigned
   before planning and freed :data:`~flipkit.planning.kitchen.table.DWELL_S` after the
   previous serve to them ends: :mod:`flipkit.planning.kitchen.table`).

Lateness, reported per burger: landing − (``t_drop`` + 90 s) and lift-off − (``t_drop`` +
150 s); both ≥ 0 (overcooking), the second ≥ the first.

Planning runs ahead of execution: the motions are planned one after another, in the order
above, on a planning clock that starts at ``plan_start`` (default: the first drop). A
motion's plan is ready at ``planned_at`` = ``plan_start`` + the planning times so far (or,
planned ahead in parallel worker processes by :mod:`flipkit.planning.kitchen.prefetch`, + when its
plan was in); its slack = (when the arm would start it: free and due) − ``planned_at``. A negative slack
means planning fell behind: the motion then waits for its plan and its lateness shows it.

What is optimal about it: no motion starts early, so cook times are never shortened; when
the motions' windows do not collide every lateness is 0; and among motions that compete for
the arm with equal durations and equal lead times, serving them in deadline order
minimises the largest lateness (Jackson's rule; swapping two adjacent motions out of
deadline order cannot lower the later one's lateness). What is not: flips (3.0–3.4 s) and
serves differ in duration and lead, and then another order, or a deliberate wait, can have
a smaller largest lateness (single-machine L_max with release times is NP-hard in general);
the greedy choice does not look ahead, trades nothing between burgers and does not minimise
total lateness. Durations are known only once a motion is planned from where the previous
one ended, so this rule searches no orders; every flip and serve ends at q_home, and
:mod:`flipkit.planning.kitchen.optimal` plans each motion once and searches the orders and
start times with CP-SAT (``flipkit schedule --policy cpsat``, the default). This rule stays
as the fallback and the baseline (``--policy greedy``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.planning.kitchen.cook import SECOND_SIDE_S, CookBurger, check_cook, table_spots
from flipkit.planning.planners.planner import REST_TOL
from flipkit.planning.kitchen.motions import (KINDS, MissingPlannerError, MotionJob,
                                     MotionPlanner)
from flipkit.planning.kitchen.table import DWELL_S, assign_spots
from flipkit.planning.kitchen.windows import Windows, event_deviations
from tqdm import tqdm

FORMAT = "flipkit-timeline/1"
GREEDY = "earliest-deadline-first, one arm, no motion before its mark"  # the policy's text


@dataclass
class MotionRecord:
    """One motion of the timeline (times in s on the cook order's clock)."""

    kind: str
    burger: str
    due: float  # the burger event's mark
    start: float
    end: float
    event: float | None  # landing (flip) or lift-off (serve); None: not executed
    planned_at: float
    planning_time_s: float
    slack_s: float
    ok: bool
    failure: str | None = None
    plan: object | None = field(default=None, repr=False)
    plan_file: str | None = None

    @property
    def key(self) -> str:
        """``kind:burger``, the motion's key in ``slack_s.by_motion``."""
        return f"{self.kind}:{self.burger}"


@dataclass
class BurgerRecord:
    """One burger of the timeline."""

    burger: CookBurger
    flip_time: float | None = None
    serve_time: float | None = None
    table_spot: tuple | None = None
    landing: tuple | None = None
    failure: str | None = None

    def lateness(self) -> dict:
        """Lateness (s) of the flip against the 90 s mark and of the serve against the
        150 s mark (``None``: not done)."""
        b = self.burger
        return {"flip": None if self.flip_time is None else self.flip_time - b.flip_mark,
                "serve": None if self.serve_time is None else self.serve_time - b.serve_mark}


@dataclass
class Timeline:
    """The scheduled and planned cook.

    Attributes:
        burgers: One :class:`BurgerRecord` per burger, in drop order.
        motions: The arm's motions in execution order.
        kinds: The motion kinds planned (``("flip",)`` for a flips-only timeline).
        plan_start: When planning began (s, order clock).
        policy: How the motions were ordered and timed (one line).
        windows: The event windows the deviations are judged against.
        dwell_s: The table dwell (s).
        solver: The optimiser's record (status, objectives, wall time), or ``None``.
    """

    burgers: list[BurgerRecord]
    motions: list[MotionRecord]
    kinds: tuple
    plan_start: float
    policy: str = GREEDY
    windows: Windows = field(default_factory=Windows)
    dwell_s: float = DWELL_S
    solver: dict | None = None

    @property
    def ok(self) -> bool:
        """Every motion was planned and solved."""
        return all(m.ok for m in self.motions)

    @property
    def planning_time_s(self) -> float:
        """Planning wall time (s): from the start of planning to the last plan in (the sum of
        the motions' planning times when they are planned one after another)."""
        return max((m.planned_at - self.plan_start for m in self.motions), default=0.0)

    @property
    def min_slack_s(self) -> float | None:
        """The smallest slack over the motions (s)."""
        return min((m.slack_s for m in self.motions), default=None)

    def max_lateness_s(self) -> dict:
        """The largest flip and serve lateness (s) over the burgers (``None``: none done)."""
        out = {}
        for mark in ("flip", "serve"):
            vals = [v for b in self.burgers if (v := b.lateness()[mark]) is not None]
            out[mark] = max(vals) if vals else None
        return out

    def to_dict(self) -> dict:
        """The timeline JSON (``flipkit schedule --json``; docs in the module)."""
        def r(v):
            return None if v is None else round(float(v), 6)
        return {
            "format": FORMAT,
            "policy": self.policy,
            "kinds": list(self.kinds),
            "windows": self.windows.to_dict(),
            "dwell_s": self.dwell_s,
            "solver": self.solver,
            "status": "solved" if self.ok else "failed",
            "burgers": [{
                "burger": b.burger.burger, "t_drop": b.burger.t_drop,
                "position": [b.burger.x, b.burger.y],
                "flip_time": r(b.flip_time), "serve_time": r(b.serve_time),
                "lateness_s": {k: r(v) for k, v in b.lateness().items()},
                "deviation_s": {k: r(v) for k, v in event_deviations(b).items()},
                "table_spot": None if b.table_spot is None else list(b.table_spot),
                "landing": None if b.landing is None else [r(v) for v in b.landing],
                "failure": b.failure} for b in self.burgers],
            "motions": [{
                "kind": m.kind, "burger": m.burger, "start": r(m.start), "end": r(m.end),
                "event": r(m.event), "due": r(m.due), "plan": m.plan_file,
                "status": "solved" if m.ok else "failed", "failure": m.failure,
                "planned_at": r(m.planned_at), "planning_time_s": r(m.planning_time_s),
                "slack_s": r(m.slack_s)} for m in self.motions],
            "planning_start": r(self.plan_start),
            "planning_time_s": r(self.planning_time_s),
            "slack_s": {"min": r(self.min_slack_s),
                        "by_motion": {m.key: r(m.slack_s) for m in self.motions}},
            "max_lateness_s": {k: r(v) for k, v in self.max_lateness_s().items()},
        }


def check_cook_inputs(burgers, planners, kinds, cell, spots, dwell_s):
    """The checks both policies make before they plan: ``(cell, kinds, order, spots,
    assigned)`` — the cell (default :class:`~flipkit.config.CellConfig`), the kinds as a
    tuple, the checked cook order, the table spots and each burger's assigned spot (empty
    without serves).

    Raises:
        ConfigError: Bad kinds. MissingPlannerError: A kind without a planner.
        CookOrderError: A malformed order.
    """
    cell = cell or CellConfig()
    kinds = tuple(kinds)
    if "flip" not in kinds or not set(kinds) <= set(KINDS):
        raise ConfigError(f"kinds must be ('flip',) or ('flip', 'serve'), got {kinds}")
    for kind in kinds:
        if kind not in planners:
            raise MissingPlannerError(f"no planner given for the {kind!r} motions")
    order = check_cook(burgers, cell)
    spots = list(table_spots(cell) if spots is None else spots)
    assigned = ({a.burger: a for a in assign_spots(order, spots, dwell_s)}
                if "serve" in kinds else {})
    return cell, kinds, order, spots, assigned


def schedule_cook(burgers, planners: Mapping[str, MotionPlanner], q_start, *,
                  kinds=KINDS, cell: CellConfig | None = None, spots=None,
                  plan_start: float | None = None, progress: bool = False,
                  dwell_s: float = DWELL_S, windows: Windows = Windows()) -> Timeline:
    """Order, time and plan the arm's motions for a cook order (policy: module docstring).

    Args:
        burgers: :class:`~flipkit.planning.kitchen.cook.CookBurger` rows (checked with
            :func:`~flipkit.planning.kitchen.cook.check_cook`).
        planners: Motion kind → :class:`~flipkit.planning.kitchen.motions.MotionPlanner`
            (:func:`~flipkit.planning.kitchen.motions.default_planners` for the real ones).
        q_start: Configuration (rad) the arm rests at before the first motion.
        kinds: Motions to plan: ``("flip", "serve")`` (the cook) or ``("flip",)`` (flips
            only; burgers are left on the grill and ``serve_time`` stays ``None``).
        cell: The cell (default :class:`~flipkit.config.CellConfig`).
        spots: Table spots (x, y) (m) (default
            :func:`~flipkit.planning.kitchen.cook.table_spots`), assigned by
            :func:`~flipkit.planning.kitchen.table.assign_spots`.
        plan_start: When planning begins (s, order clock); default the first drop.
        progress: Show a tqdm progress bar (stderr), one step per motion.
        dwell_s: Table dwell (s): a spot is free again this long after a serve to it ended.
        windows: The event windows, recorded in the timeline (this rule does not use them).

    Returns:
        The timeline. A motion whose plan failed is recorded (``ok`` False) and not
        executed: the arm stays where it was, and that burger gets no further motion.

    Raises:
        MissingPlannerError: A kind in ``kinds`` without a planner.
        CookOrderError: A malformed order. ConfigError: Bad kinds, spots or times.
    """
    cell, kinds, order, spots, assigned = check_cook_inputs(burgers, planners, kinds, cell,
                                                            spots, dwell_s)
    serve_end: dict[str, float] = {}
    records = [BurgerRecord(b) for b in order]
    clock = min(b.t_drop for b in order) if plan_start is None else float(plan_start)
    if not np.isfinite(clock):
        raise ConfigError(f"plan_start must be finite (s), got {plan_start!r}")
    t0, q = clock, np.asarray(q_start, float)
    q_rest = q.copy()
    arm_free = -np.inf
    # pending: (due, drop rank, kind rank, burger index, kind)
    pending = [(b.burger.flip_mark, k, 0, k, "flip") for k, b in enumerate(records)]
    motions: list[MotionRecord] = []
    bar = tqdm(total=len(order) * len(kinds), desc="motions", unit="motion",
               disable=not progress)
    while pending:
        pending.sort()
        due, _, _, k, kind = pending.pop(0)
        rec = records[k]
        b = rec.burger
        spot_free = -np.inf
        if kind == "flip":
            job = MotionJob("flip", b.burger, b.location(cell))
        else:
            rec.table_spot = tuple(assigned[b.burger].spot)
            job = MotionJob("serve", b.burger, (*rec.landing, cell.grill.height),
                            rec.table_spot)
            spot_free = serve_end.get(assigned[b.burger].previous, -np.inf) + dwell_s
        pm = planners[kind](job, q)
        ready = getattr(pm, "ready_s", None)  # planned ahead, in parallel: when it was in
        clock = (max(clock, t0 + ready) if ready is not None
                 else clock + float(pm.planning_time_s))
        wanted = max(arm_free, due - pm.event_s,  # arm free, and the event not early,
                     spot_free - pm.event_s)  # and a serve's spot free at its lift-off
        start = max(wanted, clock)  # and the plan ready
        run = pm.duration_s if pm.ok else 0.0  # a failed plan is not executed
        m = MotionRecord(kind, b.burger, due, start, start + run,
                         start + pm.event_s if pm.ok else None, clock,
                         float(pm.planning_time_s), wanted - clock, pm.ok, pm.failure, pm.plan)
        motions.append(m)
        bar.update(1)
        bar.set_postfix_str(f"{m.key} {'solved' if pm.ok else 'failed'}")
        if not pm.ok:  # not executed: the arm stays; the burger gets no further motion
            rec.failure = f"{kind}: {pm.failure}"
            if kind == "serve":
                rec.table_spot = None
            if kind == "flip" and "serve" in kinds:
                bar.total -= 1  # its serve will not be planned
            continue
        arm_free, q = m.end, np.asarray(pm.q_end, float)
        if np.abs(q - q_rest).max() <= REST_TOL:  # back at rest to the solver's tolerance
            q = q_rest
        if kind == "flip":
            rec.flip_time = m.event
            rec.landing = pm.landing if pm.landing is not None else (b.x, b.y)
            if "serve" in kinds:
                pending.append((m.event + SECOND_SIDE_S, k, 1, k, "serve"))
        else:
            rec.serve_time = m.event
            serve_end[b.burger] = m.end
    bar.close()
    return Timeline(records, motions, kinds, t0, windows=windows, dwell_s=dwell_s)


def format_timeline(timeline: Timeline) -> str:
    """The lateness table and the motions, as aligned text: per burger its flip and its
    lateness (= its deviation from the 90 s mark), its serve, its lateness against the 150 s
    mark and its deviation from its own mark (landing + 60 s), which its window judges."""
    def f(v):
        return "-" if v is None else f"{v:.2f}"
    lines = [f"{'burger':<10}{'t_drop':>8}{'flip':>9}{'late':>7}{'serve':>9}{'late':>7}"
             f"{'dev':>7}  failure"]
    for b in timeline.burgers:
        late, dev = b.lateness(), event_deviations(b)
        lines.append(f"{b.burger.burger:<10}{b.burger.t_drop:>8.2f}{f(b.flip_time):>9}"
                     f"{f(late['flip']):>7}{f(b.serve_time):>9}{f(late['serve']):>7}"
                     f"{f(dev['serve']):>7}  {b.failure or ''}")
    lines.append(f"{'motion':<16}{'start':>9}{'end':>9}{'event':>9}{'plan s':>8}{'slack':>9}")
    for m in timeline.motions:
        lines.append(f"{m.key:<16}{m.start:>9.2f}{m.end:>9.2f}{f(m.event):>9}"
                     f"{m.planning_time_s:>8.2f}{m.slack_s:>9.2f}"
                     + ("" if m.ok else "  failed"))
    return "\n".join(lines)


__all__ = ["FORMAT", "BurgerRecord", "MotionRecord", "Timeline", "format_timeline",
           "schedule_cook"]
