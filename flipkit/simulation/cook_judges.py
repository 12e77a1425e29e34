"""The verdict on one burger of a simulated cook, from its own trajectory.

Flip: :func:`~flipkit.simulation.judges.judge_flip` on the burger's flip window (its flip
motion and :data:`~flipkit.simulation.execute.HOLD_S` after it), against the plan's landing
target (the flip segment's ``landing["target"]``, else
:func:`~flipkit.behaviors.targets.landing_spot`): on the blade ≥ 60 % of the flip, upside
down, on the grill, within 5 cm in x and y. Serve: :func:`~flipkit.simulation.judges.judge_serve`
on its serve window, against the plan's table spot: resting on the table, off the blade,
within 3 cm, the face that was up when the serve began still up (a flipped burger's up axis
is its original −z: the judge reads the burger frame turned half a turn about its x axis,
the disc being symmetric about its mid-plane).

Events, on the cook clock (s): the landing is the first burger–grill contact after the last
burger–blade contact of the flip segment; the lift-off is the sample after the last
burger–grill contact of the serve window (``None`` when the burger never left the grill).
Their deviations from the marks are :func:`~flipkit.planning.kitchen.windows.event_deviations`
of these times.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from flipkit.planning.kitchen.windows import event_deviations
from flipkit.planning.planners.serve import table_spot
from flipkit.simulation.judges import (FLIP_CONTACT_FRACTION, LANDING_TOL, SERVE_TOL, FlipVerdict,
                                      ServeVerdict, judge_flip, judge_serve, landing_target)
from flipkit.simulation.run import BurgerRun

HALF_TURN_X = np.diag([1.0, -1.0, -1.0])  # burger frame turned π about its x axis


@dataclass
class BurgerResult:
    """One burger of a simulated cook (times in s on the cook clock, lengths in m).

    Attributes:
        burger: Its id. flipped, served: The flip and serve judges' verdicts.
        flip, serve: The judges' full verdicts (``None``: that motion was not run).
        landing_s, liftoff_s: Simulated event times (``None``: did not happen).
        deviation_s: Simulated events − marks (``{"flip", "serve"}``, ``None`` where missing).
        planned_deviation_s: The timeline's deviations of the planned events.
        knocked_m: Largest displacement of its centre while it lay untouched by its own
            motions (moved by another burger's motion: knocked).
        contact_s: Time (s) it touched another burger.
        failure: Why it is not flipped and served (one line), or ``None``.
    """

    burger: str
    flipped: bool
    served: bool
    flip: FlipVerdict | None
    serve: ServeVerdict | None
    landing_s: float | None
    liftoff_s: float | None
    deviation_s: dict
    planned_deviation_s: dict
    knocked_m: float
    contact_s: float
    failure: str | None

    @property
    def ok(self) -> bool:
        """Flipped and served."""
        return self.flipped and self.served

    def to_dict(self) -> dict:
        """JSON-ready fields (verdict details: landing offset, serve distance, up axis)."""
        def r(v):
            return None if v is None else round(float(v), 6)
        return {"burger": self.burger, "flipped": self.flipped, "served": self.served,
                "landing_s": r(self.landing_s), "liftoff_s": r(self.liftoff_s),
                "deviation_s": {k: r(v) for k, v in self.deviation_s.items()},
                "planned_deviation_s": {k: r(v) for k, v in self.planned_deviation_s.items()},
                "landing_offset_m": None if self.flip is None else [r(v) for v in self.flip.offset],
                "serve_distance_m": None if self.serve is None else r(self.serve.distance),
                "serve_up_z": None if self.serve is None else r(self.serve.up_z),
                "knocked_m": r(self.knocked_m), "contact_s": r(self.contact_s),
                "failure": self.failure}


def landing_time(run: BurgerRun, flip_bounds) -> float | None:
    """First burger–grill contact after the last burger–blade contact in the flip (run's s)."""
    sel = (run.t >= flip_bounds[0] - 1e-9) & (run.t <= flip_bounds[1] + 1e-9)
    on = np.flatnonzero(sel & run.touch_spatula)
    if on.size == 0:
        return None
    hit = np.flatnonzero(run.touch_grill[on[-1] + 1:])
    return None if hit.size == 0 else float(run.t[on[-1] + 1 + hit[0]])


def liftoff_time(run: BurgerRun) -> float | None:
    """The sample after the last burger–grill contact (run's s); ``None`` if it never left."""
    on = np.flatnonzero(run.touch_grill)
    if on.size == 0 or on[-1] + 1 >= len(run.t):
        return None
    return float(run.t[on[-1] + 1])


def upright_frame(run: BurgerRun) -> BurgerRun:
    """``run`` with the burger frame whose z was up at its start (half a turn if upside down)."""
    if run.up_z[0] >= 0:
        return run
    return BurgerRun(run.t, run.burger_pos, run.burger_rot @ HALF_TURN_X, run.spatula_pos,
                     run.spatula_rot, run.touch_spatula, run.touch_grill, run.force_spatula,
                     run.force_grill, run.burger_diameter, run.burger_thickness,
                     run.blade_length, run.blade_width, run.grill_height)


def judge_burger(record, flip, serve, table, knocked_m: float, contact_s: float
                 ) -> BurgerResult:
    """The verdict on one burger.

    Args:
        record: The timeline's burger record (``burger``, ``flip_time``, ``serve_time``).
        flip, serve: ``(plan, run, bounds, start)`` of its flip and serve (``None``: not
            run): the run on times from the motion's ``start`` (s, cook clock) and the
            plan's segment bounds on that clock.
        table: The :class:`~flipkit.config.TableConfig`.
        knocked_m, contact_s: From the recorder.
    """
    fv = sv = landing = liftoff = None
    if flip is not None:
        plan, run, bounds, start = flip
        flight = bounds[plan.step("release").name]
        fv = judge_flip(run, flight, landing_target(plan))
        t = landing_time(run, flight)
        landing = None if t is None else start + t
    if serve is not None:
        plan, run, _, start = serve
        sv = judge_serve(upright_frame(run), table_spot(plan), table)
        t = liftoff_time(run)
        liftoff = None if t is None else start + t
    done = SimpleNamespace(burger=record.burger, flip_time=landing, serve_time=liftoff)
    return BurgerResult(record.burger.burger, bool(fv and fv.ok), bool(sv and sv.ok), fv, sv,
                        landing, liftoff, event_deviations(done), event_deviations(record),
                        float(knocked_m), float(contact_s), _failure(fv, sv))


def _failure(fv: FlipVerdict | None, sv: ServeVerdict | None) -> str | None:
    """The first reason the burger is not flipped and served, one line."""
    if fv is None:
        return "flip: not run"
    if not fv.ok:
        miss = max(abs(v) for v in fv.offset)
        return ("flip: " + ("on the blade only {:.0%} of the flip".format(fv.contact_fraction)
                            if fv.contact_fraction < FLIP_CONTACT_FRACTION else
                            f"not upside down (up z {fv.up_z:+.2f})" if not fv.upside_down else
                            "not on the grill" if not fv.on_grill else
                            f"landed {100 * miss:.1f} cm from its target (tolerance "
                            f"{100 * LANDING_TOL:g} cm)"))
    if sv is None:
        return "serve: not run"
    if not sv.ok:
        return ("serve: " + (f"not top up (up z {sv.up_z:+.2f})" if not sv.upright else
                             "not on the table" if not sv.on_table else
                             "still on the blade" if not sv.off_blade else
                             "not at rest" if not sv.at_rest else
                             f"{100 * sv.distance:.1f} cm from its spot (tolerance "
                             f"{100 * SERVE_TOL:g} cm)"))
    return None


__all__ = ["BurgerResult", "judge_burger", "landing_time", "liftoff_time",
           "upright_frame"]
