"""Rendering of a simulated execution: a GIF or MP4 of the run, and a filmstrip of key frames.

Frames are rendered offscreen with :class:`mujoco.Renderer` from the recorded MuJoCo state of
an :class:`~flipkit.simulation.execute.Execution` (``qpos`` per controller sample). Offscreen OpenGL
needs a backend chosen before MuJoCo is imported: ``MUJOCO_GL`` defaults to ``osmesa``
(software rendering; Debian package ``libosmesa6``) when unset, set at import of this module
— import it (or run ``flipkit animate``) before anything imports ``mujoco``.

GIFs are written with Pillow. MP4 needs an ffmpeg writer (``imageio-ffmpeg``), which is not
in ``environment.lock``: asking for ``.mp4`` without it raises a one-line error naming the
package.
"""

from __future__ import annotations

import importlib
import importlib.util
import os

os.environ.setdefault("MUJOCO_GL", "osmesa")

from pathlib import Path  # noqa: E402

import matplotlib  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from PIL import Image  # noqa: E402
from tqdm import tqdm  # noqa: E402

from flipkit.behaviors.library import PICKUP_AND_FLIP  # noqa: E402
from flipkit.errors import FlipkitError, InvalidChoiceError  # noqa: E402

FORMATS = (".gif", ".mp4")
CAMERA = {"lookat": (0.68, -0.15, 0.15), "distance": 1.1, "azimuth": 150.0, "elevation": -25.0}


def _camera() -> mujoco.MjvCamera:
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = CAMERA["lookat"]
    cam.distance, cam.azimuth, cam.elevation = (CAMERA[k] for k in
                                                ("distance", "azimuth", "elevation"))
    return cam


def _renderer(model, width: int, height: int) -> mujoco.Renderer:
    if not (isinstance(width, int) and isinstance(height, int) and 16 <= width <= 1280
            and 16 <= height <= 960):
        raise FlipkitError(f"frame size must be 16..1280 x 16..960 pixels, got {width}x{height}")
    try:
        return mujoco.Renderer(model, height, width)
    except Exception as exc:  # no GL backend: one line, with the remedy
        raise FlipkitError(f"offscreen rendering unavailable ({exc}); install libosmesa6 "
                           f"(MUJOCO_GL={os.environ.get('MUJOCO_GL')})") from None


def frame_indices(t: np.ndarray, fps: float) -> np.ndarray:
    """Indices of the first samples at or after the ticks of a ``fps`` clock over the run
    (times t in s)."""
    if not (np.isfinite(fps) and 0 < fps <= 120):
        raise FlipkitError(f"fps must be in (0, 120], got {fps!r}")
    clock = np.arange(t[0], t[-1] + 1e-9, 1.0 / fps)
    return np.unique(np.clip(np.searchsorted(t, clock - 1e-9), 0, len(t) - 1))


SPOT_RADIUS = 0.05  # m: the paper's landing tolerance (5 cm), drawn about the target


def _landing_spot(execution):
    """(x, y, z) of the executed plan's landing target on the grill surface, or None."""
    plan = getattr(execution, "plan", None)
    flip = plan.step("release") if plan else None
    if flip is None or not flip.landing:
        return None
    x, y = flip.landing["target"]
    return np.array([x, y, execution.run.grill_height + 0.0005])


def _mark_spot(scene, spot) -> None:
    """A translucent red disc of :data:`SPOT_RADIUS` at the landing target (visual only)."""
    if scene.ngeom >= scene.maxgeom:
        return
    mujoco.mjv_initGeom(scene.geoms[scene.ngeom], mujoco.mjtGeom.mjGEOM_CYLINDER,
                        np.array([SPOT_RADIUS, 0.0005, 0.0]), spot,
                        np.eye(3).ravel(), np.array([0.9, 0.1, 0.1, 0.45], np.float32))
    scene.ngeom += 1


def render_states(model, qpos, width: int = 480, height: int = 360, camera=None,
                  spot=None, progress: bool = False) -> list:
    """Rendered RGB frames (height×width×3 uint8) of the MuJoCo states ``qpos`` (rows) of
    ``model``, seen from ``camera`` (a :class:`mujoco.MjvCamera`; default the package's view
    of the grill), with a translucent 5 cm disc at ``spot`` (x, y, z) (m) if given."""
    d = mujoco.MjData(model)
    cam, frames = camera or _camera(), []
    renderer = _renderer(model, width, height)
    try:
        it = tqdm(qpos, desc="frames", unit="frame") if progress else qpos
        for row in it:
            d.qpos[:] = row
            mujoco.mj_forward(model, d)
            renderer.update_scene(d, camera=cam)
            if spot is not None:
                _mark_spot(renderer.scene, spot)
            frames.append(renderer.render().copy())
    finally:
        renderer.close()
    return frames


def render(execution, indices, width: int = 480, height: int = 360, progress: bool = False):
    """Rendered RGB frames (height×width×3 uint8) of the samples ``indices`` of a run, with the
    landing target marked by a translucent 5 cm disc."""
    return render_states(execution.scene.model, [execution.qpos[k] for k in indices], width,
                         height, spot=_landing_spot(execution), progress=progress)


def write_animation(execution, out, fps: float = 30.0, width: int = 480, height: int = 360,
                    progress: bool = False) -> Path:
    """Render the run at ``fps`` into ``out`` (``.gif`` or ``.mp4``), in real time.

    Raises:
        InvalidChoiceError: Unknown extension. FlipkitError: No writer or GL backend, or the
            file cannot be written.
    """
    out = Path(out)
    check_writer(out)
    frames = render(execution, frame_indices(execution.run.t, fps), width, height, progress)
    return write_frames(frames, out, fps)


def check_writer(out) -> str:
    """The extension of ``out`` (``.gif`` or ``.mp4``) once a writer for it is installed.

    Raises:
        InvalidChoiceError: Unknown extension. FlipkitError: ``.mp4`` without imageio-ffmpeg.
    """
    ext = Path(out).suffix.lower()
    if ext not in FORMATS:
        raise InvalidChoiceError("animation format", ext or Path(out).name, FORMATS)
    if ext == ".mp4" and importlib.util.find_spec("imageio_ffmpeg") is None:
        raise FlipkitError("MP4 needs imageio-ffmpeg, which is not installed (not in "
                           "environment.lock); write a .gif instead")
    return ext


def write_frames(frames, out, fps: float) -> Path:
    """Write RGB frames (height×width×3 uint8, all one size) to ``out`` (``.gif`` or ``.mp4``)
    at ``fps``.

    Raises:
        InvalidChoiceError, FlipkitError: As :func:`check_writer`; the file cannot be written.
    """
    out = Path(out)
    ext = check_writer(out)
    try:
        if ext == ".gif":
            imgs = [Image.fromarray(f) for f in frames]
            imgs[0].save(out, save_all=True, append_images=imgs[1:], loop=0,
                         duration=int(round(1000 / fps)))
        else:
            writer = importlib.import_module("imageio_ffmpeg")  # optional: only .mp4 needs it
            height, width = frames[0].shape[:2]
            w = writer.write_frames(str(out), (width, height), fps=fps)
            w.send(None)
            for f in frames:
                w.send(np.ascontiguousarray(f))
            w.close()
    except OSError as exc:
        raise FlipkitError(f"cannot write {out}: {exc.strerror or exc}") from None
    return out


def key_frames(execution) -> dict:
    """Sample indices of the flip's key moments (``None`` where one did not happen).

    ``release``: last burger-blade contact during the flip segment; ``landing``: first
    burger-grill contact after it; ``mid_flight``: the sample halfway in time between them
    (a flipped burger often falls from the release on, so its highest point is the release).
    """
    run, (t0, t1) = execution.run, execution.bounds[PICKUP_AND_FLIP.step("release").name]
    in_flip = np.flatnonzero((run.t >= t0) & (run.t <= t1) & run.touch_spatula)
    out = {"release": None, "mid_flight": None, "landing": None}
    if in_flip.size == 0:
        return out
    out["release"] = r = int(in_flip[-1])
    hit = np.flatnonzero(run.touch_grill[r + 1:])
    if hit.size:
        out["landing"] = land = r + 1 + int(hit[0])
        out["mid_flight"] = int(np.searchsorted(run.t, 0.5 * (run.t[r] + run.t[land])))
    return out


def filmstrip_figure(execution, width: int = 320, height: int = 240, panel_width: float = 3.2,
                     fontsize: float = 9):
    """A matplotlib figure of the key frames (:func:`key_frames`) side by side, titled with
    their times; the end of the run stands in for a key moment that did not happen.

    Args:
        execution: An :class:`~flipkit.simulation.execute.Execution`.
        width, height: Rendered frame size (pixels).
        panel_width: Width of one panel (in); the height follows the frame's aspect.
        fontsize: Title size (pt).

    Returns:
        ``(fig, times)``: the figure and ``{key: time (s) or None}`` of the moments shown.
    """
    import matplotlib.pyplot as plt  # pyplot picks a backend: write_filmstrip chooses Agg first

    keys = key_frames(execution)
    last = len(execution.run.t) - 1
    idx = [last if k is None else k for k in keys.values()]
    frames = render(execution, idx, width, height)
    fig, axes = plt.subplots(1, len(frames), figsize=(
        panel_width * len(frames), panel_width * height / width + 0.35))
    for ax, (name, k), f, i in zip(axes, keys.items(), frames, idx):
        ax.imshow(f)
        ax.set_axis_off()
        what = "not reached: end" if k is None else name.replace("_", "-")
        ax.set_title(f"{what}, t = {execution.run.t[i]:.2f} s", fontsize=fontsize)
    fig.tight_layout()
    times = {name: None if k is None else float(execution.run.t[k]) for name, k in keys.items()}
    return fig, times


def write_filmstrip(execution, out, width: int = 320, height: int = 240) -> Path:
    """A PNG of the key frames (:func:`filmstrip_figure`) side by side."""
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after the backend is chosen

    fig, _ = filmstrip_figure(execution, width, height)
    try:
        fig.savefig(out, dpi=100)
    except OSError as exc:
        raise FlipkitError(f"cannot write {out}: {exc.strerror or exc}") from None
    finally:
        plt.close(fig)
    return Path(out)


__all__ = ["FORMATS", "check_writer", "frame_indices", "render", "render_states",
           "write_animation", "write_frames", "key_frames",
           "filmstrip_figure", "write_filmstrip"]
