"""The simulated patty: hinged strips, a plate that bends under its own weight.

A patty is stiff through its thickness but not in bending. Held as a cantilever, a 15 mm
patty of E = 50 kPa (:attr:`~flipkit.config.PhysicsConfig.burger_modulus`) droops
q L⁴ / (8 E I) ≈ 5 mm over 5 cm (q its weight per length), five times the blade's
thickness. So when the blade's tip lifts the rim, a rigid disc would pivot on its far rim
and put half its weight on the blade, and the blade's friction would drag it along whenever
the burger–blade friction exceeds the grill's. A real patty lifts only a strip near the rim
(a heavy beam lifted by δ = 1 mm at its end, its curvature continuous where it meets the
floor, leaves the floor over (24 E I δ / q)^¼ ≈ 4 cm and carries half that length's weight
at the end), and the blade's share grows as the blade slides under it.

The model is Hencky's bar chain: the patty is cut into ``burger_strips`` equal strips
along its x axis (the simulation lays x along the scoop, :func:`scoop_heading`); each strip
is a rigid body carrying its part of the disc (rounded rims included), and neighbouring strips
are joined at their common edge, on the mid-plane, by a hinge about y with the rotational
stiffness k = E I / a of the beam it replaces: I = c h³/12 for the chord c of the disc at the
hinge, a = diameter / n the strip width. Each hinge is damped with the patty's damping
ratio ζ (``burger_dampratio``): b = 2 ζ √(k J), J the outer strip's moment of inertia about
the hinge. The model bends the patty about one axis only, the one across the scoop; Poisson
stiffening (a factor 1/(1 − ν²) ≤ 1.25 for ν ≤ 0.45) is left out. With one strip the patty is
the rigid disc.

The middle strip is the patty's root body (its free joint, and its pose is the burger's);
the others hang from it in two chains.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.config import CellConfig

QUADRATURE = 400  # grid cells per diameter for the strips' mass properties (deterministic)


def disc_profile(radius: float, thickness: float, edge_radius: float,
                 n_arc: int = 4) -> np.ndarray:
    """(ρ, z) points (m) around the rim of a disc with rounded rims, top to bottom: flat
    faces at z = ±thickness/2, rims of radius ``edge_radius`` (clipped to half the
    thickness)."""
    h2 = thickness / 2
    rho = min(edge_radius, h2)
    prof = []
    for zc, sgn in ((h2 - rho, 1.0), (-h2 + rho, -1.0)):
        for a in np.linspace(0.0, np.pi / 2, n_arc + 1):
            prof.append((radius - rho + rho * np.sin(a), zc + sgn * rho * np.cos(a)))
    return np.unique(np.round(prof, 12), axis=0)


def strip_vertices(radius: float, thickness: float, edge_radius: float, x0: float, x1: float,
                   n_around: int = 64) -> np.ndarray:
    """Vertices (m, patty frame) of the part x0 ≤ x ≤ x1 of the rounded disc: its rim points
    in the slab and its sections by the planes x = x0 and x = x1 (the convex hull is the
    strip)."""
    pts = []
    phi = 2 * np.pi * np.arange(n_around) / n_around
    for rr, z in disc_profile(radius, thickness, edge_radius):
        x = rr * np.cos(phi)
        keep = (x >= x0 - 1e-12) & (x <= x1 + 1e-12)
        pts += [(xi, rr * np.sin(f), z) for xi, f in zip(x[keep], phi[keep])]
        for c in (x0, x1):
            if rr > abs(c) + 1e-12:
                y = math.sqrt(rr * rr - c * c)
                pts += [(c, y, z), (c, -y, z)]
    return np.array(pts)


@dataclass(frozen=True)
class Strip:
    """One rigid strip of the patty.

    Attributes:
        index: 0 … n − 1 along x. x0, x1: Its extent along the patty's x (m).
        hinge_x: x (m) of the hinge joining it to its parent (the neighbour nearer the middle);
            ``None`` for the middle strip, the root.
        mass: kg. com: Centre of mass (m, patty frame). inertia: Principal moments (kg m²)
            about the centre of mass, axes x, y, z of the patty.
        stiffness, damping: Of its hinge (N m/rad, N m s/rad); 0 for the root.
    """

    index: int
    x0: float
    x1: float
    hinge_x: float | None
    mass: float
    com: tuple
    inertia: tuple
    stiffness: float
    damping: float


def strips(cell: CellConfig, mass: float | None = None) -> list[Strip]:
    """The patty's strips for the cell's burger and physics (``mass`` overrides the burger's,
    kg). The mass properties come from a fixed grid quadrature of the disc (uniform density,
    the thickness's share of the inertia as for a slab)."""
    bg, ph = cell.burger, cell.physics
    n, m = ph.burger_strips, bg.mass if mass is None else float(mass)
    r, h = bg.diameter / 2, bg.thickness
    edges = np.linspace(-r, r, n + 1)
    mid = n // 2
    g = (np.arange(QUADRATURE) + 0.5) / QUADRATURE * 2 * r - r
    X, Y = np.meshgrid(g, g, indexing="ij")
    inside = X**2 + Y**2 <= r * r
    x_all, y_all = X[inside], Y[inside]
    width = 2 * r / n
    out = []
    for j in range(n):
        sel = (x_all >= edges[j]) & (x_all < edges[j + 1]) if j < n - 1 else x_all >= edges[j]
        x, y = x_all[sel], y_all[sel]
        mj = m * sel.sum() / len(x_all)
        xc = float(x.mean())
        var_x, var_y = float(np.mean((x - xc) ** 2)), float(np.mean(y**2))
        inertia = (mj * (var_y + h * h / 12), mj * (var_x + h * h / 12), mj * (var_x + var_y))
        hinge = None if j == mid else float(edges[j + 1] if j < mid else edges[j])
        k = b = 0.0
        if hinge is not None:
            chord = 2 * math.sqrt(max(r * r - hinge * hinge, 0.0))
            k = ph.burger_modulus * chord * h**3 / 12 / width
            J = inertia[1] + mj * (xc - hinge) ** 2
            b = 2 * ph.burger_dampratio * math.sqrt(k * J)
        out.append(Strip(j, float(edges[j]), float(edges[j + 1]), hinge, float(mj), (xc, 0.0, 0.0),
                         inertia, k, b))
    return out


def _vec(v) -> str:
    return " ".join(f"{float(x):.9g}" for x in np.ravel(v))


def _origin(s: Strip) -> float:
    """x (m, patty frame) of the strip's body origin: its hinge, or the centre for the root."""
    return 0.0 if s.hinge_x is None else s.hinge_x


def mesh_assets(cell: CellConfig, ss: list[Strip]) -> str:
    """The MJCF ``<mesh>`` assets of the strips ``ss`` (``burger_strip_j``, of :func:`strips`),
    each in its body's frame; empty for a rigid patty (the scene's own disc mesh)."""
    bg, ph = cell.burger, cell.physics
    if ph.burger_strips == 1:
        return ""
    out = []
    for s in ss:
        v = strip_vertices(bg.diameter / 2, bg.thickness, ph.burger_edge_radius, s.x0, s.x1)
        out.append(f'<mesh name="burger_strip_{s.index}" vertex="{_vec(v - [_origin(s), 0, 0])}"/>')
    return "\n    ".join(out)


def strip_geom_name(burger: str, s: Strip, n: int) -> str:
    """The geom (and body) name of strip ``s`` of the patty ``burger``: the root keeps the
    burger's name."""
    return burger if s.index == n // 2 else f"{burger}_s{s.index}"


def body_xml(name: str, pos: str, gravcomp: str, cell: CellConfig, ss: list[Strip],
             contact: str) -> str:
    """The MJCF body tree of a hinged-strip patty named ``name`` at ``pos`` with the strips
    ``ss`` (:func:`strips`; its free joint on the middle strip, two chains of hinged strips),
    each strip geom with the attributes ``contact`` (collision bits, friction, softness)."""
    n, mid, h2 = len(ss), len(ss) // 2, cell.burger.thickness / 2

    def part(s: Strip) -> str:
        gname, o = strip_geom_name(name, s, n), _origin(s)
        chord = 2 * math.sqrt(max((cell.burger.diameter / 2) ** 2 - max(s.x0 ** 2, s.x1 ** 2), 0.0))
        return (f'<inertial pos="{_vec(np.subtract(s.com, (o, 0, 0)))}" mass="{s.mass:.9g}" '
                f'diaginertia="{_vec(s.inertia)}"/>'
                f'<geom name="{gname}" type="mesh" mesh="burger_strip_{s.index}" {contact} '
                f'rgba="0.45 0.25 0.15 1"/>'
                f'<geom type="box" size="{0.4 * (s.x1 - s.x0):.4g} {0.4 * max(chord, 0.01):.4g} 0.0005" '
                f'pos="{(s.x0 + s.x1) / 2 - o:.6g} 0 {h2:.6g}" contype="0" conaffinity="0" '
                f'rgba="0.3 0.15 0.08 1" mass="0"/>')

    def chain(order) -> str:
        xml, parent = "", 0.0
        for j in order:
            s = ss[j]
            xml += (f'<body name="{strip_geom_name(name, s, n)}" pos="{s.hinge_x - parent:.9g} 0 0"'
                    f'{gravcomp}><joint name="{strip_geom_name(name, s, n)}" type="hinge" '
                    f'axis="0 1 0" stiffness="{s.stiffness:.9g}" damping="{s.damping:.9g}"/>'
                    + part(s))
            parent = s.hinge_x
        return xml + "</body>" * len(order)

    return (f'<body name="{name}" pos="{pos}"{gravcomp}><freejoint name="{name}"/>' + part(ss[mid])
            + chain(range(mid + 1, n)) + chain(range(mid - 1, -1, -1)) + "</body>")


def scoop_heading(plan, robot) -> float:
    """Yaw (rad, world) of the blade's x axis at the end of the plan's first scoop: the
    simulation lays the patty's strips along it (module docstring); 0 for a plan without a
    scoop."""
    seg = next((s for s in plan.segments if SUBBEHAVIORS[s.name].role == "scoop"), None)
    if seg is None:
        return 0.0
    R = robot.rotation(np.asarray(seg.q[-1], float))
    return float(math.atan2(R[1, 0], R[0, 0]))
