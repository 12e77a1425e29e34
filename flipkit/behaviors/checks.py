"""The subbehaviours' independent path checks: what ``verify`` checks of a segment beyond its
end pose, end condition and cone, declared on its spec (``Subbehavior.checks``).

Each check takes a :class:`~flipkit.behaviors.probe.Probe` and adds rows (group
``endpoints``, ``behavior_path`` or ``placing``; a violation ≥ 0, 0 when satisfied). A check
recomputes from the plan's arrays (the blade's states at the nodes, from pinocchio) and the
targets of :mod:`flipkit.behaviors.targets` and :mod:`flipkit.behaviors.serve`; it never
calls a constraint block's rows.
"""

from __future__ import annotations

import numpy as np

from flipkit.behaviors import serve as sv
from flipkit.behaviors import targets as tg
from flipkit.behaviors.approach import approach_limits, descent_node, slide_node
from flipkit.behaviors.options import SCOOP_PRESS, SCOOP_TIP_BAND
from flipkit.behaviors.probe import Probe, angle, outside
from flipkit.config.task import APPROACH_LOW
from flipkit.errors import FlipkitError
from flipkit.model.orientation import rpy


def starts_at_rest_and_ends_flat(p: Probe) -> None:
    """Translate (eq. 9): at rest at its start, the blade flat (o_x = o_y = 0) at its end."""
    N = p.seg.N
    p.add("endpoints", np.abs(p.seg.qd[0]), 0)
    p.add("endpoints", angle(rpy(p.states[N].R)[:2], 0.0), N)


def approach_tip(p: Probe) -> None:
    """Go to burger: the tip behind the burger's rim over the descent, then low and not past
    the scoop's start over the slide (:mod:`flipkit.behaviors.approach`)."""
    N, hg, frame = p.seg.N, p.cell.grill.height, p.task.frame()
    rim, start = approach_limits(p.cell, p.location)
    for i in range(descent_node(N), N + 1):
        tip = frame.point(p.tip(i))  # x along the scoop heading
        if i < slide_node(N):
            p.add("behavior_path", [max(tip[0] - rim, 0.0)], i)
        else:
            p.add("behavior_path", [max(tip[0] - start, 0.0),
                                    max(tip[2] - hg - APPROACH_LOW, 0.0)], i)


def scoop_tip(p: Probe) -> None:
    """Scoop (eq. 24): the tip pressed SCOOP_PRESS into the grill, within ±SCOOP_TIP_BAND."""
    hg = p.cell.grill.height
    for i in range(p.seg.N + 1):
        p.add("behavior_path", outside(p.tip(i)[2], hg - SCOOP_PRESS - SCOOP_TIP_BAND,
                                       hg - SCOOP_PRESS + SCOOP_TIP_BAND), i)


def flip_end_set(p: Probe) -> None:
    """Flip (eq. 26): the blade's normal and height at the end, its x axis on every node,
    seen along the scoop heading."""
    N, hg, end, frame = p.seg.N, p.cell.grill.height, p.states[-1], p.task.frame()
    p.add("behavior_path", outside(frame.rotation(end.R)[:, 2], *tg.FLIP_NORMAL_BOUNDS), N)
    lo, hi = tg.FLIP_HEIGHT_BAND
    p.add("behavior_path", outside(end.p[2], hg + lo, hg + hi), N)
    for i, st in enumerate(p.states):
        p.add("behavior_path", outside(frame.rotation(st.R)[:, 0], *tg.FLIP_XAXIS_BOUNDS), i)


def table_spot(p: Probe):
    """The recorded table spot (x, y) (m) if it lies on the table; else one failing
    ``placing`` row and ``None``."""
    spot = None if p.seg.placing is None else np.asarray(p.seg.placing["spot"])
    try:
        if spot is not None:
            return tg.check_table_spot(p.cell, spot)
    except FlipkitError:
        pass
    p.add("placing", [np.inf], p.seg.N, 1e-3)
    return None


def placing_recorded(p: Probe) -> None:
    """Carry: it records a table spot on the table."""
    table_spot(p)


def place_pivot_and_rest(p: Probe) -> None:
    """Place: a spot on the table; the tip at its final point ± PIVOT_BAND from node
    ⌈0.7 N⌉ on (the tilt pivots about it); the rest point predicted from the end pose (FK)
    within 1 mm of the spot (:func:`~flipkit.behaviors.serve.predicted_rest`)."""
    spot = table_spot(p)
    if spot is None:
        return
    N, on_blade = p.seg.N, np.asarray(p.seg.placing["on_blade"])
    target = sv.place_end(p.cell, spot, on_blade)
    tip = sv.tip_point(p.cell, target)
    for i in sv.pivot_nodes(N):
        p.add("behavior_path", np.maximum(np.abs(p.tip(i) - tip) - sv.PIVOT_BAND, 0.0), i)
    end = p.states[-1]
    rest = sv.predicted_rest(p.cell, end.p, rpy(end.R)[2], on_blade)
    p.add("placing", [np.linalg.norm(rest - spot)], N, 1e-3)


def withdrawal(p: Probe) -> None:
    """Return home: over its first WITHDRAW_NODES nodes the blade slides back in its start
    frame within the bands, its attitude within WITHDRAW_ANGLE_BAND of the start's."""
    R0, p0 = p.states[0].R, p.states[0].p
    lo, hi = sv.withdraw_bounds(p.seg.N)
    o0 = rpy(R0)
    for row, i in enumerate(range(1, sv.WITHDRAW_NODES + 1)):
        st = p.states[i]
        p.add("behavior_path", outside(R0.T @ (st.p - p0), lo[row], hi[row]), i)
        p.add("behavior_path", np.maximum(angle(rpy(st.R), o0) - sv.WITHDRAW_ANGLE_BAND, 0.0), i)
