"""A modelled stream's motions placed at their burgers and turned to a clear heading
(flipkit.planning.kitchen.reach)."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from flipkit.behaviors.targets import default_heading
from flipkit.config import CellConfig
from flipkit.planning.kitchen.cook import CookBurger
from flipkit.planning.kitchen.reach import blocked_burgers, placed, to_task_frame
from flipkit.planning.kitchen.sweep import Footprint, meetings, Lying

CELL = CellConfig()
R = CELL.burger.diameter / 2


def square(cx, cy, half):
    return np.array([[cx - half, cy - half], [cx + half, cy - half], [cx + half, cy + half],
                     [cx - half, cy + half]])


def test_placing_undoes_the_task_frame_and_moves_with_the_burger():
    fp = Footprint(blade=[(0.5, "scoop", square(0.60, -0.20, 0.02))],
                   carried=[(0.6, "scoop", (0.70, -0.20), (0.72, -0.19))],
                   landing=(2.0, (0.70, -0.20), R + 0.01))
    pb, psi = (0.70, -0.20), -0.3
    task = to_task_frame(fp, pb, psi)
    back = placed(task, pb, psi)
    assert np.allclose(back.blade[0][2], fp.blade[0][2])
    assert np.allclose(back.carried[0][2:], fp.carried[0][2:])
    assert np.allclose(back.landing[1], fp.landing[1]) and back.landing[2] == fp.landing[2]
    # in the task frame the burger is at the origin and the blade 10 cm behind it along -x
    c = task.blade[0][2].mean(axis=0)
    assert np.allclose(c, [-0.10 * math.cos(psi), 0.10 * math.sin(psi)], atol=1e-12)
    assert np.allclose(task.landing[1], (0.0, 0.0))
    # placed at another burger with another heading: the blade 10 cm behind it along that
    other = placed(task, (0.80, 0.0), 0.4)
    rot = np.array([[math.cos(0.4), -math.sin(0.4)], [math.sin(0.4), math.cos(0.4)]])
    assert np.allclose(other.blade[0][2].mean(axis=0), np.array([0.80, 0.0]) + rot @ c)
    assert np.allclose(other.landing[1], (0.80, 0.0))


def timeline(b2_xy, lying_xy):
    """b2 flipped at 100 s; the burgers of ``lying_xy`` dropped before, never flipped."""
    mk = SimpleNamespace
    burgers = [mk(burger=CookBurger("b2", 10.0, *b2_xy), landing=tuple(b2_xy))]
    burgers += [mk(burger=CookBurger(f"o{k}", 0.0, *xy), landing=None)
                for k, xy in enumerate(lying_xy)]
    motions = [mk(kind="flip", burger="b2", key="flip:b2", start=100.0, end=103.0,
                  event=102.0, ok=True, plan=None)]
    return mk(burgers=burgers, motions=motions, ok=True)


def test_a_flip_is_blocked_only_when_no_heading_keeps_clear():
    """A blade 25 cm behind the burger (in its task frame) meets a burger lying straight
    behind along the radial heading, but a turn within 30° clears it: not blocked. A
    footprint that covers everything within 30 cm meets it at every heading: blocked."""
    b2 = (0.75, -0.20)
    psi0 = default_heading(CELL, (*b2, 0.0))
    behind = (b2[0] - 0.25 * math.cos(psi0), b2[1] - 0.25 * math.sin(psi0))
    narrow = {"flip": Footprint(blade=[(1.0, "scoop", square(-0.25, 0.0, 0.02))])}
    lie = [Lying("o0", behind, 0.0, 1e9)]
    assert meetings(placed(narrow["flip"], b2, psi0), "flip:b2", 100.0, lie, CELL)
    assert blocked_burgers(timeline(b2, [behind]), narrow, CELL) == []
    wide = {"flip": Footprint(blade=[(1.0, "scoop", square(0.0, 0.0, 0.30))])}
    (blocked,) = blocked_burgers(timeline(b2, [behind]), wide, CELL)
    assert (blocked.burger, blocked.kind, blocked.met) == ("b2", "flip", "o0")
    assert blocked.overlap_m == pytest.approx(R + 0.01) and "every scoop heading" in \
        blocked.describe()
    # nobody lying: nothing blocked; a burger lying only after the flip: nothing blocked
    assert blocked_burgers(timeline(b2, []), wide, CELL) == []


def test_a_landing_on_a_neighbour_blocks_at_every_heading():
    """The landing disc is where the burger was picked up whatever the heading: a
    neighbour within it blocks the flip."""
    b2 = (0.75, -0.20)
    fp = {"flip": Footprint(landing=(2.5, (0.0, 0.0), R + 0.02))}
    near = (b2[0], b2[1] + 2 * R + 0.02)  # inside R + 0.02 + R + 0.01
    far = (b2[0], b2[1] + 2 * R + 0.04)
    assert [b.burger for b in blocked_burgers(timeline(b2, [near]), fp, CELL)] == ["b2"]
    assert blocked_burgers(timeline(b2, [far]), fp, CELL) == []
