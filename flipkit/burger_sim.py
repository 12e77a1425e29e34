"""MuJoCo burger physics under a prescribed spatula motion, and the paper's success judges.

The model is built in code: the grill is a plane whose surface is at h_g, the spatula blade a
thin box, the burger a free cylinder. Frames follow DESIGN.md: the blade frame has x along the
blade toward the tip and z along its normal; its origin is the blade centre **on the top
(carrying) face** — the box extends a thickness below it. The planner treats the blade as a
zero-thickness plate through the spatula frame (the scoop puts ``p_z − (l/2) sin o_y = h_g``),
so with this choice the carrying face meets the grill exactly at the tip and the burger's rim
rides up the blade without a step. The blade does not collide with the grill: its motion is
prescribed, and the planned scoop puts it flush with the grill surface.

How the blade is driven. A mocap body teleports and has zero velocity in MuJoCo, so friction
could not drag the burger along, and a weld to a mocap damps the blade toward zero velocity
(a lag of about 2·v·timeconst). Instead the blade is a free body, heavy (``blade_mass``,
standing in for the stiff arm) and driven by a computed wrench: the spline feed-forward
acceleration of the desired pose plus a stiff PD on the pose error (natural frequency
``drive_omega``). It therefore has the true velocity and acceleration of the trajectory, and
the contact solver gives the burger the normal and friction forces of a real spatula. A
non-colliding mocap ``target`` body shows the desired pose (for rendering only).

Contacts: only two explicit pairs exist, burger–blade (friction μ) and burger–grill (μ_grill),
elliptic cones, condim 3 (Coulomb sliding friction), ``solref`` (4 ms, critically damped) and
``noslip`` iterations so that static friction holds without creep.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation, RotationSpline

from .config import CellConfig
from .errors import ConfigError

UPSIDE_DOWN_Z = -0.9  # up-axis z below this: lying on its other side (within ~26°)
LANDING_TOL = 0.05  # m, in x and in y (paper Sec. V)
FLIP_CONTACT_FRACTION = 0.6  # of the flip duration (paper Sec. V)
SCOOP_OVERLAP = 0.5  # of the burger's area over the blade (paper Sec. V)
# "On the spatula" / "off the grill" are judged geometrically and over a short window, not from
# one sample's contact flag: MuJoCo's burger–blade contact flickers (present, absent, present
# from one 1 ms step to the next) while the blade decelerates upward with the burger resting on
# it at a gap of micrometres, so a single-instant flag reads "not on the spatula" at random.
# Measured on the Table I IPOPT plans: flag-off runs of 1–9 ms at gaps ≤ 0.07 mm during the
# pickup (the flag is set on a median 57 % of the last 50 ms); of 35 scooped burgers the
# last-sample flag passed 9 pickups, these judges 34.
CONTACT_WINDOW = 0.05  # s: "in contact" at an instant = some contact in the last 50 ms
BLADE_GAP_TOL = 0.003  # m: burger bottom within 3 mm of the blade's carrying face = resting on it
GRILL_SEPARATION = 0.001  # m: burger bottom more than 1 mm above the grill = lifted off it
STARTS = ("on_spatula", "on_grill")
# Burger–grill friction (the paper is silent; "low grill temperature makes the burgers sticky").
# A rigid puck is harder to scoop than a soft patty: with the 18° scoop wedge and μ = 0.5 on
# the blade, μ_grill = 0.5 lets the blade push the burger 12 cm instead of sliding under it,
# 0.8 leaves it 3 cm ahead of the blade centre (measured on a scripted scoop).
GRILL_MU = 0.8


def _half_extent(axis_z, diameter: float, thickness: float):
    """Extent of a cylinder below its centre along a unit direction n, where ``axis_z`` is the
    cosine between n and the cylinder axis: r·sin θ + (h/2)·|cos θ|."""
    axis_z = np.clip(np.abs(axis_z), 0.0, 1.0)
    return diameter / 2 * np.sqrt(1.0 - axis_z**2) + thickness / 2 * axis_z


def _bridge(t: np.ndarray, flag: np.ndarray, span: float) -> np.ndarray:
    """``flag`` with its False runs filled where they lie between two True samples that are
    at most ``span`` (s) apart (a morphological closing in time)."""
    out = np.asarray(flag, bool).copy()
    on = np.flatnonzero(out)
    for a, b in zip(on[:-1], on[1:]):
        if b > a + 1 and t[b] - t[a] <= span + 1e-9:
            out[a + 1:b] = True
    return out


def _vogel_disc(n: int = 400) -> np.ndarray:
    """n equal-area, deterministic points filling the unit disc (sunflower pattern), n×2."""
    k = np.arange(n) + 0.5
    r, th = np.sqrt(k / n), k * np.pi * (3.0 - np.sqrt(5.0))
    return np.column_stack((r * np.cos(th), r * np.sin(th)))


_DISC = _vogel_disc()


@dataclass
class BurgerRun:
    """Time series of one simulation (world frame, SI units); N samples.

    Attributes:
        t: Times (s). burger_pos: Burger centre (m), N×3. burger_rot: Burger→world rotation,
            N×3×3 (burger z = the face that was up at the start).
        spatula_pos, spatula_rot: Actual blade pose (carrying-face centre), N×3 and N×3×3.
        touch_spatula, touch_grill: Burger–blade / burger–grill contact present (N bools).
        force_spatula, force_grill: Summed normal contact force of each pair (N), N.
        burger_diameter, burger_thickness, blade_length, blade_width, grill_height: Geometry
            (m) the judges need.
    """

    t: np.ndarray
    burger_pos: np.ndarray
    burger_rot: np.ndarray
    spatula_pos: np.ndarray
    spatula_rot: np.ndarray
    touch_spatula: np.ndarray
    touch_grill: np.ndarray
    force_spatula: np.ndarray
    force_grill: np.ndarray
    burger_diameter: float
    burger_thickness: float
    blade_length: float
    blade_width: float
    grill_height: float

    @property
    def up_z(self) -> np.ndarray:
        """World z component of the burger's up axis (1 upright, −1 upside down), N."""
        return self.burger_rot[:, 2, 2]

    def in_blade_frame(self) -> np.ndarray:
        """Burger centre in the blade frame (m), N×3."""
        d = self.burger_pos - self.spatula_pos
        return np.einsum("nji,nj->ni", self.spatula_rot, d)

    def blade_gap(self) -> np.ndarray:
        """Height of the burger's lowest point above the blade's carrying face, along the
        blade normal (m), N; negative when it sinks into (or lies under) the blade plane."""
        local = self.in_blade_frame()
        axis_z = np.einsum("ni,ni->n", self.burger_rot[:, :, 2], self.spatula_rot[:, :, 2])
        return local[:, 2] - _half_extent(axis_z, self.burger_diameter, self.burger_thickness)

    def grill_clearance(self) -> np.ndarray:
        """Height of the burger's lowest point above the grill surface (m), N."""
        return (self.burger_pos[:, 2] - self.grill_height
                - _half_extent(self.up_z, self.burger_diameter, self.burger_thickness))

    def over_blade(self) -> np.ndarray:
        """Burger centre over the blade rectangle and on its carrying side (blade frame), N."""
        local = self.in_blade_frame()
        return ((np.abs(local[:, 0]) <= self.blade_length / 2)
                & (np.abs(local[:, 1]) <= self.blade_width / 2) & (local[:, 2] > 0))

    def on_blade(self) -> np.ndarray:
        """Per sample: touching the blade, or resting on it while the contact flag flickers
        off — a flag-off run of at most :data:`CONTACT_WINDOW` between two contacts, with the
        centre over the blade rectangle and the lowest point within :data:`BLADE_GAP_TOL` of
        the carrying face. N bools. A burger leaving the blade is off from its last contact
        on (the run after it is not bounded by a contact)."""
        resting = self.over_blade() & (np.abs(self.blade_gap()) <= BLADE_GAP_TOL)
        return self.touch_spatula | (_bridge(self.t, self.touch_spatula, CONTACT_WINDOW)
                                     & resting)

    def window(self, time: float, length: float = CONTACT_WINDOW, start: float = -np.inf):
        """Samples in ``(time − length, time]`` and at or after ``start`` (s); at least the
        sample :meth:`index` gives, as a boolean mask of N."""
        k = self.index(time)
        sel = (self.t > self.t[k] - length - 1e-9) & (self.t >= start - 1e-9)
        sel[k + 1:] = False
        sel[k] = True
        return sel

    def index(self, time: float) -> int:
        """Index of the last sample at or before ``time`` (s), clipped to the run."""
        return int(np.clip(np.searchsorted(self.t, time + 1e-9) - 1, 0, len(self.t) - 1))


class BurgerSim:
    """A burger on a grill, pushed around by a spatula following a pose trajectory.

    Args:
        cell: Cell configuration (spatula, burger, grill, gravity).
        grill_height: Grill surface height h_g (m); default ``cell.grill.height``.
        mu: Burger–spatula friction coefficient; default ``cell.burger.mu``.
        mu_grill: Burger–grill friction coefficient; default :data:`GRILL_MU`.
        mass: Burger mass (kg); default ``cell.burger.mass``.
        burger_xy: Where the burger lies on the grill for ``'on_grill'`` starts (m).
        timestep: Integration step (s).
        solref: MuJoCo contact (timeconst s, damping ratio); timeconst ≥ 2·timestep.
        noslip_iterations: Post-solve iterations removing soft-contact creep.
        blade_mass: Mass of the driven blade body (kg); large so the burger barely disturbs it.
        drive_omega: Natural frequency of the blade's pose PD (rad/s), critically damped.
    """

    def __init__(self, cell: CellConfig | None = None, grill_height=None, mu=None, mu_grill=None,
                 mass=None, burger_xy=None, timestep=1e-3, solref=(0.004, 1.0),
                 noslip_iterations=10, blade_mass=50.0, drive_omega=150.0):
        self.cell = cell or CellConfig()
        sp, bg = self.cell.spatula, self.cell.burger
        self.grill_height = float(self.cell.grill.height if grill_height is None else grill_height)
        self.mu = float(bg.mu if mu is None else mu)
        self.mu_grill = float(GRILL_MU if mu_grill is None else mu_grill)
        self.mass = float(bg.mass if mass is None else mass)
        for name in ("mu", "mu_grill", "mass"):
            if not (np.isfinite(getattr(self, name)) and getattr(self, name) > 0):
                raise ConfigError(f"{name} must be positive and finite, got {getattr(self, name)}")
        if not np.isfinite(self.grill_height):
            raise ConfigError(f"grill_height must be finite, got {grill_height}")
        if not (timestep > 0 and solref[0] >= 2 * timestep and blade_mass > 0 and drive_omega > 0
                and int(noslip_iterations) >= 0):
            raise ConfigError("need timestep > 0, solref[0] >= 2 timestep, blade_mass > 0, "
                              "drive_omega > 0, noslip_iterations >= 0")
        self.burger_xy = None if burger_xy is None else np.asarray(burger_xy, float)[:2]
        self.blade_mass, self.drive_omega = float(blade_mass), float(drive_omega)
        l, w, th = sp.length, sp.width, sp.thickness
        self.blade_inertia = blade_mass / 12 * np.array([w**2 + th**2, l**2 + th**2, l**2 + w**2])
        self.model = mujoco.MjModel.from_xml_string(self._mjcf(timestep, solref, noslip_iterations))
        self.data = mujoco.MjData(self.model)
        gid = lambda n: mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, n)  # noqa: E731
        self._g_blade, self._g_grill, self._g_burger = gid("blade"), gid("grill"), gid("burger")

    def _mjcf(self, dt, solref, noslip) -> str:
        sp, bg, c = self.cell.spatula, self.cell.burger, self.cell.grill
        l2, w2, t2 = sp.length / 2, sp.width / 2, sp.thickness / 2
        r, h2 = bg.diameter / 2, bg.thickness / 2
        cx, cy = np.mean(c.x_range), np.mean(c.y_range)
        box = f'type="box" size="{l2} {w2} {t2}" pos="0 0 {-t2}"'
        pair = lambda mu: (f'condim="3" solref="{solref[0]} {solref[1]}" '  # noqa: E731
                           f'friction="{mu} {mu} 0.001 0.0001 0.0001"')
        g = " ".join(str(x) for x in self.cell.gravity)
        return f"""<mujoco model="flipkit_burger">
  <option timestep="{dt}" gravity="{g}" cone="elliptic" noslip_iterations="{int(noslip)}"/>
  <worldbody>
    <geom name="grill" type="plane" pos="{cx} {cy} {self.grill_height}" size="0.6 0.6 0.01"
          contype="0" conaffinity="0" rgba="0.3 0.3 0.3 1"/>
    <body name="target" mocap="true"><geom {box} contype="0" conaffinity="0" group="2"
          rgba="0.2 0.8 0.2 0.3"/></body>
    <body name="blade"><freejoint name="blade"/>
      <inertial pos="0 0 0" mass="{self.blade_mass}"
                diaginertia="{' '.join(str(x) for x in self.blade_inertia)}"/>
      <geom name="blade" {box} contype="0" conaffinity="0" rgba="0.75 0.75 0.8 1"/></body>
    <body name="burger"><freejoint name="burger"/>
      <geom name="burger" type="cylinder" size="{r} {h2}" mass="{self.mass}" contype="0"
            conaffinity="0" rgba="0.45 0.25 0.15 1"/></body>
  </worldbody>
  <contact>
    <pair geom1="burger" geom2="blade" {pair(self.mu)}/>
    <pair geom1="burger" geom2="grill" {pair(self.mu_grill)}/>
  </contact>
</mujoco>"""

    # ------------------------------------------------------------------ simulation
    def simulate(self, t, spatula_pos, spatula_rot, burger_start=None,
                 hold: float = 0.0) -> BurgerRun:
        """Drive the blade along a pose trajectory and record the burger.

        The samples are interpolated by a cubic spline (position) and a rotation spline
        (orientation), which also give the feed-forward velocity and acceleration.

        Args:
            t: Strictly increasing sample times (s), N ≥ 2.
            spatula_pos: Spatula-frame origin (carrying-face centre) at t (m), N×3.
            spatula_rot: Spatula→world rotations at t, N×3×3.
            burger_start: ``'on_spatula'`` (centred on the blade at t[0]), ``'on_grill'``
                (upright at ``burger_xy``), or ``None``: on the grill if ``burger_xy`` was
                given, else on the spatula.
            hold: Extra time (s) after t[-1] with the blade held at its last pose (its velocity
                is set to zero there: give trajectories that end at rest), e.g. to let a flipped
                burger land.

        Returns:
            The :class:`BurgerRun`, sampled every timestep from t[0].
        """
        t = np.asarray(t, float)
        P, R = np.asarray(spatula_pos, float), np.asarray(spatula_rot, float)
        n = len(t)
        if t.ndim != 1 or n < 2 or np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)):
            raise ConfigError("t must be a strictly increasing 1-D array of at least 2 times")
        if P.shape != (n, 3) or R.shape != (n, 3, 3) or not np.all(np.isfinite(P)):
            raise ConfigError(f"spatula_pos must be {n}x3 and spatula_rot {n}x3x3")
        if burger_start is None:
            burger_start = "on_grill" if self.burger_xy is not None else "on_spatula"
        if burger_start not in STARTS:
            raise ConfigError(f"unknown burger_start {burger_start!r}; valid: {STARTS}")
        if burger_start == "on_grill" and self.burger_xy is None:
            raise ConfigError("burger_start='on_grill' needs burger_xy")
        m, d, dt = self.model, self.data, self.model.opt.timestep
        ts = t[0] + dt * np.arange(int(np.floor((t[-1] - t[0] + hold) / dt + 1e-9)) + 1)
        tc = np.minimum(ts, t[-1])
        moving = ts <= t[-1]
        ps = CubicSpline(t, P, axis=0)
        rs = RotationSpline(t, Rotation.from_matrix(R))
        p_d, v_d, a_d = ps(tc), ps(tc, 1) * moving[:, None], ps(tc, 2) * moving[:, None]
        q_d = np.roll(rs(tc).as_quat(), 1, axis=1)  # MuJoCo quaternions are (w, x, y, z)
        w_d, al_d = rs(tc, 1) * moving[:, None], rs(tc, 2) * moving[:, None]  # body frame

        mujoco.mj_resetData(m, d)
        d.qpos[0:3], d.qpos[3:7], d.qvel[0:3], d.qvel[3:6] = p_d[0], q_d[0], v_d[0], w_d[0]
        d.mocap_pos[0], d.mocap_quat[0] = p_d[0], q_d[0]
        h2 = self.cell.burger.thickness / 2
        if burger_start == "on_spatula":
            d.qpos[7:10] = p_d[0] + R[0][:, 2] * h2
            d.qpos[10:14] = q_d[0]
            d.qvel[6:9] = v_d[0]
        else:
            d.qpos[7:10] = [*self.burger_xy, self.grill_height + h2]
            d.qpos[10:14] = [1, 0, 0, 0]
        K = len(ts)
        out = {k: np.zeros((K, 3)) for k in ("bp", "sp")}
        out.update({k: np.zeros((K, 3, 3)) for k in ("br", "sr")})
        out.update({k: np.zeros(K) for k in ("fs", "fg")})
        out.update({k: np.zeros(K, bool) for k in ("ts", "tg")})
        kp, kd = self.drive_omega**2, 2 * self.drive_omega
        I, g = self.blade_inertia, np.asarray(self.cell.gravity)
        err, f6 = np.zeros(3), np.zeros(6)
        for k in range(K):  # step1: kinematics + contacts at state k; step2: forces, integrate
            mujoco.mj_step1(m, d)
            d.mocap_pos[0], d.mocap_quat[0] = p_d[k], q_d[k]
            a = a_d[k] + kp * (p_d[k] - d.qpos[0:3]) + kd * (v_d[k] - d.qvel[0:3])
            mujoco.mju_subQuat(err, q_d[k], d.qpos[3:7])  # body-frame rotation error
            w = d.qvel[3:6]
            al = al_d[k] + kp * err + kd * (w_d[k] - w)
            d.qfrc_applied[0:3] = self.blade_mass * (a - g)
            d.qfrc_applied[3:6] = I * al + np.cross(w, I * w)
            mujoco.mj_step2(m, d)
            self._record(out, k, f6)
        bg, sp = self.cell.burger, self.cell.spatula
        return BurgerRun(ts, out["bp"], out["br"], out["sp"], out["sr"], out["ts"], out["tg"],
                         out["fs"], out["fg"], bg.diameter, bg.thickness, sp.length, sp.width,
                         self.grill_height)

    def _record(self, out: dict, k: int, f6: np.ndarray) -> None:
        d = self.data
        out["sp"][k], out["bp"][k] = d.xpos[2], d.xpos[3]  # bodies: world, target, blade, burger
        out["sr"][k], out["br"][k] = d.xmat[2].reshape(3, 3), d.xmat[3].reshape(3, 3)
        for i in range(d.ncon):
            c = d.contact[i]
            other = c.geom2 if c.geom1 == self._g_burger else c.geom1
            key = {self._g_blade: "s", self._g_grill: "g"}[other]  # the only two pairs
            mujoco.mj_contactForce(self.model, d, i, f6)
            out["t" + key][k] = True
            out["f" + key][k] += f6[0]


# ---------------------------------------------------------------------- judges (paper Sec. V)
@dataclass(frozen=True)
class ScoopVerdict:
    """Scoop: ``ok`` if ≥ half the burger's area is over the blade, on its carrying side.

    Attributes:
        ok: Success. overlap: Fraction of the burger's disc over the blade rectangle (0–1).
        above: Burger centre on the carrying side of the blade (blade-frame z > 0).
    """

    ok: bool
    overlap: float
    above: bool


@dataclass(frozen=True)
class PickupVerdict:
    """Pickup: ``ok`` if, at the end of the pickup, the burger is off the grill and resting on
    the blade.

    Attributes:
        ok: Success.
        off_grill: No burger–grill contact in the last :data:`CONTACT_WINDOW` and the burger's
            lowest point more than :data:`GRILL_SEPARATION` above the grill.
        on_spatula: Centre over the blade rectangle (carrying side), lowest point within
            :data:`BLADE_GAP_TOL` of the carrying face, and some burger–blade contact in the
            last :data:`CONTACT_WINDOW`.
        clearance: Height of the burger's lowest point above the grill (m).
        gap: Height of the burger's lowest point above the blade's carrying face (m).
        over_blade: Centre over the blade rectangle, on its carrying side.
        spatula_contact: Fraction of the window's samples with burger–blade contact.
    """

    ok: bool
    off_grill: bool
    on_spatula: bool
    clearance: float
    gap: float
    over_blade: bool
    spatula_contact: float


@dataclass(frozen=True)
class FlipVerdict:
    """Flip: contact ≥ 60 % of the flip, then upside down on the grill within 5 cm in x and y.

    Attributes:
        ok: Success. contact_fraction: Fraction of flip samples with the burger on the blade
            (:meth:`BurgerRun.on_blade`: in contact, or resting within
            :data:`BLADE_GAP_TOL` of the face while the contact flag flickers off).
        upside_down: Up axis pointing down (z < −0.9) at the end. on_grill: Some burger–grill
            contact in the last :data:`CONTACT_WINDOW` of the run. offset: Landing offset
            (x, y) from the designated spot (m). up_z: World z of the burger's up axis at the end.
    """

    ok: bool
    contact_fraction: float
    upside_down: bool
    on_grill: bool
    offset: tuple
    up_z: float


def overlap_fraction(run: BurgerRun, k: int) -> float:
    """Fraction of the burger's disc lying over the blade rectangle at sample k.

    The disc (equal-area sample points in the burger's mid-plane) is projected along the
    blade normal onto the blade plane.
    """
    pts = np.column_stack((_DISC * run.burger_diameter / 2, np.zeros(len(_DISC))))
    world = run.burger_pos[k] + pts @ run.burger_rot[k].T
    local = (world - run.spatula_pos[k]) @ run.spatula_rot[k]
    inside = (np.abs(local[:, 0]) <= run.blade_length / 2) & (
        np.abs(local[:, 1]) <= run.blade_width / 2)
    return float(inside.mean())


def judge_scoop(run: BurgerRun, bounds) -> ScoopVerdict:
    """Judge the scoop segment ``bounds = (t_start, t_end)`` (s) at its end."""
    k = run.index(bounds[1])
    overlap = overlap_fraction(run, k)
    above = bool(run.in_blade_frame()[k, 2] > 0)
    return ScoopVerdict(ok=bool(overlap >= SCOOP_OVERLAP and above), overlap=overlap, above=above)


def judge_pickup(run: BurgerRun, bounds) -> PickupVerdict:
    """Judge the pickup segment ``bounds = (t_start, t_end)`` (s) at its end.

    Geometry at the last sample, contact over the last :data:`CONTACT_WINDOW` (within the
    segment): a flickering contact flag neither fails a burger resting on the blade nor passes
    one still touching the grill.
    """
    k = run.index(bounds[1])
    win = run.window(bounds[1], start=bounds[0])
    clearance = float(run.grill_clearance()[k])
    gap, over = float(run.blade_gap()[k]), bool(run.over_blade()[k])
    touching = run.touch_spatula[win]
    off = bool(not run.touch_grill[win].any() and clearance > GRILL_SEPARATION)
    on = bool(over and abs(gap) <= BLADE_GAP_TOL and touching.any())
    return PickupVerdict(ok=off and on, off_grill=off, on_spatula=on, clearance=clearance,
                         gap=gap, over_blade=over, spatula_contact=float(touching.mean()))


def judge_flip(run: BurgerRun, bounds, spot) -> FlipVerdict:
    """Judge the flip segment ``bounds = (t_start, t_end)`` (s) and the landing at the run's end.

    The run must last until the burger has landed (see ``hold`` of :meth:`BurgerSim.simulate`).

    Args:
        run: The simulation.
        bounds: Flip segment start and end times (s).
        spot: Designated landing spot (x, y) (m), e.g. :func:`flipkit.targets.landing_spot`.
    """
    sel = (run.t >= bounds[0] - 1e-9) & (run.t <= bounds[1] + 1e-9)
    if not np.any(sel):
        raise ConfigError(f"flip bounds {tuple(bounds)} contain no sample of the run")
    frac = float(np.mean(run.on_blade()[sel]))
    up_z = float(run.up_z[-1])
    offset = run.burger_pos[-1, :2] - np.asarray(spot, float)[:2]
    down, grill = up_z < UPSIDE_DOWN_Z, bool(run.touch_grill[run.window(run.t[-1])].any())
    near = bool(np.all(np.abs(offset) <= LANDING_TOL))
    return FlipVerdict(ok=bool(frac >= FLIP_CONTACT_FRACTION and down and grill and near),
                       contact_fraction=frac, upside_down=bool(down), on_grill=grill,
                       offset=tuple(float(x) for x in offset), up_z=up_z)
