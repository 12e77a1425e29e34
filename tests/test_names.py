"""Solver and execution-mode names are defined once (flipkit.solvers.names,
flipkit.simulation.modes); every other list of them must agree."""

from flipkit.simulation.modes import FEEDFORWARD, MODES, POSITION
from flipkit.solvers.names import EXACT_RESULT_NAMES, EXACT_SOLVERS, NLP_SOLVERS, SOLVERS


def test_solver_names():
    assert SOLVERS == ("sqp", "ipopt", "auto")
    assert NLP_SOLVERS == SOLVERS[:2]
    assert tuple(EXACT_RESULT_NAMES) == EXACT_SOLVERS
    assert not set(EXACT_RESULT_NAMES.values()) & set(NLP_SOLVERS)  # results tell them apart


def solver_options() -> dict:
    """The choices of every sub-command's ``--solver``, by the sub-command's words."""
    import argparse

    from flipkit.cli import build_parser

    out = {}

    def walk(parser, words):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    walk(sub, (*words, name))
            elif "--solver" in action.option_strings:
                out[words] = tuple(action.choices)

    walk(build_parser(), ())
    return out


def test_the_planner_and_the_command_line_accept_the_same_solvers():
    from flipkit.planning.planners.chain import SOLVERS as PLANNER_SOLVERS

    options = solver_options()
    assert {("plan", "flip"), ("plan", "serve"), ("validate",), ("schedule",),
            ("compare-ik",)} <= set(options)
    assert PLANNER_SOLVERS is SOLVERS
    assert all(choices == SOLVERS for choices in options.values()), options


def test_exact_solver_names():
    from flipkit.experiments.speed import TRANSLATE_SOLVERS
    from flipkit.solvers import exact

    assert exact.EXACT_SOLVERS is EXACT_SOLVERS
    assert set(TRANSLATE_SOLVERS) == {*NLP_SOLVERS, *EXACT_RESULT_NAMES.values()}


def test_execution_modes():
    from flipkit.cli.animate import MODES as CLI_MODES
    from flipkit.simulation import execute

    assert MODES == (FEEDFORWARD, POSITION) == ("feedforward", "position")
    assert execute.MODES is MODES and CLI_MODES == MODES


def test_the_command_line_offers_every_named_location_set():
    from flipkit.cli.common import LOCATION_SET_CHOICES
    from flipkit.config import LOCATION_SETS, MORE_LOCATIONS, TABLE1_LOCATIONS, CellConfig
    from flipkit.behaviors.targets import check_location

    assert LOCATION_SET_CHOICES == tuple(LOCATION_SETS)
    assert LOCATION_SETS["table1"] is TABLE1_LOCATIONS
    assert not set(MORE_LOCATIONS) & set(TABLE1_LOCATIONS)  # "more" is beyond Table I
    for loc in MORE_LOCATIONS:
        check_location(CellConfig(), loc)  # on the grill
