"""Physical parameters of the simulated cell (MuJoCo), each with its source or a stated range.

:class:`PhysicsConfig` holds the values one parameter set uses at every location;
:data:`PHYSICAL_RANGES` gives each one's plausible range for the sensitivity study, and
:func:`with_parameter` moves one of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from flipkit.config.checks import finite, positive
from flipkit.errors import ConfigError, InvalidChoiceError

if TYPE_CHECKING:  # the cell imports this module
    from flipkit.config.cell import BurgerConfig, CellConfig, SpatulaConfig


BLADE_FLEX = ("contact", "hinge")  # the simulated blade's flex (PhysicsConfig.blade_flex)
# How the simulated joint servo follows position commands (PhysicsConfig.servo_form)
SERVO_FORMS = ("pd_gravity", "model_based")


SERVOJ_LOOKAHEAD = (0.03, 0.2)  # s, servoj lookahead_time (URScript manual)
SERVOJ_LOOKAHEAD_DEFAULT = 0.1  # s, servoj's default lookahead_time (URScript manual)


def servo_lookahead(value, what: str = "servo_lookahead_s") -> float:
    """``value`` (s) as a servo lookahead: 0 (no smoothing) or within
    :data:`SERVOJ_LOOKAHEAD`; else a one-line ConfigError naming ``what``."""
    lo, hi = SERVOJ_LOOKAHEAD
    ok = isinstance(value, (int, float, np.floating)) and not isinstance(value, bool) and (
        value == 0.0 or (math.isfinite(value) and lo <= value <= hi))
    if not ok:
        raise ConfigError(f"{what} must be 0 (no smoothing) or a number in [{lo:g}, {hi:g}] s "
                          f"(servoj lookahead_time), got {value!r}")
    return float(value)


@dataclass(frozen=True)
class PhysicsConfig:
    """Simulation-only physics of the cell (MuJoCo scene, closed-loop execution).

    One parameter set serves every location; no value is tuned to make plans pass. Each
    value's source is stated beside it; where none was found a range is given and said so.
    The ranges swept by the sensitivity study are in :data:`PHYSICAL_RANGES`.

    Attributes:
        mu_grill: Burger-grill friction (meat on a steel grill plate). Same material pair and
            source as :attr:`BurgerConfig.mu` (foods on a test surface 0.04-0.52); the paper
            only says a cool grill makes burgers "sticky", which would raise it. 0.5; range
            0.2-1.0 stated as ours.
        burger_modulus: Young's modulus E of the patty (Pa). Grilled pork 28-147 kPa,
            grilled poultry 31-75 kPa (Hindawi J. Food Quality 2022, "Application of Food
            Mechanics and Oral Processing in Modelling First Bite of Grilled Meat", Table 4,
            https://www.hindawi.com/journals/jfq/2022/9176628/tab4/); no beef-patty modulus
            was found: 50 kPa, range 28-147 kPa.
        burger_edge_radius: Radius (m) of the patty's rounded rim (a hand-formed or pressed
            patty has no sharp edge). No source: 5 mm, range 1 mm to half the thickness.
        burger_dampratio: Damping ratio of the burger contacts (MuJoCo solref[1]) and of the
            patty's bending (its hinges, :mod:`flipkit.simulation.patty`); a patty does not
            bounce (no source: 1 = critically damped, range 0.7-2).
        burger_strips: How many hinged strips the simulated patty is made of (odd; 1 is a
            rigid disc). The patty bends under its own weight (:mod:`flipkit.simulation.patty`:
            Hencky's bar chain with the bending stiffness of ``burger_modulus``). A numerical
            setting, not a physical one: 5, where the Table I outcomes agree with 7 and 9
            strips.
        blade_thickness: Blade thickness (m). A stiff one-piece stainless turner is 0.04 in
            = 1 mm, 18 gauge (J. Kenji Lopez-Alt, "The Food Lab", equipment chapter); a thin
            plated-steel turner 0.45 mm (softsolder.com, "Kitchen Spatula Search", 2016);
            heavy griddle turners up to 2 mm (no source). 1 mm, range 0.45-2 mm.
        bevel_length: Length of the ground bevel on the underside of the leading edge (m).
            No source: 5 mm, range 2-10 mm.
        edge_thickness: Thickness left at the leading edge (m); "keen and sturdy front edge"
            (The Food Lab) gives no number: 0.2 mm, range 0.1-0.5 mm (ours).
        mu_blade_grill: Blade-grill friction, steel on steel. Dry, clean steel: static
            0.6-0.8, kinetic 0.4-0.6 (enersection.io, "Understanding the friction coefficient
            of steel on steel"); an oiled griddle is lower (no number found). 0.3, range
            0.1-0.6.
        blade_modulus: Young's modulus E of the blade's stainless steel (Pa). AISI 304:
            193 GPa (Alloys International, "Stainless Steel 304 Material Data Sheet",
            https://alloysintl.com/?p=6124; APAC Infrastructure, "Material Specifications -
            304 Stainless Steel"), 200 GPa (MakeItFrom, "AISI 304 Stainless Steel",
            http://www.makeitfrom.com/material-data/?for=AISI-304-SUS304-1.4301-S30400-
            Stainless-Steel). 193 GPa, range 193-200 GPa.
        blade_dampratio: Damping ratio of the blade's flex against the grill. Steel's own
            structural damping is far below 1 (a struck blade rings); the squeezed oil film
            and the burger residue on a griddle add an unknown amount. No source: 1
            (critically damped: a pressed blade does not chatter), range 0.3-2 (ours).
        blade_flex: How the simulated blade flexes (:mod:`flipkit.simulation.scene`, "Blade
            flex"): ``"hinge"`` (default), the blade on a hinge at its neck with the
            cantilever's tip stiffness, meeting the grill in a stiff contact (its tip stays
            on the surface, as a steel blade's does: it bends, it does not sink); ``"contact"``,
            a rigid blade whose penetration of a compliant blade-grill contact stands for the
            flex (the blade's faces then sink below the grill's surface by the deflection).
            A modelling choice, not a physical value.
        blade_tip_mass: Effective mass (kg) the blade tip presents along the grill normal,
            1/(J M⁻¹ Jᵀ) of the arm with its spatula at the tip, vertical row: measured on the
            scoops of the Table I plans 0.34-0.75 kg (the wrist's small inertia). 0.5 kg;
            it only sets the damping b = 2 ζ √(k m).
        timestep: MuJoCo integration step (s).
        servo_rate_hz: Rate at which the robot's controller receives desired (q, qd) in
            ``position`` mode (Hz). Real-time client interface: CB-series 125 Hz, e-Series
            500 Hz (Universal Robots, "Remote Control Via TCP/IP", https://www.universal-
            robots.com/articles/ur/interface-communication/remote-control-via-tcpip/).
            The paper's arm is unnamed: CB3 rate 125 Hz, range 125-500 Hz.
        latency_s: Delay (s) between a desired state and its arrival at the joint servo in
            ``position`` mode. One 125 Hz period of transport plus one of the controller's
            cycle is 16 ms. Measured on a UR10e streaming at 500 Hz, a target echoed back
            without ``servoj`` returned 4-6 ms later (UniversalRobots/
            Universal_Robots_Client_Library issue 86, cross-correlation); through ``servoj``
            with a lookahead time of 0.03 s, 34 ms: its smoothing, modelled apart
            (``servo_lookahead_s``). 8 ms, range 2-20 ms
            (ours, around the measured transport).
        kp, kd: Joint PD gains (N m/rad, N m s/rad), the values of
            :data:`flipkit.simulation.tracking.DEFAULT_KP` / ``DEFAULT_KD`` (about critical damping at
            q_home, stated there); UR does not publish its servo gains.
        servo_gain_scale: Factor on ``kp`` and ``kd`` of the simulated servo: the real gains
            are unknown, while the commands of :mod:`flipkit.planning.plans.servo_command` are
            computed with the nominal ones. 1; range 0.5-2 (no source: UR publishes none).
        servo_lookahead_s: Smoothing (s) of the ``position`` commands between their
            servo-rate samples and the joint PD: UR's ``servoj`` ``lookahead_time``
            ([0.03, 0.2] s, default 0.1 s, URScript manual; flipkit's URScript export sends
            the same), modelled as a first-order low-pass of that time constant (the form is
            ours; UR publishes none; its group delay matches the lag measured through
            ``servoj``). The cell sets it, so the
            compensated commands are made for it
            (:func:`flipkit.planning.plans.servo_command.lookahead_command`). 0: no
            smoothing, the held commands reach the PD as they are (no ``servoj`` does that).
        servo_form: How the joint servo follows the smoothed commands in ``position`` mode,
            one of :data:`SERVO_FORMS`: ``"pd_gravity"``, the PD above plus the gravity of
            its model (arm and spatula); ``"model_based"``, the inverse dynamics of that model
            driving each joint to the smoothed command, its acceleration fed forward and the
            error closed at ``servo_bandwidth`` (critically damped), as a controller that
            carries the arm's dynamic model does (UR's controller is told the payload's mass
            and centre of gravity for that model). UR publishes neither form: the
            sensitivity study runs both.
        servo_bandwidth: The ``model_based`` servo's natural frequency (rad/s): 30, range
            15-60 (ours: a joint position loop of a few hertz; UR publishes none).
    """

    mu_grill: float = 0.5
    burger_modulus: float = 50e3
    burger_edge_radius: float = 0.005
    burger_dampratio: float = 1.0
    burger_strips: int = 5
    blade_thickness: float = 0.001
    bevel_length: float = 0.005
    edge_thickness: float = 0.0002
    mu_blade_grill: float = 0.3
    blade_modulus: float = 193e9
    blade_dampratio: float = 1.0
    blade_tip_mass: float = 0.5
    blade_flex: str = "hinge"
    timestep: float = 0.0005
    servo_rate_hz: float = 125.0
    latency_s: float = 0.008
    kp: tuple = (2000.0, 2000.0, 1000.0, 300.0, 300.0, 50.0)
    kd: tuple = (120.0, 160.0, 90.0, 6.0, 6.0, 0.4)
    servo_gain_scale: float = 1.0
    servo_lookahead_s: float = SERVOJ_LOOKAHEAD_DEFAULT
    servo_form: str = "pd_gravity"
    servo_bandwidth: float = 30.0

    def __post_init__(self):
        for name in ("mu_grill", "burger_modulus", "burger_edge_radius", "burger_dampratio", "blade_thickness",
                     "bevel_length", "edge_thickness", "mu_blade_grill", "blade_modulus",
                     "blade_dampratio", "blade_tip_mass",
                     "timestep", "servo_rate_hz", "servo_gain_scale", "servo_bandwidth"):
            positive(f"physics {name}", getattr(self, name))
        n = self.burger_strips
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1 or n % 2 == 0:
            raise ConfigError(f"physics burger_strips must be an odd integer >= 1 (1: a rigid "
                              f"disc), got {n!r}")
        if self.blade_flex not in BLADE_FLEX:
            raise InvalidChoiceError("physics blade_flex", self.blade_flex, BLADE_FLEX)
        if self.servo_form not in SERVO_FORMS:
            raise InvalidChoiceError("physics servo_form", self.servo_form, SERVO_FORMS)
        for name in ("latency_s", "servo_lookahead_s"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float, np.floating)) and math.isfinite(value)
                    and value >= 0):
                raise ConfigError(f"physics {name} must be >= 0 s, got {value!r}")
        if self.edge_thickness >= self.blade_thickness:
            raise ConfigError("physics edge_thickness must be below blade_thickness, got "
                              f"{self.edge_thickness} >= {self.blade_thickness}")
        for name in ("kp", "kd"):
            g = finite(f"physics {name}", getattr(self, name))
            if g.ndim != 1 or np.any(g < 0):
                raise ConfigError(f"physics {name} must be non-negative gains, got {g}")

    def blade_stiffness(self, spatula: "SpatulaConfig") -> float:
        """Stiffness (N/m) of the blade tip against the grill: the blade's flex.

        A turner's blade is a thin steel plate cantilevered from the neck (where it joins the
        handle, the blade's back edge x = −l/2) to the tip (x = +l/2), so the cantilever
        length L is the blade length ``spatula.length``; a force at the tip meets
        k = 3 E I / L³ with I = w t³ / 12 (w ``spatula.width``, t :attr:`blade_thickness`).
        Default 1 mm × 12 cm × 16 cm blade: k = 1.41 kN/m (3 mm of press: 4.2 N). In series
        with it, the grill plate's steel (Hertzian, MN/m) and the handle (a 16 mm steel rod
        over the 12 cm from the flange to the neck, loaded at the tip 16 cm further:
        ≈ 100 kN/m) add about 1 % of compliance and are left out.
        """
        inertia = spatula.width * self.blade_thickness**3 / 12
        return 3 * self.blade_modulus * inertia / spatula.length**3

    def blade_damping(self, spatula: "SpatulaConfig") -> float:
        """Damping (N s/m) of the blade-tip contact: b = 2 ζ √(k m) with ζ
        :attr:`blade_dampratio`, k :meth:`blade_stiffness`, m :attr:`blade_tip_mass`."""
        return 2 * self.blade_dampratio * math.sqrt(self.blade_stiffness(spatula)
                                                    * self.blade_tip_mass)

    def burger_timeconst(self, burger: "BurgerConfig", mass: float | None = None) -> float:
        """MuJoCo solref time constant (s) of the burger's contacts, from the patty stiffness.

        The patty compressed through its thickness is a spring k = E A / h (N/m), A its face
        area; carrying mass m it has the natural frequency ω = √(k/m), and MuJoCo's
        reference spring with time constant τ and damping ratio 1 has ω = 1/τ. So
        τ = √(m h / (E A)), clipped below at 2 timesteps (MuJoCo's stability floor).
        Default patty: k = 26 kN/m, τ = 2.1 ms.
        """
        m = burger.mass if mass is None else float(mass)
        tau = math.sqrt(m * burger.thickness / (self.burger_modulus * burger.area))
        return max(tau, 2 * self.timestep)


# PhysicsConfig fields that no plan depends on: numerical settings of the simulation, how the
# simulated servo treats its commands and how the simulated blade flexes (the atlas's staleness
# hash leaves them out)
SIMULATION_ONLY = ("burger_strips", "servo_lookahead_s", "blade_flex", "servo_form",
                   "servo_bandwidth")

_NO_SOURCE = "no source found; range ours"
PHYSICAL_RANGES = {  # dotted CellConfig name -> (lo, hi, source); swept one at a time
    "burger.diameter": (0.089, 0.127, "3.5-5 in: The Donut Whole / Kitchen Wisdom (BurgerConfig)"),
    "burger.thickness": (0.010, 0.019, "19 mm raw (3/4 in, same sources); lower end " + _NO_SOURCE),
    "burger.mass": (0.085, 0.1134, "quarter pound raw 113.4 g; cooked -15..25 % (BurgerConfig)"),
    "burger.mu": (0.2, 0.8, "foods on a test surface 0.04-0.52 (J. Texture Studies); "
                  + _NO_SOURCE + " for meat on stainless"),
    "physics.mu_grill": (0.2, 1.0, "as burger.mu; sticky patty (paper) raises it; " + _NO_SOURCE),
    "physics.burger_modulus": (28e3, 147e3, "grilled pork/poultry E (Hindawi JFQ 2022, Table 4)"),
    "physics.burger_edge_radius": (0.001, 0.0075, _NO_SOURCE + " (up to half the thickness)"),
    "physics.burger_dampratio": (0.7, 2.0, _NO_SOURCE),
    "physics.blade_thickness": (0.00045, 0.002, "1 mm (The Food Lab), 0.45 mm (softsolder.com); "
                                "2 mm " + _NO_SOURCE),
    "physics.bevel_length": (0.002, 0.010, _NO_SOURCE),
    "physics.edge_thickness": (0.0001, 0.0005, _NO_SOURCE),
    "physics.mu_blade_grill": (0.1, 0.6, "dry steel-steel kinetic 0.4-0.6 (enersection.io); "
                               "oiled " + _NO_SOURCE),
    "physics.blade_modulus": (193e9, 200e9, "AISI 304 stainless: 193 GPa (alloysintl.com, "
                              "apacinfrastructure.com.au), 200 GPa (makeitfrom.com)"),
    "physics.blade_dampratio": (0.3, 2.0, _NO_SOURCE),
    "physics.blade_tip_mass": (0.34, 0.75, "measured: arm's 1/(J M^-1 J^T) at the blade tip "
                               "over the Table I scoops"),
    "physics.servo_rate_hz": (125.0, 500.0, "UR CB-series 125 Hz, e-Series 500 Hz "
                              "(UR 'Remote Control Via TCP/IP')"),
    "physics.servo_gain_scale": (0.5, 2.0, _NO_SOURCE + " (UR publishes no servo gains)"),
    "physics.servo_lookahead_s": (*SERVOJ_LOOKAHEAD, "servoj lookahead_time 0.03-0.2 s (URScript "
                                  "manual; default 0.1 s, as flipkit's export); its smoothing's form ours"),
    "physics.latency_s": (0.002, 0.020, "UR10e at 500 Hz: 4-6 ms from sent to reported, "
                          "without servoj's smoothing (Universal_Robots_Client_Library issue "
                          "86); range ours around it"),
}
"""Plausible range (lo, hi) of each physical parameter, with its source text: the values a
sensitivity study sweeps one at a time (see :func:`with_parameter`)."""


KNOWN_PARAMETERS = ("burger.diameter", "physics.blade_thickness", "physics.bevel_length",
                    "physics.edge_thickness", "physics.servo_rate_hz", "physics.servo_lookahead_s")
"""The parameters of :data:`PHYSICAL_RANGES` that a cell knows: it chose its spatula (the
blade's geometry) and its robot controller (the servo rate: a CB-series arm streams at
125 Hz, an e-Series at 500 Hz; the ``servoj`` lookahead it sends), and it sees the burger's
diameter with the camera that locates the burger (a patty's outline gives its place and its
size alike; ``flipkit plan flip --burger-diameter``). The others it cannot measure: the
burger's thickness, mass and stiffness, the frictions, the contact damping, the servo's gains
and latency. A plan is made for what the cell knows. The planner models the blade as its top
face with a 3 mm collision box (``spatula.thickness``, an envelope of the blade's thickness
range); the blade's thickness enters a plan through the scoop model only (how high the blade
can lift the patty's overhang). The burger's diameter and the blade's thickness change the
plans (:data:`PLANNED_PARAMETERS`); the servo rate and the lookahead change the position
commands (:func:`known_physics`)."""

PLANNED_PARAMETERS = ("burger.diameter", "physics.blade_thickness")
"""The known parameters that change a plan: the burger's diameter (its friction cone's
footprint, the scoop's overlap, the landing) and the blade's thickness (the scoop model's
overhang, :func:`flipkit.model.scoop.overhang_share`). A study that moves one plans again for
each value (:func:`flipkit.experiments.sensitivity.run_sensitivity`'s ``replanned``)."""


def known_physics(physics: PhysicsConfig, values: dict) -> PhysicsConfig:
    """The cell's model of its own physics, as the commands use it: ``physics`` with the
    known ``physics.*`` parameters among ``values`` (``{dotted name: value}``, keys of
    :data:`PHYSICAL_RANGES`) set; every other entry is left at ``physics``'s value.

    Raises:
        InvalidChoiceError: A key that is not a parameter of :data:`PHYSICAL_RANGES`.
    """
    for name in values:
        if name not in PHYSICAL_RANGES:
            raise InvalidChoiceError("physical parameter", name, PHYSICAL_RANGES)
    known = {name.split(".")[1]: float(v) for name, v in values.items()
             if name in KNOWN_PARAMETERS and name.startswith("physics.")}
    return replace(physics, **known) if known else physics


def with_parameter(cell: "CellConfig", name: str, value: float) -> "CellConfig":
    """``cell`` with one dotted parameter (a key of :data:`PHYSICAL_RANGES`) replaced."""
    if name not in PHYSICAL_RANGES:
        raise InvalidChoiceError("physical parameter", name, PHYSICAL_RANGES)
    group, attr = name.split(".")
    return replace(cell, **{group: replace(getattr(cell, group), **{attr: float(value)})})
