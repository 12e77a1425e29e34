"""The task's choices: what the subbehaviours aim at, and the margins they keep (SI units).

Each constant names its source: an equation of the paper (Kolathaya et al., RA-L 2018,
Sec. IV.C) where it gives the value, or a stated choice of flipkit's with its reason where
the paper is silent. The behaviour layer (:mod:`flipkit.behaviors`) reads them from here.
"""

from __future__ import annotations

from flipkit.config.physics import PHYSICAL_RANGES
from flipkit.config.uncertainty import ScoopUncertainty

# --- the paper's targets, eqs. (22)–(26) -----------------------------------------------------
SCOOP_PITCH = 0.314  # rad, o_y* of the blade going to the burger, eq. (22)
PICKUP_OFFSET = (0.02, 0.0, 0.05)  # m, the pickup's end from p^b, eq. (25)
PICKUP_PITCH = -0.05  # rad, the pickup's end tipped back, eq. (25)
FLIP_CONE_FRACTION = 0.6  # the flip's cone on nodes i <= 0.6 N, eq. (26)
FLIP_NORMAL_BOUNDS = ((-0.5, -0.5, -1.0), (0.0, 0.5, -0.8))  # F_n(q_N), eq. (26)
FLIP_XAXIS_BOUNDS = ((0.6, -1.0, -1.0), (1.0, 1.0, 1.0))  # R(q_i) x̂, eq. (26)
FLIP_HEIGHT_BAND = (0.1, 0.4)  # m, h_g + band on p_z(q_N), eq. (26)

# --- the scoop (flipkit's choices; the paper's eq. 24 keeps the tip on the grill) -------------
# The blade's tip is pressed this far into the grill: the grill's contact absorbs it, the
# arm's PD presses the blade onto the grill, and a grill up to this much lower than modelled
# still meets the tip.
SCOOP_PRESS = 0.003  # m
SCOOP_TIP_BAND = 0.0005  # m, the tip's band about h_g − SCOOP_PRESS: never above h_g + 0.5 mm
# The tip comes down this far before the burger's near edge (the paper: at it, eq. 23): three
# standard deviations of the burger's placement (5 mm, the Table I trials' placement error),
# so that the blade does not land on the burger's rim.
SCOOP_START_MARGIN = 0.015  # m
# The go to burger's approach (flipkit.behaviors.approach): the blade's corners stay
# APPROACH_CLEARANCE above the tallest burger of the sourced range until its last
# APPROACH_FRACTION of node intervals (the descent). Over the descent the tip stays behind the
# near rim of the largest burger of the range put 2 placement standard deviations toward the
# arm, and over the last APPROACH_SLIDE_FRACTION (the slide) it is pressed into the grill, as
# the scoop is, and at most APPROACH_LOW above it: it meets any burger at its foot and pushes
# it along the grill instead of coming down on its rim. Ours.
APPROACH_FRACTION = 0.2
APPROACH_SLIDE_FRACTION = 0.1
APPROACH_CLEARANCE = 0.005  # m
APPROACH_LOW = 0.005  # m
# The scoop heading ψ (flipkit.model.task_frame) lies within this of the world's +x: the
# flip's end set (eq. 26) keeps the blade's x axis pointing away from the arm, and the grill's
# area is seen from the base within −40° to +15°. Ours.
HEADING_LIMIT = 1.0471975511965976  # rad (60°)
# rad, turns of the default scoop heading that a cook tries and the atlas holds: 15° moves a
# scoop's blade corners 2-4 cm sideways over its 15-20 cm; 30° keeps every burger on the
# grill within HEADING_LIMIT of +x for at least one side.
HEADING_STEPS = (0.2617993877991494, 0.5235987755982988)  # (15°, 30°)
SCOOP_LATERAL_BAND = 0.01  # m, |p_y − p^b_y| during the scoop: slide straight under it
SCOOP_ANGLE_BAND = 0.05  # rad, |o_x|, |o_z| during the scoop: no yaw or roll that pushes it

# --- the flip's landing (flipkit's release, flight and landing) ------------------------------
RELEASE_FRACTION = 0.7  # release node r = ceil(0.7 N): contact on 70 % of the flip
# The nominal landing aims within R_LAND of the spot, which leaves the whole of the paper's
# 5 cm success square for what the plan cannot know.
R_LAND = 0.005  # m
# The landing radii accepted (plan flip --r-land, SegmentOptions, verify). The landing point
# is predicted by the NLP's flight rows and recomputed by verify's ODE to within 0.1 mm of it
# (verify_flight.LANDING_TOL): a disc smaller than that spread can be neither planned to nor
# checked (the solvers then fail after long solves; docs/history.md). Above 0.1 m the disc is
# wider than the burger's own diameter and the paper's success square.
R_LAND_RANGE = (1e-4, 0.1)  # m
# Every scenario of the burger's place on the blade lands within R_SCENARIO: 1 cm inside the
# paper's success square (5 cm in x and y), which holds the disc.
R_SCENARIO = 0.04  # m
FLIGHT_MARGIN = 0.002  # m, the blade plane below the flying burger from node r + 2 on
# The burger lands flat: its top face's normal at least TILT_MIN_DEG from +z (within 5° of
# upside down). A burger that lands tilted slaps down rim first and slides; one that lands
# flat stops where it touches (its sideways speed is inside the grill's friction cone): in the
# simulated cell a patty landing within a few degrees of flat barely slides, one landing at
# 10° can slide several centimetres. A real patty bends about every axis, so the bound holds
# the whole tilt. Ours, from those simulations (docs/history.md, "Measurements behind the
# code's choices").
TILT_MIN_DEG = 175.0
# The cones of the segments that carry the burger (pickup, flip, translate, carry, place) are
# planned for the least sticky burger the cell may meet, since it cannot measure μ: the low
# end of the sourced burger–blade range (PHYSICAL_RANGES["burger.mu"], 0.2) times the low end
# of the per-burger spread (ScoopUncertainty.mu_scale, × 0.8): 0.16. A cone planned at the
# nominal μ is active, and a less sticky burger then slides off (the sensitivity study's
# flips planned at the nominal μ fail with the least sticky burger; docs/history.md).
MU_PLAN = PHYSICAL_RANGES["burger.mu"][0] * ScoopUncertainty().mu_scale[0]
# The scoop's cone only limits how hard the blade brakes under the burger (what any burger
# does on the blade is the scoop model's, with its scenarios): nominal μ × MU_SAFETY.
MU_SAFETY = 0.8
# A decisive release: one node before the release node the contact still presses the burger
# onto the blade with this specific force (m/s²) at its predicted place and at every
# scenario's, and at the release node the normal force at the predicted place is zero, so the
# burger leaves the blade at that node, where the flight model starts it. The force falls
# from ≥ 3 m/s² to zero over the last node interval (≥ 67 m/s³ for a flip of up to 0.9 s):
# an error of 1 m/s² in the specific force, or a burger a little off its place, moves the
# release by less than a third of an interval (15 ms), well inside the 10 % of the flip
# between the release node (70 %) and the paper's contact criterion (60 %). Ours: 3 m/s²
# ≈ 0.3 g.
RELEASE_PRESS = 3.0

# --- segment ends and durations ---------------------------------------------------------------
# A moving segment end keeps the stopping distance at this share of q̈_max: the next segment's
# polynomial motion cannot realise a bang-bang stop at the full limit.
BRAKING_FRACTION = 0.5
# A segment infeasible within its duration bound is planned once more with the upper bound
# stretched by this factor: the bounds are a preference for a fast chain, not a physical
# limit (the joint limits, dynamics and cone are).
T_STRETCH = 1.5

# --- clearance of the tool end (see flipkit.behaviors.clearance) ------------------------------
FLIP_TOOL_FRACTION = 0.25  # the flip and carry hold the tool end to the margin from 0.25 N on
FLIP_END_ALLOWANCE = 0.03  # m, ≈ 0.9 m/s × the turn back's first node (0.06 s) / 2

# --- serving at the side table (see flipkit.behaviors.serve) ----------------------------------
PLACE_PITCH = 0.70  # rad, tip down at the place's end: tan 0.70 = 0.84 > μ's range 0.2–0.8
PLACE_TIP_GAP = 0.005  # m, the blade tip above the table at the place's end
PLACE_CONE_FRACTION = 0.7  # the cone holds on place nodes i ≤ 0.7 N
PIVOT_BAND = 0.003  # m, the tip within this of its final point while the blade tilts about it
CARRY_CLEARANCE = 0.06  # m, the carry ends with the blade centre this far above the place pose
WITHDRAW_NODES = 8  # return home's nodes 1..8 withdraw the blade in its own plane
WITHDRAW_DISTANCE = 0.14  # m, back along −x of the blade by node 8: l − 2 cm of overlap
BURGER_CLEARANCE = 0.01  # m, the blade's edges above the placed burger's top after withdrawing
WITHDRAW_BAND = 0.005  # m, off the blade's start plane / start line while withdrawing
WITHDRAW_ANGLE_BAND = 0.05  # rad, rpy about the place end's while withdrawing
