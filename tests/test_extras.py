"""A command whose extra is not installed says which extra, in one line, and exits 1
(:mod:`flipkit.extras`); a module missing from the core is a broken install and is raised."""

from __future__ import annotations

from pathlib import Path

import pytest

import flipkit
from flipkit import cli
from flipkit.cli import figures as figures_cli
from flipkit.extras import COMMAND_EXTRAS, EXTRAS, is_core, missing_extra_message

REPO = Path(flipkit.__file__).resolve().parents[1]


def test_the_message_names_the_extra_of_the_missing_module():
    assert missing_extra_message("animate", "mujoco") == (
        "flipkit animate needs the 'sim' extra (no module named 'mujoco'): "
        "pip install 'flipkit[sim]'")
    # matplotlib is in sim and lab: the command's own extra is named
    assert "'lab' extra" in missing_extra_message("figures", "matplotlib.pyplot")
    assert "'sim' extra" in missing_extra_message("animate", "matplotlib")
    # schedule needs kitchen and sim: the one that installs the module
    assert "'kitchen' extra" in missing_extra_message("schedule", "ortools")
    assert "'sim' extra" in missing_extra_message("schedule", "mujoco")
    # a sweep on a Dask scheduler, from a core command
    assert "'lab' extra" in missing_extra_message("compare-ik", "distributed")
    # a package an extra brings along: the command's extra
    assert "'lab' extra" in missing_extra_message("figures", "cycler")


def test_a_core_module_missing_is_no_extras_fault():
    assert missing_extra_message("plan", "cvxpy") is None
    assert missing_extra_message("verify", None) is None
    assert missing_extra_message("figures", "") is None
    assert missing_extra_message("figures", "flipkit.figures.nowhere") is None


def test_every_command_extra_is_an_extra_and_core_commands_have_none():
    assert {e for extras in COMMAND_EXTRAS.values() for e in extras} <= set(EXTRAS)
    for command in cli.COMMANDS:
        work = f"flipkit.cli.commands.{command.replace('-', '_')}"
        assert is_core(work) == (command not in COMMAND_EXTRAS), command


def test_the_command_line_reports_a_missing_extra_in_one_line(tmp_path, monkeypatch, capsys):
    def no_papermill(**kwargs):
        raise ModuleNotFoundError("No module named 'papermill'", name="papermill")

    monkeypatch.setattr(figures_cli, "run_notebooks", no_papermill)
    argv = ["figures", "--only", "cell", "--out", str(tmp_path / "f"), "--notebooks",
            str(REPO / "notebooks")]
    assert cli.main(argv) == 1
    assert capsys.readouterr().err.splitlines() == [
        "flipkit: error: flipkit figures needs the 'lab' extra (no module named 'papermill'): "
        "pip install 'flipkit[lab]'"]

    def broken(**kwargs):
        raise ModuleNotFoundError("No module named 'flipkit.nowhere'", name="flipkit.nowhere")

    monkeypatch.setattr(figures_cli, "run_notebooks", broken)
    with pytest.raises(ModuleNotFoundError):
        cli.main(argv)


def test_figures_refuses_a_missing_notebooks_directory(tmp_path, capsys):
    argv = ["figures", "--only", "cell", "--out", str(tmp_path / "f"), "--notebooks",
            str(tmp_path / "nowhere")]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--notebooks" in err and "nowhere" in err
