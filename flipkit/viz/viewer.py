"""An interactive view of a verified plan in the browser: MeshCat, with a time slider and a
play button (``flipkit view``, ``docs/viewer.md``).

What is drawn (every node under ``/flipkit``): the UR10 by its URDF's collision meshes (STL,
the shapes the clearance check uses, 0.3 MB; ``meshes="visual"`` loads the URDF's detailed
Collada meshes instead, 9 MB) placed by pinocchio's :class:`MeshcatVisualizer`; the spatula
as :class:`~flipkit.model.collision.ArmShapes` has it (the blade a box, the handle a
cylinder); the burger as a cylinder on its pose of :mod:`flipkit.viz.motion`; the cell and
the predicted landing of :mod:`flipkit.viz.scene`. The motion is one MeshCat ``Animation``
(a key per frame at :data:`~flipkit.viz.motion.FPS`, real time), driven from the viewer's
controls: Animations > default > play, pause, reset and the ``time`` slider (s).

MeshCat draws through a server process (:mod:`flipkit.viz.server`); :func:`static_html`
starts one, draws, asks it for the page as one self-contained HTML file (three.js and every
command inlined, no URL fetched) and stops it. Only plans that pass ``flipkit verify`` are drawn
(:func:`~flipkit.planning.plans.verify.require_verified`).
"""

from __future__ import annotations

import html

import meshcat
import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
from IPython.display import HTML
from meshcat.animation import Animation
from pinocchio.visualize import MeshcatVisualizer

from flipkit.config.urdf import robots_dir
from flipkit.errors import InvalidChoiceError
from flipkit.fileio import write_text
from flipkit.model.collision import BLADE, HANDLE, ArmShapes
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify import require_verified
from flipkit.viz.motion import FPS, Motion, plan_motion
from flipkit.viz.server import close_visualizer, open_visualizer, page
from flipkit.viz.scene import COLORS, ROOT, cylinder, draw_cell, draw_landing, material

MESHES = {"collision": pin.COLLISION, "visual": pin.VISUAL}  # the URDF's meshes for the arm


def _arm(plan: Plan, cell, vis, meshes: str):
    """The arm's meshes loaded under ``/flipkit/arm``; (robot, geometry model, viewer)."""
    robot = plan.robot_for(plan.segments[0], cell)
    dirs = [str(robots_dir().parent.parent)] if robots_dir() is not None else []
    geom = pin.buildGeomFromUrdf(robot.model, robot.urdf, MESHES[meshes], package_dirs=dirs)
    base = pin.SE3(np.asarray(cell.robot.base_in_world, float))
    for go in geom.geometryObjects:  # the base link hangs from the world: put it on the base
        if go.parentJoint == 0:
            go.placement = base * go.placement
    viewer = MeshcatVisualizer(robot.model, None, geom)
    viewer.initViewer(viewer=vis)
    color = np.array([(COLORS["arm"] >> s & 0xFF) / 255 for s in (16, 8, 0)] + [1.0])
    viewer.loadViewerModel(rootNodeName=f"{ROOT}/arm",
                           visual_color=color if meshes == "collision" else None)
    return robot, geom, viewer


def view_plan(plan: Plan, vis: meshcat.Visualizer | None = None, *, where: str = "plan",
              fps: float = FPS, meshes: str = "collision", play: bool = True):
    """Draw ``plan`` into ``vis`` (default: :func:`open_visualizer`) and return it.

    In JupyterLab, ``vis.jupyter_cell()`` shows the live view (the server runs in the
    kernel); :func:`inline` shows a self-contained copy without a server.

    Args:
        plan: A plan that passes ``flipkit verify``. vis: The visualizer to draw into.
        where: How messages name the plan (its file).
        fps: Animation keys per second (frames/s, in [1, 200]).
        meshes: The arm's URDF meshes, ``"collision"`` (STL) or ``"visual"`` (Collada).
        play: Play once when the page opens, then rest at t = 0 (MeshCat's time slider
            moves the view only once the animation has played: with ``False``, press play
            first).

    Raises:
        VerificationError: The plan is not solved or fails verification (one line).
        InvalidChoiceError: Unknown ``meshes``. ConfigError: ``fps`` out of range.
        ViewerError: No MeshCat server.
    """
    motion = _checked(plan, where, fps, meshes)
    vis = vis if vis is not None else open_visualizer()
    _draw(plan, motion, vis, meshes, play)
    return vis


def _checked(plan: Plan, where: str, fps: float, meshes: str) -> Motion:
    """The plan's motion, once the options are valid and the plan is verified."""
    if meshes not in MESHES:
        raise InvalidChoiceError("arm meshes", meshes, MESHES)
    require_verified(plan, where)
    return plan_motion(plan, fps)


def _draw(plan: Plan, motion: Motion, vis: meshcat.Visualizer, meshes: str, play: bool) -> None:
    """The cell, the landing, the arm, spatula and burger and their animation, into ``vis``."""
    cell = plan.cell()
    draw_cell(vis, cell)
    draw_landing(vis, motion.landing, cell.burger.diameter)
    robot, geom, viewer = _arm(plan, cell, vis, meshes)
    spatula = [s for s in ArmShapes(robot, cell).shapes if s.name in (BLADE, HANDLE)]
    for s in spatula:
        node = vis[f"{ROOT}/spatula/{s.name}"]
        if s.name == BLADE:
            node["shape"].set_object(mg.Box(2 * s.geometry.halfSide), material("blade"))
        else:
            cylinder(node, 2 * s.geometry.halfLength, s.geometry.radius, material("handle"))
    if motion.burger is not None:
        b = cell.burger
        cylinder(vis[f"{ROOT}/burger"], b.thickness, b.diameter / 2, material("burger"))
    anim = Animation(default_framerate=motion.fps)
    data, gdata = robot.model.createData(), geom.createData()
    for k, q in enumerate(motion.q):
        pin.forwardKinematics(robot.model, data, q)
        pin.updateGeometryPlacements(robot.model, data, geom, gdata)
        poses = {viewer.getViewerNodeName(go, pin.GeometryType.VISUAL): gdata.oMg[i].homogeneous
                 for i, go in enumerate(geom.geometryObjects)}
        poses.update({f"{ROOT}/spatula/{s.name}": (data.oMi[s.joint] * s.placement).homogeneous
                      for s in spatula})
        if motion.burger is not None:
            poses[f"{ROOT}/burger"] = motion.burger[k]
        with anim.at_frame(vis, k) as frame:
            for name, pose in poses.items():
                frame[name].set_transform(pose)
                if k == 0:  # the first pose also as the nodes' own, for a page not yet played
                    vis[name].set_transform(pose)
    vis.set_animation(anim, play=play)


def static_html(plan: Plan, *, where: str = "plan", fps: float = FPS,
                meshes: str = "collision", play: bool = True) -> str:
    """The view of ``plan`` as one self-contained HTML page (it opens offline): a server is
    started for the drawing and stopped. Arguments and errors: as :func:`view_plan`."""
    motion = _checked(plan, where, fps, meshes)
    vis = open_visualizer()
    try:
        _draw(plan, motion, vis, meshes, play)
        return page(vis)
    finally:
        close_visualizer(vis)


def write_html(plan: Plan, path, **options) -> None:
    """Write :func:`static_html` to ``path`` (atomically). ``options``: as :func:`view_plan`."""
    write_text(path, static_html(plan, **options))


def inline(plan: Plan, height: int = 480, **options) -> HTML:
    """The view for a notebook cell: :func:`static_html` in an iframe ``height`` pixels high,
    which needs no server and is kept in the saved notebook."""
    page = html.escape(static_html(plan, **options), quote=True)
    return HTML(f'<div style="height: {int(height)}px; resize: vertical; overflow: hidden">'
                f'<iframe srcdoc="{page}" style="width: 100%; height: 100%; border: none">'
                '</iframe></div>')
