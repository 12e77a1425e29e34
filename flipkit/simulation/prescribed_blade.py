"""MuJoCo burger physics under a prescribed spatula motion (the blade alone, no arm).

The model is built in code: the grill is a plane whose surface is at h_g, the spatula blade a
thin box, the burger a free cylinder. Frames follow docs/conventions.md: the blade frame has
x along the blade toward the tip and z along its normal; its origin is the blade centre **on
the top (carrying) face** — the box extends a thickness below it. The planner treats the
blade as a zero-thickness plate through the spatula frame (the scoop puts
``p_z − (l/2) sin o_y = h_g``), so with this choice the carrying face meets the grill exactly at the tip and the burger's rim
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

import mujoco
import numpy as np
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation, RotationSpline

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.simulation.run import BurgerRun

STARTS = ("on_spatula", "on_grill")
# Burger–grill friction (the paper is silent; "low grill temperature makes the burgers sticky").
# A rigid puck is harder to scoop than a soft patty: with the 18° scoop wedge and μ = 0.5 on
# the blade, a slipperier grill lets the blade push the burger along instead of sliding under
# it; 0.8 leaves it a few centimetres ahead of the blade centre on a scripted scoop
# (docs/history.md).
GRILL_MU = 0.8


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
