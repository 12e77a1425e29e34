"""The per-step record of one burger's execution: poses, contact flags and contact forces.

:func:`flipkit.simulation.execute.execute_plan` calls :class:`BurgerTrace` once per control
step, thousands of times a trial, so it writes into arrays allocated once and reads MuJoCo's
buffers without intermediate copies. What it records at step k is the state the last
``mj_step`` computed its forces at (MuJoCo's kinematics and contacts of the step's start),
as :class:`~flipkit.simulation.run.BurgerRun` expects.
"""

from __future__ import annotations

import numpy as np

from flipkit.simulation.scene import Scene

__all__ = ["BurgerTrace"]


class BurgerTrace:
    """Arrays of N samples, filled by calling the trace with the sample index.

    Attributes:
        bp, br: The burger's position (m) and rotation matrix, (N, 3) and (N, 3, 3).
        sp, sr: The spatula frame's, the same shapes.
        ts, tg: Burger–blade and burger–grill contact flags (N,).
        fs, fg, fbg: Summed normal forces (N) of the burger–blade, burger–grill and
            blade–grill contacts (N,). fbt: The blade–table contacts' (N,).

    Args:
        scene: The scene whose ``data`` is read. n: Samples to hold.
    """

    def __init__(self, scene: Scene, n: int):
        self.scene, self.data = scene, scene.data
        self.burger_body = int(scene.model.geom_bodyid[scene.geoms["burger"]])
        self.site = int(scene.blade_site)
        self.bp, self.sp = np.zeros((n, 3)), np.zeros((n, 3))
        self._br, self._sr = np.zeros((n, 9)), np.zeros((n, 9))
        self.ts, self.tg = np.zeros(n, bool), np.zeros(n, bool)
        self.fs, self.fg, self.fbg = np.zeros(n), np.zeros(n), np.zeros(n)
        self.fbt = np.zeros(n)
        g, ngeom = scene.geoms, scene.model.ngeom
        # the slot of each geom pair: 0 not recorded, 1 blade-grill, 2 burger-blade,
        # 3 burger-grill (every strip of the patty is the burger), 4 blade-table
        self._slot = np.zeros((ngeom, ngeom), np.intp)
        pairs = [(g["blade"], g["grill"], 1), (g["blade"], g["table"], 4)]
        for part in scene.burger_geoms[0]:
            pairs += [(part, g["blade"], 2), (part, g["grill"], 3)]
        for a, b, slot in pairs:
            self._slot[a, b] = self._slot[b, a] = slot
        self.sleeps = scene.sleeps

    @property
    def br(self) -> np.ndarray:
        return self._br.reshape(-1, 3, 3)

    @property
    def sr(self) -> np.ndarray:
        return self._sr.reshape(-1, 3, 3)

    def __call__(self, k: int) -> None:
        """Record sample k from the scene's current data; forces summed in contact order.

        A sleeping burger (:class:`~flipkit.simulation.scene.Scene` ``sleeps``) is not in
        MuJoCo's contact list: it lies as it fell asleep, so its flags and forces are those
        of sample k − 1.
        """
        d, b, s = self.data, self.burger_body, self.site
        self.sp[k], self._sr[k] = d.site_xpos[s], d.site_xmat[s]
        self.bp[k], self._br[k] = d.xpos[b], d.xmat[b]
        if d.ncon:
            pairs, force = self.scene.contact_arrays()
            slot = self._slot[pairs[:, 0], pairs[:, 1]]
            sums = np.bincount(slot, weights=force, minlength=5)
            seen = np.bincount(slot, minlength=5)
            self.fbg[k], self.fs[k], self.fg[k], self.fbt[k] = sums[1:]
            self.ts[k], self.tg[k] = seen[2] > 0, seen[3] > 0
        if k and self.sleeps and not d.body_awake[b]:
            self.ts[k], self.tg[k] = self.ts[k - 1], self.tg[k - 1]
            self.fs[k], self.fg[k] = self.fs[k - 1], self.fg[k - 1]

    def trimmed(self, n: int) -> "BurgerTrace":
        """This trace cut to its first n samples (views, not copies)."""
        for name in ("bp", "sp", "_br", "_sr", "ts", "tg", "fs", "fg", "fbg", "fbt"):
            setattr(self, name, getattr(self, name)[:n])
        return self
