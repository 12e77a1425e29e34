"""The whole cell as one MuJoCo model: the UR10 with its spatula, the grill, the burger, a table.

The arm is converted from the pinocchio model of :class:`~flipkit.model.robot.Robot` built *without*
the burger payload (the burger is its own free body here): one body per joint, placed by
``model.jointPlacements``, a hinge about the joint's axis, and the inertia ``model.inertias``
(the spatula's mass is already lumped into the last one). Inverse dynamics of the two models
agree to round-off (tests/test_scene.py), so the planner's torques mean the same here.

Geometry (docs/conventions.md): the spatula frame has x along the blade toward the tip and z
along its normal; its xy-plane is the blade's top (carrying) face — the zero-thickness plate of
the planner. The blade is a convex mesh below that plane: ``blade_thickness`` thick, its
leading edge (x = +l/2) ground on the underside over ``bevel_length`` down to
``edge_thickness``, so the planned tip point (l/2, 0, 0) is the top of the edge.

Contacts are explicit pairs only (every geom has contype = conaffinity = 0): blade-grill
(steel on steel, ``mu_blade_grill``; compliant: the blade's flex, below), burger-blade (``burger.mu``) and burger-grill
(``mu_grill``) with the patty's softness (:meth:`PhysicsConfig.burger_timeconst`); the
side table, where serve plans put the burger, is a steel tray like the grill plate: burger-table
is the burger-grill pair's friction and softness, blade-table the blade-grill pair's; the
burger is a convex disc with rounded rims (``burger_edge_radius``); condim 3,
elliptic cones, ``noslip`` iterations against soft-contact creep. Links are capsules for
rendering only.

Blade-grill compliance. A real turner's tip pressed onto the grill is held by the thin blade
flexing as a cantilever from its neck, not by the grill's steel: the pair is a spring-damper
of the physical stiffness k (:meth:`PhysicsConfig.blade_stiffness`, N/m) and damping b
(:meth:`PhysicsConfig.blade_damping`, N s/m); the rigid blade's penetration of the grill
stands for the tip's flex. MuJoCo's direct form ``solref = (−s, −c)`` is *not* in N/m: with a
constant impedance d (``solimp = d d …``) the solver gives (MuJoCo Computation chapter,
soft constraints: a₁ + d (B v + K r) = (1 − d) a₀, K = s/d², B = c/d, regulariser
R = (1 − d)/d · D) a contact force f = [A F + d (K d x + B ẋ)] / (A + R), with x the
penetration, A the true inverse inertia along the normal, F the load pushing in and D the
model's approximate inverse inertia (``efc_diagApprox``: the blade body's
``body_invweight0``). For small d (R ≫ A) this is f = (s x + c ẋ)/((1 − d) D): so s and c are
set to k (1 − d) D / n and b (1 − d) D / n after compiling, d = :data:`BLADE_IMPEDANCE`, with
n = :data:`BLADE_EDGE_CONTACTS` contact points sharing the edge's load; the static
force is exactly k x whatever A is (tests/test_scene.py), and the instantaneous share of the
push the constraint takes is A/(A + R) < 0.1 %. Friction on this pair stays Coulomb through
the ``noslip`` iterations.

Blade flex (``physics.blade_flex``). The contact above lets the rigid blade sink into the
grill by the tip's deflection, so its faces go below the grill's surface: under the patty the
tip's top face rides from below to above the grill over a scoop, as the servo and the
blade's roll share the press (docs/history.md). With ``"hinge"`` the blade is a body of its
own on a hinge about its y axis at its neck (x = −l/2), of rotational stiffness k L² and
damping b L² (:func:`hinge_flex`: the tip meets the cantilever's k and b, L the blade length),
carrying the spatula's mass and inertia (moved there from the last link, so the arm's
dynamics with the hinge at rest are the planner's). It meets the grill and the table in a
stiff steel contact (:data:`STEEL_TIMECONST_STEPS`), so its tip stays on the surface and its
faces above it. The spatula's mass swinging on the hinge rings at about 19 Hz (a 1 mm blade
alone: 31 Hz); the hinge rotates the blade rigidly where a real one bends.

Several burgers (``burgers=n`` > 1, a whole cook: :mod:`flipkit.simulation.cook`). Burger k is
the body and geom ``burger_k``, with the same pairs as the single burger (blade, grill,
table) and a pair with every other burger, so that burgers cannot pass through each other;
burger–burger contacts have the patty's softness and the burger-grill friction
(``mu_grill``): the cell has no patty-on-patty friction, and any such contact is reported by
the cook simulation, not relied on. All n start *parked* (:func:`park_burger`): below the
(visual) floor, :data:`PARK_SPACING` apart, out of every pair's reach and held against gravity
(``gravcomp`` 1), so a parked burger stays exactly where it is; :func:`place_burger` with
``burger=k`` puts one at rest on the grill (or table) and gives it back its weight. With one
burger (the default) the scene is unchanged: body and geom ``burger``, on the grill.

Sleeping. A burger lying still on the grill costs a step as much as one being scooped: its
five strips keep about twenty contacts. The scene therefore lets MuJoCo put a burger at rest
to sleep (``<flag sleep="enable"/>``): a tree whose speed stays below
:data:`SLEEP_TOLERANCE` for MuJoCo's ``mjMINAWAKE`` steps is frozen and skipped until an awake
body touches it (the blade arriving), when it is simulated again. The arm never sleeps
(``sleep="never"``). A frozen burger keeps the contacts it fell asleep with: the records of
a run (:class:`~flipkit.simulation.trace.BurgerTrace`,
:class:`~flipkit.simulation.cook_record.CookRecorder`) carry them on, so the judges still see
it lying on the grill. A step costs about half as much. :func:`place_burger` and :func:`park_burger` wake the burger they move: they write
−0.0 into its velocities, MuJoCo's documented wake signal (a non-zero bit pattern that is
zero), besides its new pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot
from flipkit.simulation import patty

NOSLIP_ITERATIONS = 10  # post-solve iterations: static friction holds without creep
# m/s (MuJoCo's default, speeds weighted by each dof's length): a tree slower than this for
# mjMINAWAKE steps sleeps, in a scene that sleeps (module docstring)
SLEEP_TOLERANCE = 1e-3
ARM_JOINTS = 6
LINK_RADIUS = 0.045  # m, capsule visuals
# Constant impedance of the blade-grill contact (module docstring): small, so that the contact
# is the blade's spring-damper and not MuJoCo's stiff-constraint blend; with D ≈ 33 /kg and
# A ≈ 1.3-2.9 /kg at the scoops, A/R = A d/((1 − d) D) ≈ 0.1 %.
BLADE_IMPEDANCE = 0.01
# MuJoCo's convex collider puts one blade-grill contact at each end of the leading edge when the
# edge lies on the grill (at y = ±w/2, 2 contacts); each is one half of the blade's
# spring-damper, so that the pressed edge meets k and b in all.
BLADE_EDGE_CONTACTS = 2
# A flexing blade meets the grill and the table steel on steel: MuJoCo's stiffest recommended
# contact, a time constant of two timesteps, critically damped (MuJoCo Modeling chapter,
# solref: "not smaller than 2 times the physics timestep").
STEEL_TIMECONST_STEPS = 2
# Collision bit of the burgers' geoms in a several-burger scene: burger-burger contacts come from
# MuJoCo's broad phase (a pair per strip pair would be thousands); every other geom has none.
BURGER_BIT = 2
# Parked burgers (several-burger scenes): a row below the visual floor (z = -0.6 m), hidden from
# the cameras above it, 0.2 m apart (more than a diameter: no burger-burger contact).
PARK_ORIGIN = (-1.0, 0.0, -1.5)  # m
PARK_SPACING = 0.2  # m, along x


def _vec(v) -> str:
    return " ".join(f"{float(x):.12g}" for x in np.ravel(v))


def _quat(R) -> str:
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, np.asarray(R, float).reshape(9))
    return _vec(q)


def blade_vertices(length: float, width: float, thickness: float, bevel: float,
                   edge: float) -> np.ndarray:
    """Vertices (m, spatula frame, 10×3) of the convex blade: top face z = 0, flat underside
    z = −thickness, bevelled on the underside over ``bevel`` to ``edge`` at x = +length/2."""
    l2, w2 = length / 2, width / 2
    out = []
    for y in (-w2, w2):
        out += [(-l2, y, 0.0), (l2, y, 0.0), (-l2, y, -thickness), (l2 - bevel, y, -thickness),
                (l2, y, -edge)]
    return np.array(out)


def burger_vertices(diameter: float, thickness: float, edge_radius: float,
                    n_around: int = 32, n_arc: int = 4) -> np.ndarray:
    """Vertices (m, burger frame, axis z) of a disc with rounded rims: flat faces at
    z = ±thickness/2, rims of radius ``edge_radius`` (clipped to half the thickness)."""
    prof = patty.disc_profile(diameter / 2, thickness, edge_radius, n_arc)
    phi = 2 * np.pi * np.arange(n_around) / n_around
    return np.array([(rr * np.cos(f), rr * np.sin(f), z) for rr, z in prof for f in phi])


@dataclass
class Scene:
    """A compiled cell: MuJoCo model, data and the ids the simulation needs.

    Attributes:
        model, data: MuJoCo model and data. xml: The MJCF it was compiled from.
        robot: The pinocchio arm it mirrors (no burger payload).
        blade_site: Site id of the spatula frame (top-face centre). grill_height: Actual
            surface height (m). geoms: ``{"blade", "grill", "burger", "table"}`` geom ids.
        burger_qpos, burger_qvel: Slices of the (first) burger's free joint in qpos / qvel.
        blade_contact: The blade-grill pair's physical ``stiffness`` (N/m) and ``damping``
            (N s/m) and the MuJoCo ``solref`` (−s, −c) and ``impedance`` d realising them;
            on a flexing blade (``physics.blade_flex`` "hinge") the hinge's (:func:`hinge_flex`),
            ``flex`` "hinge" and the stiff contact's ``solref``.
        burger_bodies: Root body id of each burger (one, or ``burgers`` of :func:`build_scene`);
            with several, ``geoms`` holds ``burger_k`` for each instead of ``burger``. A
            root is the patty's middle strip (:mod:`flipkit.simulation.patty`): its pose
            is the burger's.
        burger_geoms: Per burger, the geom ids of all its strips, in order along the patty's
            x; ``geoms`` names them too (``burger_s0`` …).
        sleeps: Whether MuJoCo puts a burger at rest to sleep (module docstring).
    """

    model: mujoco.MjModel
    data: mujoco.MjData
    xml: str
    robot: Robot
    blade_site: int
    grill_height: float
    geoms: dict
    blade_contact: dict
    burger_bodies: tuple = ()
    burger_geoms: tuple = ()
    sleeps: bool = False

    @property
    def burger_qpos(self) -> slice:
        return self.qpos_of(0)

    @property
    def burger_qvel(self) -> slice:
        return self.qvel_of(0)

    def contacts(self) -> list[tuple[int, int, float]]:
        """(geom, geom, normal force N) of each contact of the last step, in contact order.

        The normal force is the contact's first ``efc_force`` row: with the scene's elliptic
        cones that is what ``mj_contactForce`` returns, read without a call per contact; a
        contact without constraint rows (``efc_address`` −1) has none. A sleeping burger (a
        scene that sleeps) has none: MuJoCo skips it, and it lies as it fell asleep.
        """
        pairs, force = self.contact_arrays()
        return [(a, b, f) for (a, b), f in zip(pairs.tolist(), force.tolist())]

    def contact_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`contacts` as arrays: the geom pairs (ncon×2) and normal forces (N, ncon)."""
        d = self.data
        if d.ncon == 0:
            return np.zeros((0, 2), int), np.zeros(0)
        con, efc = d.contact, d.efc_force
        adr = con.efc_address
        force = efc[adr] if efc.size else np.zeros(len(adr))
        force[adr < 0] = 0.0
        return con.geom, force

    def blade_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """World position (m) and rotation of the spatula frame (after mj_kinematics)."""
        return (self.data.site_xpos[self.blade_site].copy(),
                self.data.site_xmat[self.blade_site].reshape(3, 3).copy())

    def in_blade_frame(self, body: int) -> np.ndarray:
        """Position (m) of ``body`` (a burger's root) in the spatula frame, from the current
        qpos (runs mj_kinematics): what a camera measures of the burger on the blade."""
        mujoco.mj_kinematics(self.model, self.data)
        p_b, R_b = self.blade_pose()
        return (self.data.xpos[body] - p_b) @ R_b

    def qpos_of(self, k: int) -> slice:
        """Slice of burger k's free joint (position, quaternion) in qpos."""
        a = int(self.model.jnt_qposadr[self.model.body_jntadr[self.burger_bodies[k]]])
        return slice(a, a + 7)

    def qvel_of(self, k: int) -> slice:
        """Slice of burger k's free joint (linear, angular velocity) in qvel."""
        a = int(self.model.jnt_dofadr[self.model.body_jntadr[self.burger_bodies[k]]])
        return slice(a, a + 6)

    def patty_bodies(self, k: int) -> np.ndarray:
        """Body ids of burger k's strips (its root and the strips hinged to it)."""
        return np.flatnonzero(self.model.body_rootid == self.burger_bodies[k])

    def hinges_of(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """qpos and qvel indices of burger k's strip hinges (empty for a rigid patty)."""
        m = self.model
        joints = [j for b in self.patty_bodies(k)[1:]
                  for j in range(m.body_jntadr[b], m.body_jntadr[b] + m.body_jntnum[b])]
        return (np.asarray(m.jnt_qposadr[joints], int), np.asarray(m.jnt_dofadr[joints], int))


def _joint_axis(joint) -> np.ndarray:
    """Unit rotation axis of a revolute pinocchio joint (in its own frame)."""
    name = joint.shortname()
    if name in ("JointModelRX", "JointModelRY", "JointModelRZ"):
        return np.eye(3)["XYZ".index(name[-1])]
    if name == "JointModelRevoluteUnaligned":
        return np.asarray(joint.extract().axis, float)
    raise ConfigError(f"scene supports revolute joints only, got {name}")


def _arm_bodies(robot: Robot, sp_xml: str, carried=None) -> str:
    """Nested <body> elements of the six joints; ``sp_xml`` goes into the last one.
    ``carried``: an inertia (last joint's frame) that a body in ``sp_xml`` carries instead of
    the last link (the spatula, on a flexing blade)."""
    m = robot.model
    if m.njoints - 1 != ARM_JOINTS or any(m.parents[j] != j - 1 for j in range(1, m.njoints)):
        raise ConfigError(f"scene needs a serial {ARM_JOINTS}-joint arm, got {m.njoints - 1}")
    opened, close = [], []
    for j in range(1, m.njoints):
        M, I = m.jointPlacements[j], m.inertias[j]
        if carried is not None and j == m.njoints - 1:
            I = I - carried
        axis = _joint_axis(m.joints[j])
        full = I.inertia
        fi = _vec([full[0, 0], full[1, 1], full[2, 2], full[0, 1], full[0, 2], full[1, 2]])
        child = m.jointPlacements[j + 1].translation if j + 1 < m.njoints else np.zeros(3)
        link = "" if np.linalg.norm(child) < 1e-6 else (
            f'<geom type="capsule" fromto="0 0 0 {_vec(child)}" size="{LINK_RADIUS}" '
            f'contype="0" conaffinity="0" rgba="0.55 0.6 0.65 1" mass="0"/>')
        never = ' sleep="never"' if j == 1 else ""  # the arm is driven: it never sleeps
        opened.append(
            f'<body name="{m.names[j]}" pos="{_vec(M.translation)}" quat="{_quat(M.rotation)}"'
            f'{never}>'
            f'<joint name="{m.names[j]}" type="hinge" axis="{_vec(axis)}" '
            f'limited="false"/>'
            f'<inertial pos="{_vec(I.lever)}" mass="{I.mass:.12g}" fullinertia="{fi}"/>{link}')
        close.append("</body>")
    return "\n".join(opened) + sp_xml + "".join(close)


def build_scene(robot: Robot | None = None, cell: CellConfig | None = None, *,
                grill_offset: float = 0.0, burger_xy=None, mu: float | None = None,
                mass: float | None = None, burgers: int = 1, sleep: bool | None = None) -> Scene:
    """Compile the cell.

    Args:
        robot: Arm model; default ``Robot(cell, with_burger=False)``. It must not carry the
            burger (the burger is simulated as its own body).
        cell: Cell configuration; default ``robot.cell``.
        grill_offset: Grill surface error (m), added to ``cell.grill.height``.
        burger_xy: Where the burger lies (m); default the grill centre. Set later with
            :func:`place_burger`.
        mu: Burger-blade friction; default ``cell.burger.mu``.
        mass: Burger mass (kg); default ``cell.burger.mass``.
        burgers: Number of burgers, ≥ 1. One: the burger lies at ``burger_xy``. Several:
            all start parked (module docstring); ``burger_xy`` must be ``None``.
        sleep: Let a burger at rest sleep (module docstring); default ``True``.

    Raises:
        ConfigError: ``burgers`` not a positive integer, or ``burger_xy`` with several.
    """
    if isinstance(burgers, bool) or not isinstance(burgers, (int, np.integer)) or burgers < 1:
        raise ConfigError(f"burgers must be a positive integer, got {burgers!r}")
    if burgers > 1 and burger_xy is not None:
        raise ConfigError("burger_xy places the single burger; several start parked")
    sleep = True if sleep is None else bool(sleep)
    robot = robot or Robot(cell, with_burger=False)
    cell = cell or robot.cell
    ph, sp, bg, gr, tb = cell.physics, cell.spatula, cell.burger, cell.grill, cell.table
    mu = bg.mu if mu is None else float(mu)
    mass = bg.mass if mass is None else float(mass)
    h_g = gr.height + float(grill_offset)
    verts = blade_vertices(sp.length, sp.width, ph.blade_thickness, ph.bevel_length,
                           ph.edge_thickness)
    S = robot.spatula_in_joint
    sp_pos, sp_quat = _vec(S.translation), _quat(S.rotation)
    flange = robot.model.frames[robot.model.getFrameId(cell.robot.tool_frame)].placement
    back = S.act(np.array([-sp.length / 2, 0.0, 0.0]))
    hinge = ph.blade_flex == "hinge"
    at = f' pos="{sp.length / 2:.12g} 0 0"' if hinge else ""  # the blade centre from the neck
    blade = (f'<site name="spatula" size="0.005" rgba="1 0 0 1"{at}/>'
             f'<geom name="blade" type="mesh" mesh="blade" contype="0" conaffinity="0" '
             f'mass="0" rgba="0.78 0.8 0.84 1"{at}/>')
    carried = None
    if hinge:  # module docstring, "Blade flex": the spatula's mass moves onto the blade
        body = robot.payload[0]["inertia_obj"]
        carried = S.act(body)
        flex = hinge_flex(cell)
        full = body.inertia
        fi = _vec([full[0, 0], full[1, 1], full[2, 2], full[0, 1], full[0, 2], full[1, 2]])
        blade = (f'<body name="blade_flex" pos="{-sp.length / 2:.12g} 0 0">'
                 f'<joint name="blade_flex" type="hinge" axis="0 1 0" limited="false" '
                 f'stiffness="{flex["stiffness"]:.9g}" damping="{flex["damping"]:.9g}"/>'
                 f'<inertial pos="{_vec(body.lever + [sp.length / 2, 0, 0])}" '
                 f'mass="{body.mass:.12g}" fullinertia="{fi}"/>{blade}</body>')
    sp_xml = (
        f'<geom type="capsule" fromto="{_vec(flange.translation)} {_vec(back)}" size="0.008" '
        f'contype="0" conaffinity="0" rgba="0.15 0.15 0.15 1" mass="0"/>'
        f'<body name="spatula" pos="{sp_pos}" quat="{sp_quat}">{blade}</body>')
    tau_b = ph.burger_timeconst(bg, mass)
    r, h2 = bg.diameter / 2, bg.thickness / 2
    gx, gy = np.mean(gr.x_range), np.mean(gr.y_range)
    gsx, gsy = np.ptp(gr.x_range) / 2 + 0.15, np.ptp(gr.y_range) / 2 + 0.15
    xy = (gx, gy) if burger_xy is None else tuple(np.asarray(burger_xy, float)[:2])
    tx, ty, tsx, tsy = np.mean(tb.x_range), np.mean(tb.y_range), np.ptp(tb.x_range) / 2, \
        np.ptp(tb.y_range) / 2

    def pair(g1, g2, f, solref, imp=None):
        solimp = "" if imp is None else f' solimp="{imp} {imp} 0.001 0.5 2"'
        return (f'<pair name="{g1}_{g2}" geom1="{g1}" geom2="{g2}" condim="3" '
                f'friction="{f} {f} 0.001 0.0001 0.0001" '
                f'solref="{solref[0]:.6g} {solref[1]:.6g}"{solimp}/>')

    # the blade-grill and blade-table pairs: the flex's spring (solref set after compiling) or,
    # on a flexing blade, steel on steel
    steel = ((STEEL_TIMECONST_STEPS * ph.timestep, 1.0), None) if hinge else \
        ((-1.0, -1.0), BLADE_IMPEDANCE)
    names = ["burger"] if burgers == 1 else [f"burger_{k}" for k in range(burgers)]
    soft = (tau_b, ph.burger_dampratio)

    strips = ph.burger_strips
    parts_of = patty.strips(cell, mass) if strips > 1 else []  # computed once per scene
    collide = ('contype="0" conaffinity="0"' if burgers == 1 else
               f'contype="{BURGER_BIT}" conaffinity="{BURGER_BIT}" condim="3" '
               f'friction="{ph.mu_grill} 0.001 0.0001" solref="{soft[0]:.6g} {soft[1]:.6g}"')

    def body(name, pos, gravcomp):
        if strips > 1:
            return patty.body_xml(name, pos, gravcomp, cell, parts_of, collide)
        return (f'<body name="{name}" pos="{pos}"{gravcomp}>\n'
                f'      <freejoint name="{name}"/>\n'
                f'      <inertial pos="0 0 0" mass="{mass:.9g}" '
                f'diaginertia="{_vec(_disc_inertia(mass, r, 2 * h2))}"/>\n'
                f'      <geom name="{name}" type="mesh" mesh="burger" {collide}\n'
                f'            rgba="0.45 0.25 0.15 1"/>\n'
                f'      <geom type="cylinder" size="{r * 0.8:.4g} 0.0005" pos="0 0 {h2}" '
                f'contype="0"\n            conaffinity="0" rgba="0.3 0.15 0.08 1" mass="0"/>\n'
                f'    </body>')

    if burgers == 1:
        bodies = body("burger", f"{xy[0]:.9g} {xy[1]:.9g} {h_g + h2:.9g}", "")
    else:
        bodies = "\n    ".join(body(n, _vec(_park_position(k)), ' gravcomp="1"')
                               for k, n in enumerate(names))
    disc_mesh = (f'<mesh name="burger" vertex="'
                 f'{_vec(burger_vertices(bg.diameter, bg.thickness, ph.burger_edge_radius))}"/>')
    parts = {n: [patty.strip_geom_name(n, st, strips) for st in parts_of] if strips > 1
             else [n] for n in names}
    pairs = "\n    ".join(
        line for n in names for g in parts[n]
        for line in (pair(g, "blade", mu, soft), pair(g, "grill", ph.mu_grill, soft),
                     pair(g, "table", ph.mu_grill, soft)))
    # burger-burger contacts: collision bits (BURGER_BIT), not pairs; a patty's strips meet
    # their neighbours through the hinges only
    excludes = "\n    ".join(
        f'<exclude body1="{a}" body2="{b}"/>' for n in names if burgers > 1
        for i, a in enumerate(parts[n]) for b in parts[n][i + 2:])
    xml = f"""<mujoco model="flipkit_cell">
  <compiler angle="radian" inertiafromgeom="false"/>
  <option timestep="{ph.timestep}" gravity="{_vec(cell.gravity)}" cone="elliptic"
          noslip_iterations="{NOSLIP_ITERATIONS}" sleep_tolerance="{SLEEP_TOLERANCE}">
    <flag sleep="{'enable' if sleep else 'disable'}"/></option>
  <visual><global offwidth="1280" offheight="960"/><quality shadowsize="2048"/>
    <headlight ambient="0.35 0.35 0.35" diffuse="0.5 0.5 0.5"/><rgba haze="0.85 0.88 0.92 1"/>
  </visual>
  <asset>
    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.85 0.9 0.95" rgb2="0.4 0.5 0.6"
             width="32" height="32"/>
    <mesh name="blade" vertex="{_vec(verts)}"/>
    {disc_mesh if strips == 1 else patty.mesh_assets(cell, parts_of)}
  </asset>
  <worldbody>
    <light pos="0.6 -0.2 2.0" dir="0 0 -1" diffuse="0.8 0.8 0.8"/>
    <camera name="side" pos="{gx + 0.2:.3f} {gy - 1.6:.3f} 0.9" xyaxes="1 -0.1 0 0.05 0.4 1"/>
    <geom name="floor" type="plane" size="2 2 0.1" pos="0 0 -0.6" contype="0" conaffinity="0"
          rgba="0.9 0.9 0.88 1"/>
    <geom name="grill" type="box" size="{gsx:.6g} {gsy:.6g} 0.02"
          pos="{gx:.6g} {gy:.6g} {h_g - 0.02:.9g}" contype="0" conaffinity="0"
          rgba="0.25 0.25 0.27 1"/>
    <geom name="table" type="box" size="{tsx:.6g} {tsy:.6g} 0.02"
          pos="{tx:.6g} {ty:.6g} {tb.height - 0.02:.6g}" contype="0" conaffinity="0"
          rgba="0.6 0.45 0.3 1"/>
    {_arm_bodies(robot, sp_xml, carried)}
    {bodies}
  </worldbody>
  <contact>
    {pair("blade", "grill", ph.mu_blade_grill, *steel)}
    {pairs}
    {pair("blade", "table", ph.mu_blade_grill, *steel)}
    {excludes}
  </contact>
</mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    if hinge:
        contact = {**hinge_flex(cell), "flex": "hinge", "solref": steel[0]}
    else:
        contact = _blade_contact(model, cell)
        for name in ("blade_grill", "blade_table"):
            model.pair_solref[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_PAIR, name)] = \
                contact["solref"]
        xml = xml.replace('solref="-1 -1"', 'solref="{:.9g} {:.9g}"'.format(*contact["solref"]))
    data = mujoco.MjData(model)
    gid = lambda n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n)  # noqa: E731
    every = [g for n in names for g in parts[n]]
    scene = Scene(model, data, xml, robot,
                  mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "spatula"), h_g,
                  {n: gid(n) for n in ("blade", "grill", *every, "table")}, contact,
                  tuple(int(model.geom_bodyid[gid(n)]) for n in names),
                  tuple(tuple(gid(g) for g in parts[n]) for n in names), bool(sleep))
    mujoco.mj_forward(model, data)
    return scene


def hinge_flex(cell: CellConfig) -> dict:
    """The flexing blade's hinge (module docstring, "Blade flex"): the tip's physical
    ``stiffness`` k (N/m) and ``damping`` b (N s/m) as the hinge's rotational stiffness
    k L² (N m/rad) and damping b L² (N m s/rad), L the blade length from neck to tip."""
    ph, sp = cell.physics, cell.spatula
    k, b = ph.blade_stiffness(sp), ph.blade_damping(sp)
    return {"tip_stiffness": k, "tip_damping": b, "stiffness": k * sp.length**2,
            "damping": b * sp.length**2}


def _blade_contact(model: mujoco.MjModel, cell: CellConfig) -> dict:
    """The blade-grill pair's direct-form solref (−s, −c) for the physical stiffness and
    damping of the blade (module docstring): s = k (1 − d) D / n, c = b (1 − d) D / n
    (n :data:`BLADE_EDGE_CONTACTS` contact points on the leading edge), D the blade
    body's translational ``body_invweight0`` (the contact rows' ``efc_diagApprox``; the grill
    is the world's, weight 0)."""
    ph, sp = cell.physics, cell.spatula
    k, b = ph.blade_stiffness(sp), ph.blade_damping(sp)
    blade = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "spatula")
    scale = (1.0 - BLADE_IMPEDANCE) * float(model.body_invweight0[blade, 0]) / BLADE_EDGE_CONTACTS
    return {"stiffness": k, "damping": b, "impedance": BLADE_IMPEDANCE,
            "solref": (-k * scale, -b * scale)}


def _disc_inertia(m: float, r: float, h: float) -> np.ndarray:
    """Principal inertia (kg m²) of a uniform cylinder, axis z."""
    ixx = m * (3 * r**2 + h**2) / 12
    return np.array([ixx, ixx, m * r**2 / 2])


def _park_position(k: int) -> np.ndarray:
    """Where burger k is parked (m): :data:`PARK_ORIGIN` + k :data:`PARK_SPACING` along x."""
    return np.asarray(PARK_ORIGIN, float) + [PARK_SPACING * k, 0.0, 0.0]


def place_burger(scene: Scene, xy, q=None, *, burger: int = 0, height: float | None = None,
                 heading: float = 0.0) -> None:
    """Put a burger upright and flat at ``xy`` (m) on the grill, at rest; the arm at ``q`` (rad).

    Args:
        scene: The cell. xy: Where the burger's centre lies (m).
        q: Arm configuration (rad) to set too, or ``None``.
        burger: Which burger (index into ``scene.burger_bodies``); it gets its weight back.
        height: Surface it rests on (m); default the grill's.
        heading: Yaw (rad) of the patty's x axis, along which its strips bend
            (:func:`flipkit.simulation.patty.scoop_heading`). A rigid patty (one strip) keeps
            yaw 0 whatever it is: the disc is symmetric, and turning its 32-gon mesh would
            only move its contact points.
    """
    d, h2 = scene.data, scene.robot.cell.burger.thickness / 2
    if q is not None:
        d.qpos[:ARM_JOINTS] = q
    surface = scene.grill_height if height is None else float(height)
    if len(scene.burger_geoms[burger]) == 1:
        heading = 0.0
    c, s_ = np.cos(heading / 2), np.sin(heading / 2)
    d.qpos[scene.qpos_of(burger)] = [*np.asarray(xy, float)[:2], surface + h2, c, 0, 0, s_]
    _rest_hinges(scene, burger, gravcomp=0.0)
    _wake(scene, burger)
    mujoco.mj_forward(scene.model, d)


def _wake(scene: Scene, burger: int) -> None:
    """Burger ``burger`` at rest and awake: −0.0 in its velocities, MuJoCo's wake signal
    (module docstring)."""
    _, va = scene.hinges_of(burger)
    scene.data.qvel[scene.qvel_of(burger)] = -0.0
    scene.data.qvel[va] = -0.0


def _rest_hinges(scene: Scene, burger: int, gravcomp: float) -> None:
    """Burger ``burger``'s strips flat and at rest, each body's gravity compensation set."""
    qa, va = scene.hinges_of(burger)
    scene.data.qpos[qa], scene.data.qvel[va] = 0.0, 0.0
    bodies = scene.patty_bodies(burger)
    if np.any(scene.model.body_gravcomp[bodies] != gravcomp):
        scene.model.body_gravcomp[bodies] = gravcomp


def park_burger(scene: Scene, burger: int) -> None:
    """Take a burger of a several-burger scene out of the cell: parked (module docstring), at
    rest, held against gravity.

    Raises:
        ConfigError: A single-burger scene (compiled without gravity compensation).
    """
    if len(scene.burger_bodies) < 2:
        raise ConfigError("only a scene of several burgers parks them (build_scene(burgers=n))")
    d = scene.data
    d.qpos[scene.qpos_of(burger)] = [*_park_position(burger), 1, 0, 0, 0]
    _rest_hinges(scene, burger, gravcomp=1.0)
    _wake(scene, burger)
    mujoco.mj_forward(scene.model, d)
