"""Sense, plan, act on the blade during a cook's serve: :data:`SENSE_LEAD_S` before the carry
ends the camera sees where the burger lies on the blade, and place and return home are
planned again for it while the carry runs on.

The re-plan starts where the planned carry ends (at rest, the blade flat above the table, as
:func:`~flipkit.planning.planners.serve.replan_serve` expects), so it can run while the arm
is still carrying: the cell never waits for it unless it takes longer than the lead, and then
only for the rest, held at the carry's end in whole control steps. A cook cannot stretch a
serve into the next motion: the re-plan is used only if it is solved and the serve, paused
(if at all) and re-planned, still ends before the next motion starts; otherwise the scheduled
serve runs on and the record says why.

Why a lead of 0.5 s: the blade re-plans take well under that on an idle machine, so 0.5 s
leaves the loaded machine of a busy cell some room. What the camera sees then is not quite where the burger
rests when the carry stops: the record gives both (``on_blade_true`` at the sense,
``on_blade_at_stop`` at the carry's end) and the distance between them
(``shift_over_lead_m``), so the shift over the lead is measured in every simulated cook.
"""

from __future__ import annotations

import time

import numpy as np

from flipkit.errors import FlipkitError
from flipkit.simulation.control import pause_steps, plan_references
from flipkit.simulation.scene import Scene

SENSE_LEAD_S = 0.5  # s before the carry's end that the camera sees the burger (docstring)


def sense_time(span, lead_s: float = SENSE_LEAD_S) -> float:
    """When (s) the camera sees the burger in the sensed segment ``span`` = (start, end) (s):
    ``lead_s`` before its end, not before its start."""
    return max(span[0], span[1] - lead_s)


def blade_replan(scene: Scene, burger: int, plan, replan, error, *, t_now: float,
                 t_stop: float, start: float, next_start: float, dt: float,
                 references: dict) -> tuple:
    """At cook time ``start + t_now`` (during the carry): the re-planned serve's references, or
    ``None``, and the record of the sense.

    Args:
        scene: The cook's scene. burger: Index of the carried burger. plan: The serve running.
        replan: ``replan(plan, on_blade) -> Plan`` (e.g. ``replan_serve``); a
            :class:`~flipkit.errors.FlipkitError` is a refusal.
        error: The camera's error (m, (2,)) added to the true place on the blade.
        t_now: Time (s) into the serve of the sense. t_stop: Time (s) into the serve at
            which the carry ends, ``t_stop >= t_now``: the re-plan runs meanwhile, and the
            arm holds there for the part of its wall time beyond ``t_stop - t_now``.
            start, next_start: The serve's and the next motion's start (s, cook clock;
            ``inf`` for none). dt: Control period (s).
        references: ``plan_references``'s other arguments: ``robot``, ``physics``, ``mode``,
            ``command``, ``hold_max`` (the longest hold after the serve, s).

    Returns:
        ``(refs or None, new plan or None, record)``; ``record`` holds ``burger`` (index),
        ``on_blade_true``, ``on_blade_sensed`` (m), ``replanned``, ``why``, ``wall_s``,
        ``lead_s`` (``t_stop - t_now``) and ``pause_s`` (the hold at the carry's end).
    """
    if not t_stop >= t_now:
        raise FlipkitError(f"the carry's end ({t_stop} s) precedes the sense ({t_now} s)")
    true = scene.in_blade_frame(scene.burger_bodies[burger])[:2]
    sensed = true + np.asarray(error, float)
    sp = scene.robot.cell.spatula
    t0 = time.perf_counter()
    if np.any(np.abs(sensed) > (sp.length / 2, sp.width / 2)):  # the scoop missed it
        new, why = None, (f"the burger is not on the blade during the carry: seen at "
                          f"({sensed[0]:+.3f}, {sensed[1]:+.3f}) m in the blade frame")
    else:
        try:
            new = replan(plan, sensed)
            why = None if new.status == "solved" else ("the re-plan failed: "
                                                         + (new.failure or new.status))
        except FlipkitError as exc:
            new, why = None, f"the re-plan was refused: {exc}"
    wall = time.perf_counter() - t0
    pause = pause_steps(wall, dt, t_stop - t_now)  # the hold beyond the rest of the carry
    refs = None
    if why is None:
        end = start + pause + new.duration
        if end > next_start + 1e-9:
            why = f"the re-planned serve would end {end - next_start:.2f} s into the next motion"
        else:
            r = references
            hold = min(max(next_start - end, 0.0), r["hold_max"])
            refs = plan_references(new, r["robot"], r["physics"], r["mode"], r["command"], dt,
                                   hold, t_stop, pause)
    record = {"burger": int(burger), "on_blade_true": [round(float(v), 5) for v in true],
              "on_blade_sensed": [round(float(v), 5) for v in sensed],
              "replanned": why is None, "why": why, "wall_s": round(wall, 3),
              "lead_s": round(float(t_stop - t_now), 3),
              "pause_s": round(float(pause), 3) if why is None else 0.0}
    return refs, (new if why is None else None), record


__all__ = ["SENSE_LEAD_S", "blade_replan", "sense_time"]
