"""Translate (9): carry the burger on a flat spatula to a goal pose, cone on every node, at
rest at both ends."""

from __future__ import annotations

from flipkit.behaviors.checks import starts_at_rest_and_ends_flat
from flipkit.behaviors.guesses import end_pose_guess
from flipkit.behaviors.spec import Behavior, Subbehavior

TRANSLATE = Subbehavior(
    "translate", duration=(0.6, 2.0), carries_burger=True, end="rest", needs=("goal",),
    end_pose=lambda ctx: ctx.task.goal, cone=lambda ctx: list(range(ctx.layout.n_nodes)),
    guess=end_pose_guess, role="goal", records=("goal",),
    checks=(starts_at_rest_and_ends_flat,), doc="eq. (9)")
# One segment, planned once: its bound is the user's to set (no stretched second attempt).
TRANSLATE_BEHAVIOR = Behavior("translate", (TRANSLATE,), stretch=False, open_ended=True)
