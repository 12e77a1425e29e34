"""The film of a simulated cook: the frames kept while the cell was stepped (the motions and
their settling; idle intervals cut), seen from above the grill and the side table, with the
cook clock and the motion under way written in the corner.

Rendering is offscreen (:mod:`flipkit.simulation.animate`, which sets ``MUJOCO_GL`` to
``osmesa`` when unset: import this module before anything imports MuJoCo).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
from PIL import Image, ImageDraw

from flipkit.errors import FlipkitError
from flipkit.simulation.animate import check_writer, render_states, write_frames

FILM_FPS = 15.0  # frames per second of cook time, and of the film (real time)
FILM_SIZE = (320, 240)  # pixels
# A view of the grill (x 0.60-0.88, y -0.50-0.16 m) and the side table (x 0.20-0.55,
# y 0.45-0.80 m) from beside the grill, away from the arm.
FILM_CAMERA = {"lookat": (0.55, -0.05, 0.1), "distance": 1.9, "azimuth": 200.0,
               "elevation": -40.0}


def film_camera() -> mujoco.MjvCamera:
    """The free camera of :data:`FILM_CAMERA`."""
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = FILM_CAMERA["lookat"]
    cam.distance = FILM_CAMERA["distance"]
    cam.azimuth, cam.elevation = FILM_CAMERA["azimuth"], FILM_CAMERA["elevation"]
    return cam


def _caption(frame: np.ndarray, text: str) -> np.ndarray:
    """``frame`` with ``text`` in black on white in its top-left corner."""
    img = Image.fromarray(frame)
    draw = ImageDraw.Draw(img)
    box = draw.textbbox((4, 4), text)
    draw.rectangle((box[0] - 2, box[1] - 2, box[2] + 2, box[3] + 2), fill=(255, 255, 255))
    draw.text((4, 4), text, fill=(0, 0, 0))
    return np.asarray(img)


def write_cook_film(simulation, out, fps: float = FILM_FPS, size=FILM_SIZE,
                    progress: bool = False) -> Path:
    """Render the frames of a :class:`~flipkit.simulation.cook.CookSimulation` (simulated
    with ``film_fps`` = ``fps``) into ``out`` (``.gif`` or ``.mp4``).

    Raises:
        FlipkitError: No frames (simulated without ``film_fps``), no writer or GL backend, or
            the file cannot be written. InvalidChoiceError: Unknown extension.
    """
    check_writer(out)
    if not simulation.frames:
        raise FlipkitError("the simulation kept no frames: simulate with film_fps > 0")
    width, height = size
    frames = render_states(simulation.scene.model, [q for _, _, q in simulation.frames], width,
                           height, camera=film_camera(), progress=progress)
    frames = [_caption(f, f"t = {t:6.2f} s  {label}")
              for f, (t, label, _) in zip(frames, simulation.frames)]
    return write_frames(frames, out, fps)


__all__ = ["FILM_CAMERA", "FILM_FPS", "FILM_SIZE", "film_camera", "write_cook_film"]
