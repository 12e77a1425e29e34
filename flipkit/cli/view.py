"""``flipkit view``: show a plan in the browser (MeshCat) — the arm, spatula, burger, grill,
table and the predicted landing, with a time slider and a play button (``docs/viewer.md``).

Without ``--html`` it serves the view from a MeshCat server on localhost, prints the URL,
opens a browser where there is a display (not with ``--no-browser``) and runs until Ctrl-C.
With ``--html`` it writes one self-contained page that opens offline.

Exit status: 0 shown or written; 2 refused, nothing written — one line on stderr: an
unreadable or malformed plan, a plan that is not solved or fails ``flipkit verify``, an
output that is not a writable ``.html`` file or is the plan, no MeshCat server.
"""

from __future__ import annotations

import argparse

from flipkit.cli.common import deferred, precheck_plan
from flipkit.fileio import check_output

MESHES = ("collision", "visual")  # flipkit.viz.viewer.MESHES (checked in tests)


def register(subparsers) -> None:
    """Add the ``view`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "view", help="show a plan in the browser (MeshCat): arm, burger, cell, landing; "
                     "time slider and play",
        description="Verify the plan (as flipkit verify; exit 2 if it fails), then show the "
                    "arm, spatula, burger, grill, table and the predicted landing in a browser, "
                    "animated over the plan's time (MeshCat: Open Controls > Animations).")
    parser.add_argument("plan", metavar="PLAN.json", help="a solved plan file (any behaviour)")
    parser.add_argument("--html", metavar="OUT.html",
                        help="write one self-contained page (opens offline) instead of serving")
    parser.add_argument("--meshes", choices=MESHES, default="collision",
                        help="the arm's URDF meshes: collision (STL, 0.3 MB, default) or visual "
                             "(detailed Collada, 9 MB)")
    parser.add_argument("--no-browser", action="store_true",
                        help="serve without opening a browser (print the URL only)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the output and the file cheaply, then verify, draw and write or serve
    (:mod:`flipkit.cli.commands.view`)."""
    if args.html:
        check_output(args.html, "--html", (".html",), inputs=[args.plan])
    precheck_plan(args.plan)
    return deferred("view")(args)
