"""What a stream's schedule achieves: burgers per hour served within their windows, the arm's
utilisation and the largest lateness; and a sweep of drop rates for the ``throughput`` figure.

* **Burgers per hour within windows**: the drop rate times the share of burgers whose flip
  and serve both lie within their windows (to 2 ms, the optimiser's rounding) and could
  run: a burger that another burger blocks at every scoop heading
  (:func:`~flipkit.planning.kitchen.reach.blocked_burgers`, when the model has its plans'
  footprints) is missed; the drop rate when all are within and none is blocked.
* **Utilisation**: the arm's motion time over the span from its first motion's start to
  its last motion's end.
* **Largest lateness**: the largest deviation of an event past its mark (s, ≥ 0): a flip's
  landing after ``t_drop`` + 90 s, a serve's lift-off after its landing + 60 s.

:func:`run_stream` schedules a stream with either policy on a
:class:`~flipkit.planning.kitchen.durations.MotionModel` (no motion planned; for the real
plans, schedule the stream's order as a cook); :func:`sweep_rates` runs it over rates.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import InvalidChoiceError
from flipkit.planning.kitchen.durations import MotionModel
from flipkit.planning.kitchen.cpsat_process import Child
from flipkit.planning.kitchen.optimal import schedule_cook_cpsat
from flipkit.planning.kitchen.reach import blocked_burgers
from flipkit.planning.kitchen.schedule import Timeline, schedule_cook
from flipkit.planning.kitchen.stream import StreamError, stream_order
from flipkit.planning.kitchen.table import DWELL_S
from flipkit.planning.kitchen.windows import Windows, event_deviations, worst_break

POLICIES = ("cpsat", "greedy")


@dataclass(frozen=True)
class StreamReport:
    """A stream's schedule, measured (module docstring); rates per hour, times in s.

    ``n_within`` counts the burgers within their windows and not blocked; ``n_blocked`` the
    burgers blocked at every scoop heading and ``n_within_timing`` those within their windows
    whatever the geometry (``n_blocked`` ``None``: the sweeps were not checked).
    """

    policy: str
    rate_per_h: float
    minutes: float
    n_burgers: int
    n_within: int
    per_hour_within: float
    utilisation: float
    max_lateness_s: float
    windows_met: bool
    status: str
    n_blocked: int | None = None
    n_within_timing: int | None = None

    def to_dict(self) -> dict:
        """The report as a dict (JSON)."""
        return asdict(self)

    def summary(self) -> str:
        """One line."""
        reach = ("the motions' sweeps not checked against the burgers on the grill"
                 if self.n_blocked is None else
                 f"{self.n_blocked} blocked by other burgers at every scoop heading")
        return (f"{self.policy}: {self.n_within}/{self.n_burgers} burgers within their "
                f"windows, {self.per_hour_within:.0f} per hour (drops {self.rate_per_h:g} per "
                f"hour); {reach}; arm utilisation {100 * self.utilisation:.0f} %; largest "
                f"lateness {self.max_lateness_s:.2f} s")


def stream_report(timeline: Timeline, policy: str, rate_per_h: float, minutes: float,
                  blocked=None) -> StreamReport:
    """Measure a stream's timeline (module docstring); ``blocked``: the burgers whose motions
    are clear at no heading (:func:`~flipkit.planning.kitchen.reach.blocked_burgers`), counted
    as missed, or ``None``: not checked."""
    w = timeline.windows
    within, late = 0, 0.0
    missed = set() if blocked is None else {b.burger for b in blocked}
    timed = 0
    for b in timeline.burgers:
        dev = event_deviations(b)
        done = (all(dev[k] is not None for k in timeline.kinds)
                and all(w.excess(k, dev[k]) <= 2e-3 for k in timeline.kinds))
        timed += done
        within += done and b.burger.burger not in missed
        late = max([late] + [v for v in dev.values() if v is not None])
    ran = [m for m in timeline.motions if m.ok]
    span = max(m.end for m in ran) - min(m.start for m in ran) if ran else 0.0
    busy = sum(m.end - m.start for m in ran)
    status = timeline.solver["status"] if timeline.solver else "greedy"
    return StreamReport(policy, rate_per_h, minutes, len(timeline.burgers), int(within),
                        rate_per_h * within / max(len(timeline.burgers), 1), busy / span if span > 0 else 0.0,
                        max(late, 0.0), worst_break(timeline.burgers, w) is None, status,
                        None if blocked is None else len(missed), int(timed))


def run_stream(rate_per_h: float, minutes: float, model: MotionModel, *,
               policy: str = "cpsat", windows: Windows = Windows(), dwell_s: float = DWELL_S,
               seed: int = 0, cell: CellConfig | None = None, time_limit_s: float = 10.0,
               workers: int = 1, child: Child | None = None) -> tuple[Timeline, StreamReport]:
    """Schedule a stream (:func:`~flipkit.planning.kitchen.stream.stream_order`) on the
    model's times with ``policy`` ("cpsat": fewest burgers beyond their windows first, see
    :mod:`~flipkit.planning.kitchen.cpsat`, asked of ``child`` if given, as
    :func:`~flipkit.planning.kitchen.optimal.schedule_cook_cpsat`; "greedy") and measure it.

    Raises:
        InvalidChoiceError: An unknown policy. StreamError: As ``stream_order``.
    """
    if policy not in POLICIES:
        raise InvalidChoiceError("policy", policy, POLICIES)
    cell = cell or CellConfig()
    order = stream_order(rate_per_h, minutes, seed, cell, windows)
    q = np.zeros(6)
    planners = model.planners()
    if policy == "cpsat":
        tl = schedule_cook_cpsat(order, planners, q, cell=cell, windows=windows,
                                 dwell_s=dwell_s, time_limit_s=time_limit_s, workers=workers,
                                 seed=seed, relax="count", child=child)
    else:
        tl = schedule_cook(order, planners, q, cell=cell, dwell_s=dwell_s, windows=windows)
    blocked = (None if model.footprints is None
               else blocked_burgers(tl, model.footprints, cell))
    return tl, stream_report(tl, policy, rate_per_h, minutes, blocked)


def sweep_rates(rates, minutes: float, model: MotionModel, policies=POLICIES,
                **kw) -> list[dict]:
    """:func:`run_stream` at each rate and policy; one row per pair: the report's fields, or
    ``{"policy", "rate_per_h", "refused": reason}`` where the stream cannot be made (a full
    grill). ``kw``: as :func:`run_stream`; without a ``child``, one CP-SAT child serves every
    schedule of the sweep and is stopped at its end."""
    if kw.get("child") is None:
        with Child() as child:
            return sweep_rates(rates, minutes, model, policies, **{**kw, "child": child})
    rows = []
    for rate in rates:
        for policy in policies:
            try:
                rows.append(run_stream(rate, minutes, model, policy=policy, **kw)[1].to_dict())
            except StreamError as exc:
                rows.append({"policy": policy, "rate_per_h": rate, "refused": str(exc)})
    return rows


__all__ = ["POLICIES", "StreamReport", "run_stream", "stream_report", "sweep_rates"]
