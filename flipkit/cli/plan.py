"""``flipkit plan``: plan a translate, a pickup-and-flip, a serve to the table, or a batch of
burgers.

Exit status: 0 every plan is solved and passes :func:`~flipkit.planning.plans.verify.verify_plan`; 1 a plan
failed — one line ``flipkit: error: <segment>: <group> violated by <amount> (...)`` on
stderr per failed plan, and the plan file is still written, with ``"status": "failed"``, so
it can be inspected (``flipkit verify`` exits 1 on it, ``flipkit export`` refuses it without
``--force``); 2 bad input (non-finite numbers, a burger off the grill, a point out of reach,
a start configuration of the wrong size or outside the joint limits, a table spot off the
table, a malformed CSV) —
one line on stderr, nothing written. A plan file is never written as ``"solved"`` unless it
passed the check.

The numbers, the burgers and the outputs are checked here (:mod:`flipkit.cli.plan_inputs`)
before the planners are imported; the start configuration, against the arm's model, in
:mod:`flipkit.cli.commands.plan`.
"""

from __future__ import annotations

import argparse

from flipkit.behaviors.targets import check_table_spot
from flipkit.cli.common import MAX_WORKERS, check_int, deferred
from flipkit.cli.plan_inputs import (batch_locations, burger, burger_diameter, heading, numbers,
                                     r_land, yaw)
from flipkit.config import CellConfig
from flipkit.errors import UnreachableError
from flipkit.fileio import check_output, check_output_dir
from flipkit.planning.planners.inputs import check_atlas_file
from flipkit.solvers.names import SOLVERS

DESCRIPTION = (
    "Plan with joint-space direct collocation and check the plan independently. Exit 0: "
    "solved and verified. Exit 1: a plan failed; one line per failed plan on stderr, and the "
    "plan file is written with status 'failed' for inspection. Exit 2: bad input (non-finite "
    "numbers, burger off the grill, point out of reach, start configuration of the wrong "
    "size or outside the joint limits, a table spot off the table, malformed CSV); nothing "
    "is written.")


def register(subparsers) -> None:
    """Add the ``plan`` sub-command (``translate``, ``flip``, ``serve``, ``batch``) to the parser."""
    parser = subparsers.add_parser(
        "plan", help="plan a translate, a pickup-and-flip, a serve to the table, or a batch "
                            "of up to five flips",
        description=DESCRIPTION)
    sub = parser.add_subparsers(dest="plan_command", required=True, metavar="BEHAVIOR")

    def common(p, json_out=True):
        p.add_argument("--solver", choices=SOLVERS, default="auto",
                       help="NLP solver: auto (default: the SQP, then IPOPT where the SQP "
                            "fails), sqp (cvxpy/OSQP) or ipopt (CasADi)")
        if json_out:
            p.add_argument("--json", required=True, metavar="PLAN.json",
                           help="output plan file (flipkit-plan/2, .json; not an input)")

    t = sub.add_parser("translate", help="carry the burger flat from one point to another",
                       description="Translate the flat spatula (burger on it) between two "
                                   "blade-centre positions, at rest at both ends (eq. 9).")
    t.add_argument("--from", dest="start", nargs="+", required=True, metavar="X",
                   help="start position X Y Z (m); the start configuration is found by IK")
    t.add_argument("--to", dest="goal", nargs="+", required=True, metavar="X",
                   help="goal position X Y Z (m)")
    t.add_argument("--yaw", default="0", metavar="RAD", help="spatula heading o_z (rad), any finite number: wrapped to (-pi, pi]")
    common(t)
    t.set_defaults(run=run_translate)

    f = sub.add_parser("flip", help="pick up and flip one burger (five chained segments)",
                       description="Go to burger, scoop, pickup, flip and turn back "
                                   "(eqs. 22-27), chained by (29).")
    f.add_argument("--burger", nargs="+", required=True, metavar="X",
                   help="burger location X Y Z (m), on the grill (z = grill height, +-0.01 m)")
    f.add_argument("--start-q", nargs="+", metavar="Q",
                   help="start configuration Q1 .. Q6 (rad), default q_home; at rest, within "
                        "the joint limits, q3 and q5 on q_home's side of the elbow and wrist "
                        "singularities and 0.2 rad from them")
    f.add_argument("--land", nargs="+", metavar="X",
                   help="landing spot X Y (m) on the grill; default where the burger lies")
    f.add_argument("--r-land", default=None, metavar="M",
                   help="radius (m) of the landing disc about the spot, in [0.0001, 0.1] "
                        "(below 0.1 mm is within the landing's spread) "
                        "(default: the planner's R_LAND, which the package's atlas serves)")
    f.add_argument("--heading", default=None, metavar="DEG",
                   help="scoop heading (degrees from the world's +x, within +-60): the go to "
                        "burger, scoop, pickup and flip run along it; default: radially outward "
                        "from the arm's base, which the package's atlas serves")
    f.add_argument("--burger-diameter", default=None, metavar="M",
                   help="the burger's diameter (m) as the camera sees it, in [0.089, 0.127]; "
                        "default: the cell's 0.1 m burger, which the package's atlas serves "
                        "(another diameter plans from cold starts)")
    atlas_arguments(f)
    common(f)
    f.set_defaults(run=run_flip)

    s = sub.add_parser("serve", help="pick up one burger and put it on the side table",
                       description="Go to burger, scoop, pickup (eqs. 22-25), carry with the "
                                   "friction cone, place on the table by tilting the blade "
                                   "and withdrawing it, return home.")
    s.add_argument("--burger", nargs="+", required=True, metavar="X",
                   help="burger location X Y Z (m), on the grill (z = grill height, +-0.01 m)")
    s.add_argument("--table-spot", nargs="+", required=True, metavar="X",
                   help="where the burger should rest on the table, X Y (m)")
    s.add_argument("--start-q", nargs="+", metavar="Q",
                   help="start configuration Q1 .. Q6 (rad), default q_home; at rest, within "
                        "the joint limits, q3 and q5 on q_home's side of the elbow and wrist "
                        "singularities and 0.2 rad from them")
    s.add_argument("--heading", default=None, metavar="DEG",
                   help="scoop heading (degrees from the world's +x, within +-60): the go to "
                        "burger, scoop, pickup run along it; default: radially outward "
                        "from the arm's base, which the package's atlas serves")
    s.add_argument("--burger-diameter", default=None, metavar="M",
                   help="the burger's diameter (m) as the camera sees it, in [0.089, 0.127]; "
                        "default: the cell's 0.1 m burger, which the package's atlas serves "
                        "(another diameter plans from cold starts)")
    atlas_arguments(s, " (go to burger, scoop and pickup)")
    common(s)
    s.set_defaults(run=run_serve)

    b = sub.add_parser("batch", help="pick up and flip up to five burgers in a row",
                       description="Plan up to five burgers, each starting where the "
                                   "previous solved plan ended; write DIR/burger_<k>.json "
                                   "and DIR/summary.csv.")
    b.add_argument("--burgers", required=True, metavar="FILE.csv",
                   help="CSV with header x,y,z (or px,py,pz; in any order, no other "
                        "column), 1 to 5 rows, burgers one diameter apart; lines starting "
                        "with # skipped")
    b.add_argument("--out", required=True, metavar="DIR",
                   help="output directory (burger_<k>.json, summary.csv; not holding an "
                        "input of those names)")
    b.add_argument("--workers", type=int, default=None, metavar="K",
                   help="plan the burgers in K worker processes, in [1, 256] (default: the "
                        "CPU count; 1: one after another in this process)")
    b.add_argument("--no-progress", action="store_true", help="no progress bar")
    atlas_arguments(b)
    common(b, json_out=False)
    b.set_defaults(run=run_batch)


def atlas_arguments(parser: argparse.ArgumentParser, which: str = "") -> None:
    """``--atlas FILE`` and ``--no-atlas`` on ``parser``."""
    parser.add_argument("--atlas", metavar="FILE",
                        help=f"warm-start atlas (`flipkit atlas build`){which}; default: the "
                             "package's atlas when it serves these options, else cold starts")
    parser.add_argument("--no-atlas", action="store_true", help="cold starts (no atlas)")


# The cheap checks of each behaviour, then its planning (flipkit.cli.commands.plan): a
# refusal here never imports the planners.
def _json_out(args: argparse.Namespace) -> None:
    """``--json``: a writable ``.json`` file, not an input (the atlas)."""
    check_output(args.json, "--json", (".json",), inputs=[getattr(args, "atlas", None)])


def _atlas_file(args: argparse.Namespace) -> None:
    """``--atlas FILE``, unless ``--no-atlas``: readable and an ``.npz`` archive (whether it
    serves the plan's options is known once it is loaded)."""
    if args.atlas and not args.no_atlas:
        check_atlas_file(args.atlas)


def _start_q(values):
    """``--start-q``: six finite numbers, or ``None``; their limits and singularity sides
    are checked with the arm's model."""
    return None if values is None else numbers("--start-q", values, 6)


def run_translate(args: argparse.Namespace) -> int:
    """Check the output and the numbers, then plan."""
    _json_out(args)
    args.start, args.goal = numbers("--from", args.start, 3), numbers("--to", args.goal, 3)
    args.yaw = yaw(args.yaw)
    return deferred("plan", "run_translate")(args)


def run_flip(args: argparse.Namespace) -> int:
    """Check the output, the burger, the landing and the start's numbers, then plan."""
    _json_out(args)
    args.burger = burger(args.burger, CellConfig())
    args.land = None if args.land is None else numbers("--land", args.land, 2)
    args.r_land = None if args.r_land is None else r_land(args.r_land)
    args.start_q = _start_q(args.start_q)
    args.heading = heading(args.heading)
    args.burger_diameter = burger_diameter(args.burger_diameter)
    _atlas_file(args)
    return deferred("plan", "run_flip")(args)


def run_serve(args: argparse.Namespace) -> int:
    """Check the output, the burger, the table spot and the start's numbers, then plan."""
    _json_out(args)
    cell = CellConfig()
    args.burger = burger(args.burger, cell)
    args.table_spot = numbers("--table-spot", args.table_spot, 2)
    try:
        check_table_spot(cell, args.table_spot)
    except UnreachableError as exc:
        raise UnreachableError(f"--table-spot: {exc}") from None
    args.start_q = _start_q(args.start_q)
    args.heading = heading(args.heading)
    args.burger_diameter = burger_diameter(args.burger_diameter)
    _atlas_file(args)
    return deferred("plan", "run_serve")(args)


def run_batch(args: argparse.Namespace) -> int:
    """Check the workers, the CSV's burgers and the output directory, then plan."""
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    args.locations = batch_locations(args.burgers, CellConfig())
    names = [*(f"burger_{k}.json" for k in range(1, len(args.locations) + 1)), "summary.csv"]
    check_output_dir(args.out, "--out", inputs=[args.burgers, args.atlas], names=names)
    _atlas_file(args)
    return deferred("plan", "run_batch")(args)
