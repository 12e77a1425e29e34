"""The figure pipeline: saving, the notebook runner, the ``flipkit figures`` command and the
notebooks themselves (parameters cell, no outputs)."""

import json
import os
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import nbformat
import pytest

import flipkit
from flipkit import cli
from flipkit import figures
from flipkit.figures import execute
from flipkit.errors import InvalidChoiceError

REPO = Path(flipkit.__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("*.ipynb"))


def run_cli(argv, cwd):
    """``flipkit <argv>`` with ``cwd`` as the current directory (build/ goes there)."""
    here = os.getcwd()
    os.chdir(cwd)
    try:
        return cli.main(argv)
    finally:
        os.chdir(here)


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    work = tmp_path_factory.mktemp("figures")
    out = work / "figures"
    code = run_cli(["figures", "--quick", "--only", "cell", "--out", str(out), "--notebooks",
                    str(REPO / "notebooks")], work)
    return code, work, out


@pytest.mark.slow
def test_cell_figure_and_manifest(made):
    code, work, out = made
    assert code == 0
    for name in ("cell.pdf", "cell.png"):
        assert (out / name).stat().st_size > 1000
    assert (out / "cell.pdf").read_bytes().startswith(b"%PDF")
    assert (work / "build" / "notebooks" / "cell.ipynb").is_file()
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["flipkit"] and "git" in manifest
    entry = manifest["figures"]["cell"]
    assert entry["files"] == ["cell.pdf", "cell.png"]
    assert entry["notebook"] == "notebooks/cell.ipynb"
    assert entry["parameters"]["quick"] is True
    assert entry["inputs"]["hash"].startswith("sha256:") and entry["inputs"]["modules"] > 10
    assert len(entry["caption"]) > 40
    assert entry["numbers"]["n_locations"] == 10
    assert entry["numbers"]["spatula_home_clearance_m"] > 0.05  # spatula above the grill


@pytest.mark.slow
def test_second_run_is_reproducible(made):
    _, work, out = made
    first = json.loads((out / "manifest.json").read_text())
    pdf = (out / "cell.pdf").read_bytes()
    assert run_cli(["figures", "--quick", "--only", "cell", "--out", str(out), "--force",
                    "--notebooks", str(REPO / "notebooks")], work) == 0
    second = json.loads((out / "manifest.json").read_text())
    assert second == first
    assert (out / "cell.pdf").read_bytes() == pdf  # no dates: byte-identical PDF


def test_unknown_id_is_a_one_line_error(capsys):
    assert cli.main(["figures", "--only", "cell", "nope"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "'nope'" in err
    assert all(repr(fig_id) in err for fig_id in figures.FIGURE_IDS)


def test_missing_notebook_is_skipped_and_reported(tmp_path, monkeypatch):
    monkeypatch.setitem(figures.FIGURES, "forces", "not_written_yet.ipynb")
    report = figures.run_notebooks(only=["forces"], out_dir=tmp_path / "f",
                                   build_dir=tmp_path / "b", notebooks_dir=REPO / "notebooks")
    assert report.made == [] and report.missing == ["forces"]
    assert json.loads(report.manifest.read_text())["figures"] == {}


def test_save_is_deterministic_and_writes_a_sidecar(tmp_path):
    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.COLUMN_WIDTH, 2.0))
        ax.plot([0, 1, 2], [0, 1, 4])
        for sub in ("a", "b"):
            figures.save(fig, "forces", "Caption  with\n spaces.", {"x": float("nan"), "n": 3},
                         out_dir=tmp_path / sub)
        plt.close(fig)
    assert (tmp_path / "a/forces.pdf").read_bytes() == (tmp_path / "b/forces.pdf").read_bytes()
    assert (tmp_path / "a/forces.png").read_bytes() == (tmp_path / "b/forces.png").read_bytes()
    sidecar = json.loads((tmp_path / "a/forces.json").read_text())
    assert sidecar == {"files": ["forces.pdf", "forces.png"], "caption": "Caption with spaces.",
                       "numbers": {"x": None, "n": 3}}
    with pytest.raises(InvalidChoiceError):
        figures.save(fig, "nope", "c", {}, out_dir=tmp_path)


@pytest.mark.slow
def test_failing_notebook_names_notebook_and_error(tmp_path):
    notebook = tmp_path / "broken.ipynb"
    nbformat.write(nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell("quick = False", metadata={"tags": ["parameters"]}),
        nbformat.v4.new_code_cell("raise ValueError('burnt\\nbadly')")]), notebook)
    with pytest.raises(figures.NotebookError) as info:
        execute.execute_notebook(notebook, tmp_path / "executed.ipynb", {"quick": True},
                                 figures.kernel_name(), cwd=tmp_path)
    message = str(info.value)
    assert "\n" not in message
    assert "broken.ipynb" in message and "ValueError: burnt badly" in message


@pytest.mark.slow
def test_a_notebook_naming_an_unregistered_kernel_runs_in_this_python(tmp_path):
    """The notebooks name ``flipkit-python3``, which only ``make lab`` registers; papermill is
    given :func:`flipkit.figures.kernel_name`'s kernel, so a notebook naming a kernel that
    is registered nowhere still runs, in this Python, in ``cwd``."""
    notebook = tmp_path / "nb.ipynb"
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell("quick = False", metadata={"tags": ["parameters"]}),
        nbformat.v4.new_code_cell("import os, sys\nprint(sys.prefix)\nprint(os.getcwd())")])
    nb.metadata["kernelspec"] = {"name": "flipkit-unregistered", "display_name": "nowhere",
                                 "language": "python"}
    nbformat.write(nb, notebook)
    (tmp_path / "run").mkdir()
    execute.execute_notebook(notebook, tmp_path / "executed.ipynb", {"quick": True},
                             figures.kernel_name(), cwd=tmp_path / "run")
    out = nbformat.read(tmp_path / "executed.ipynb", as_version=4).cells[-1].outputs
    prefix, cwd = "".join(o.get("text", "") for o in out).split()
    assert Path(prefix).resolve() == Path(sys.prefix).resolve()
    assert Path(cwd).resolve() == (tmp_path / "run").resolve()


def test_every_figure_id_has_a_notebook_name():
    assert len(figures.FIGURE_IDS) == 17 and figures.FIGURE_IDS[0] == "cell"
    assert {path.name for path in NOTEBOOKS} <= set(figures.FIGURES.values())


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_has_parameters_cell_and_no_outputs(path):
    nb = nbformat.read(path, as_version=4)
    tagged = [c for c in nb.cells if "parameters" in c.metadata.get("tags", [])]
    assert len(tagged) == 1 and tagged[0].cell_type == "code"
    for name in ("quick", "out_dir", "scheduler"):
        assert f"{name} =" in tagged[0].source
    for c in nb.cells:
        if c.cell_type == "code":
            assert c.outputs == [] and c.execution_count is None
