"""``flipkit view`` once its arguments passed :mod:`flipkit.cli.view`: load, verify and draw
the plan, then write the page or serve it until Ctrl-C."""

from __future__ import annotations

import argparse
import os
import sys
import webbrowser

from flipkit.planning.plans.plan_file import Plan
from flipkit.viz.server import close_visualizer, wait
from flipkit.viz.viewer import view_plan, write_html


def has_display() -> bool:
    """Whether a graphical browser can be opened here (a text browser could not show the
    view and would hold the terminal)."""
    return sys.platform in ("darwin", "win32") or bool(
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def run(args: argparse.Namespace) -> int:
    """Write the page (``--html``), or serve the view and wait for Ctrl-C."""
    plan = Plan.load(args.plan)
    total = plan.duration
    if args.html:
        write_html(plan, args.html, where=args.plan, meshes=args.meshes)
        print(f"flipkit view: wrote {args.html} ({plan.behavior} plan, {total:.2f} s; "
              "a self-contained page, open it in a browser)")
        return 0
    vis = view_plan(plan, where=args.plan, meshes=args.meshes)
    try:  # SIGTERM ends the view as Ctrl-C does (flipkit.cli.signals), the server stopped
        print(f"flipkit view: {plan.behavior} plan, {total:.2f} s, at {vis.url()} "
              "(Ctrl-C to stop)", flush=True)
        if not args.no_browser and has_display():
            webbrowser.open(vis.url(), new=2)
        wait(vis)
    finally:
        close_visualizer(vis)
    return 0
