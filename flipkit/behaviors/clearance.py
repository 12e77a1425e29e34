"""Which pairs of the arm's shapes and the cell's boxes each subbehaviour holds to the space
margin (the space limits; paper Sec. I: "operate within the boundaries of the walls and
grill"), and why the tool end is exempt where it works."""

from __future__ import annotations

from flipkit.config.task import FLIP_END_ALLOWANCE, FLIP_TOOL_FRACTION  # noqa: F401

# Space limits (paper Sec. I: "operate within the boundaries of the walls and grill"):
# every shape of the arm keeps cell.space.margin from every box of the cell, except the tool end
# and the grill while the tool works on the grill. Going to the burger ends with the blade's tip
# pressed into the grill, the scoop slides it pressed in and the pickup lifts it from there
# (SCOOP_PRESS), and the handle is straight, on the flange's axis: with the blade flat on the
# grill and the flange over it (burgers at x ≥ 0.78 m), the flange and wrist-2 housings reach
# below the grill's surface (by centimetres). There the
# blade's own floor is grill_clearance (its edges' heights); the other links keep the margin.
# The flip starts where the pickup ends (eq. 25: 5 cm above the grill, where the flange's
# housing can still lie 1 cm inside the grill's box), so it holds the tool end to the margin
# from node FLIP_TOOL_FRACTION·N on: it lifts the tool end clear in its first quarter. It ends
# FLIP_END_ALLOWANCE farther from the cell than the margin: the turn back starts with the
# flip's end velocity and needs room to turn the arm away: a flip ending on the margin with
# the flange coming down leaves no turn back that keeps it. The allowance is sized for
# ~0.9 m/s: flips at the grill's far half (x ≥ 0.74 m, y ≤ 0.02 m) end on it with the wrist
# housings coming down faster, 1.2 m/s, and no turn back keeps the margin at its first node
# even braking at the 20 rad/s² limit. So the flip also holds the configuration it would reach coasting for
# the turn back's first node interval, q_N + (T_max/N) q̇_N, to the margin
# (the spec's ``coast_into``, CoastingClearance): the turn back then keeps the margin at node 1
# without braking, and brakes clear after it (needs ≥ v/(2τ) ≈ 10 m/s² at 1.2 m/s).
# The serve's carry starts at the same pickup end as the flip and lifts the tool end clear in
# its first quarter the same way: the pickup can end with wrist 2 inside the grill's box, and
# a carry held to the margin from node 1 is infeasible.
# Serving: the place puts the blade's tip 5 mm above the table and tilts it tip down, and the
# return home first withdraws the blade along its own plane: the tool end works on the table
# there as it works on the grill above, so the same tool shapes are exempt from the table (the
# blade's height over the table is the place's own pivot constraint).
TOOL_SHAPES = ("blade", "handle", "ee", "wrist_3", "wrist_2")  # ee: the URDF's ee_link box
_TOOL_AT_GRILL = frozenset((s, "grill") for s in TOOL_SHAPES)
_TOOL_AT_TABLE = frozenset((s, "table") for s in TOOL_SHAPES)


def tool_at_grill(node: int, N: int) -> frozenset:
    """Go to burger, scoop, pickup: the tool end works on the grill at every node."""
    return _TOOL_AT_GRILL


def tool_leaves_grill(node: int, N: int) -> frozenset:
    """Flip, carry: they start where the pickup ends; the tool end is exempt from the grill
    until node FLIP_TOOL_FRACTION · N."""
    return _TOOL_AT_GRILL if node < FLIP_TOOL_FRACTION * N else frozenset()


def tool_at_table(node: int, N: int) -> frozenset:
    """Place, return home: the tool end works on the table."""
    return _TOOL_AT_TABLE
