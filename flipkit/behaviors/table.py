"""Carry, place and return home: the serve's subbehaviours at the side table, and the serve
behaviour (go to burger, scoop, pickup, then these three).

The geometry (where the blade ends, where the burger comes to rest, why a tilt-off) is
:mod:`flipkit.behaviors.serve`; ``docs/adding-a-behaviour.md`` walks through these specs.
"""

from __future__ import annotations

from functools import partial

from flipkit.behaviors import serve as sv
from flipkit.behaviors.checks import place_pivot_and_rest, placing_recorded, withdrawal
from flipkit.behaviors.clearance import tool_at_table, tool_leaves_grill
from flipkit.behaviors.guesses import return_home_guess, task_path_guess
from flipkit.behaviors.pick import GO_TO_BURGER, PICKUP, SCOOP
from flipkit.behaviors.spec import Behavior, Subbehavior, Task


def record_placing(segment, task: Task, models) -> None:
    """The carry and place record where they put the burger (``segment.placing``)."""
    segment.placing = sv.placing_record(models.cell, task.spot, task.blade_point())


def place_cone(ctx) -> list[int]:
    """The burger rides the descent: the cone on nodes i ≤ PLACE_CONE_FRACTION · N."""
    return [i for i in range(ctx.layout.n_nodes)
            if i <= sv.PLACE_CONE_FRACTION * ctx.layout.N + 1e-9]


_to_table = partial(task_path_guess, joint_fallback=True)  # a straight carry may pass the base

# The carry holds the burger in the cone planned for the least sticky burger (μ 0.16,
# docs/robust-flips.md §2), the blade tilting into its acceleration. 1.2 s is enough for the
# table's spots within reach; a farther spot (about 1.4 m) gets the stretched bound, and a
# shorter bound would send most serves to it.
CARRY = Subbehavior(
    "carry", duration=(0.6, 1.2), carries_burger=True, end="rest", needs=("spot",),
    floor=sv.table_floor, exempt=tool_leaves_grill,
    end_pose=lambda ctx: sv.carry_end(ctx.cell, ctx.task.spot, ctx.task.blade_point()),
    cone=lambda ctx: list(range(ctx.layout.n_nodes)), cone_on_blade=True, guess=_to_table,
    record=record_placing, role="carry", records=("placing",), checks=(placing_recorded,),
    doc="to above the place pose, flat, cone on every node")
# The tilt-off holds the burger in the cone planned for the least sticky burger (μ 0.16,
# docs/robust-flips.md §2); within 0.8 s it has no solution, and every serve would spend an
# SQP and an IPOPT solve before its bound was stretched, so the bound is 1.2 s.
PLACE = Subbehavior(
    "place", duration=(0.3, 1.2), carries_burger=True, end="rest", needs=("spot",),
    floor=sv.table_floor, exempt=tool_at_table, path=sv.place_pivot,
    end_pose=lambda ctx: sv.place_end(ctx.cell, ctx.task.spot, ctx.task.blade_point()),
    cone=place_cone, cone_on_blade=True, guess=_to_table, record=record_placing,
    role="place", records=("placing",), checks=(place_pivot_and_rest,),
    doc="tilt-off about the tip, just above the table")
# The return unrolls the heading back to q_home's. It solves within 1.2 s too, but its faster
# withdrawal pushes the burger just placed into the one beside it on the table, so its bound
# is 1.5 s.
RETURN_HOME = Subbehavior(
    "return_home", duration=(0.5, 1.5), carries_burger=False, end="home",
    floor=sv.withdrawn_floor, exempt=tool_at_table, path=sv.withdrawal,
    guess=return_home_guess, role="home", checks=(withdrawal,),
    doc="withdraw the blade in its plane, then home")
# The burger is sensed on the blade at the carry's end, before the place that depends on
# where it lies; a re-plan solves the place and return home again.
SERVE = Behavior("serve", (GO_TO_BURGER, SCOOP, PICKUP, CARRY, PLACE, RETURN_HOME),
                 sensed="carry", replanned="place")
