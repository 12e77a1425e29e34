"""What a cook simulation records at each control step: each burger's trajectory while one of
its own motions runs (its *watch* windows), how far a burger lying untouched was moved by
the others, the smallest distance between two lying burgers, burger–burger contact, and the
frames of the film.

A burger's watch windows are its flip and its serve, each from the motion's start to
:data:`~flipkit.simulation.execute.HOLD_S` after its end (as long as ``execute_plan`` runs a
plan: a flipped burger has landed, a served one settled); the judges read these windows
(:mod:`flipkit.simulation.cook_judges`). Outside its windows a burger placed in the cell is
*lying*: where it was left, it should stay.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from flipkit.simulation.run import BurgerRun
from flipkit.simulation.scene import Scene

_FIELDS = ("t", "bp", "br", "sp", "sr", "ts", "tg", "fs", "fg")


@dataclass
class Watch:
    """One burger's samples over one of its motions (cook clock, s)."""

    burger: int
    kind: str
    t0: float
    t1: float
    samples: dict = field(default_factory=lambda: {k: [] for k in _FIELDS})

    def run(self, scene: Scene, origin: float) -> BurgerRun:
        """The samples as a :class:`BurgerRun` with times from ``origin`` (s, cook clock)."""
        s = {k: np.asarray(v) for k, v in self.samples.items()}
        if len(s["t"]) == 0:
            raise ValueError(f"no sample recorded for burger {self.burger} {self.kind}")
        cell = scene.robot.cell
        return BurgerRun(s["t"] - origin, s["bp"], s["br"], s["sp"], s["sr"], s["ts"], s["tg"],
                         s["fs"], s["fg"], cell.burger.diameter, cell.burger.thickness,
                         cell.spatula.length, cell.spatula.width, scene.grill_height)


class CookRecorder:
    """Per-step bookkeeping of a cook simulation on ``scene`` with ``watches``.

    Attributes:
        knocked_m: Per burger, the largest displacement (m) of its centre while it was lying.
        min_distance_m: Smallest centre distance (m, in the plane) between two lying burgers.
        contact_s: Per burger, time (s) in contact with another burger.
        frames: ``(cook time s, label, qpos)`` at the film's rate (``fps``; none when 0).
    """

    def __init__(self, scene: Scene, watches: list[Watch], dt: float, fps: float = 0.0):
        self.scene, self.watches, self.dt, self.fps = scene, watches, dt, fps
        n = len(scene.burger_bodies)
        m = scene.model
        self.owner = np.full(m.ngeom, -1)
        for k, geoms in enumerate(scene.burger_geoms):
            self.owner[list(geoms)] = k
        self.active = np.zeros(n, bool)
        self.rest_pos = np.zeros((n, 3))
        self.knocked_m = np.zeros(n)
        self.contact_s = np.zeros(n)
        self.min_distance_m = np.inf
        self.frames: list = []
        self.next_frame = -np.inf
        self._open = np.zeros(n, bool)
        self._flags = [[False, False, 0.0, 0.0] for _ in range(n)]  # the last step's, per burger

    def placed(self, k: int) -> None:
        """Burger k was put into the cell (at rest): it lies there from now on."""
        self.active[k] = True
        self.rest_pos[k] = self.scene.data.xpos[self.scene.burger_bodies[k]]

    def removed(self, k: int) -> None:
        """Burger k was taken out of the cell."""
        self.active[k] = False

    def skipped_to(self, t: float) -> None:
        """An idle interval was skipped up to cook time ``t`` (s): the film jumps with it."""
        self.next_frame = max(self.next_frame, t)

    def sample(self, t: float, label: str) -> None:
        """Record the state at cook time ``t`` (s) (before the step), during motion ``label``."""
        sc, d = self.scene, self.scene.data
        bodies = np.asarray(sc.burger_bodies)
        open_now = np.zeros(len(bodies), bool)
        for w in self.watches:
            if w.t0 - 1e-9 <= t <= w.t1 + 1e-9:
                open_now[w.burger] = True
        for k in np.flatnonzero(self._open & ~open_now & self.active):  # a window closed
            self.rest_pos[k] = d.xpos[bodies[k]]
        self._open = open_now
        lying = self.active & ~open_now
        pos = d.xpos[bodies]
        if lying.any():
            moved = np.linalg.norm(pos[lying] - self.rest_pos[lying], axis=1)
            self.knocked_m[lying] = np.maximum(self.knocked_m[lying], moved)
        if lying.sum() > 1:
            p = pos[lying, :2]
            dist = np.linalg.norm(p[:, None] - p[None], axis=2)
            self.min_distance_m = min(self.min_distance_m,
                                      float(dist[np.triu_indices(len(p), 1)].min()))
        flags = self._contacts()
        blade_p, blade_r = sc.blade_pose()
        for w in self.watches:
            if w.t0 - 1e-9 <= t <= w.t1 + 1e-9:
                k, s = w.burger, w.samples
                s["t"].append(t)
                s["bp"].append(pos[k].copy())
                s["br"].append(d.xmat[bodies[k]].reshape(3, 3).copy())
                s["sp"].append(blade_p)
                s["sr"].append(blade_r)
                for key, val in zip(("ts", "tg", "fs", "fg"), flags[k]):
                    s[key].append(val)
        if self.fps > 0 and t >= self.next_frame - 1e-9:
            self.frames.append((t, label, d.qpos.copy()))
            self.next_frame = max(self.next_frame + 1.0 / self.fps, t)

    def _contacts(self) -> list:
        """Per burger ``[touch blade, touch grill, blade force N, grill force N]`` of the last
        step's contacts; burger–burger contact time accumulated. A sleeping burger is not in
        MuJoCo's contact list: it lies as it fell asleep, so its flags are the previous
        step's (as :class:`~flipkit.simulation.trace.BurgerTrace` keeps them)."""
        sc, g = self.scene, self.scene.geoms
        awake = sc.data.body_awake[np.asarray(sc.burger_bodies)]
        out = [[False, False, 0.0, 0.0] if awake[k] else list(self._flags[k])
               for k in range(len(sc.burger_bodies))]
        touching = set()
        for a, b, force in sc.contacts():
            ka, kb = self.owner[a], self.owner[b]
            if ka >= 0 and kb >= 0:
                touching.update((int(ka), int(kb)))
                continue
            k, other = (ka, b) if ka >= 0 else (kb, a)
            if k < 0 or other not in (g["blade"], g["grill"]):
                continue
            j = 0 if other == g["blade"] else 1
            out[k][j] = True
            out[k][j + 2] += force
        for k in touching:
            self.contact_s[k] += self.dt
        self._flags = out
        return out


__all__ = ["CookRecorder", "Watch"]
