"""Figures that rebuild only what changed: the hash of a notebook's inputs
(:mod:`flipkit.figures.inputs`) and the runner skipping up-to-date notebooks. No notebook
really runs here: the executor is replaced by one that writes the figure's files."""

import json
import os
from pathlib import Path

import nbformat
import pytest

import flipkit
from flipkit import cli
from flipkit.figures import inputs, pipeline
from flipkit.import_graph import closure, import_graph

REPO = Path(flipkit.__file__).resolve().parents[1]

PARAMS = {"quick": False, "out_dir": "figures", "scheduler": None}


def write_notebook(path: Path, *code: str) -> Path:
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_markdown_cell("# A figure"),
        nbformat.v4.new_code_cell("quick = False\nout_dir = 'figures'\nscheduler = None",
                                  metadata={"tags": ["parameters"]}),
        *(nbformat.v4.new_code_cell(c) for c in code)])
    nbformat.write(nb, path)
    return path


@pytest.fixture
def project(tmp_path):
    """A package ``flipkit`` of four modules and data, a lock, and a notebook importing one."""
    pkg = tmp_path / "flipkit"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "data").mkdir()
    files = {"__init__.py": "", "sub/__init__.py": "",
             "sub/a.py": "from . import b\n\ndef f():\n    from flipkit import c\n",
             "sub/b.py": "X = 1\n", "c.py": "Y = 2\n", "unrelated.py": "Z = 3\n",
             "data/table.csv": "x,y\n1,2\n"}
    for name, text in files.items():
        (pkg / name).write_text(text)
    (tmp_path / "environment.lock").write_text("numpy==2.0 --hash=sha256:00\n")
    write_notebook(tmp_path / "nb.ipynb", "%matplotlib inline\nfrom flipkit.sub import a",
                   "!echo shell lines are not Python\nprint(a)")
    return tmp_path


def digest(project, params=PARAMS):
    return inputs.hash_inputs(project / "nb.ipynb", params, root=project / "flipkit",
                              lock=project / "environment.lock")


def test_the_notebook_depends_on_the_closure_of_its_imports(project):
    found = digest(project)
    assert found.modules == ("flipkit", "flipkit.c", "flipkit.sub", "flipkit.sub.a",
                             "flipkit.sub.b")  # c: a function-local import still runs
    assert found.digest == digest(project).digest and found.digest.startswith("sha256:")


@pytest.mark.parametrize("change, part", [
    (lambda p: write_notebook(p / "nb.ipynb", "from flipkit.sub import a", "print(a, 1)"),
     "notebook"),
    (lambda p: (p / "flipkit/sub/b.py").write_text("X = 2\n"), "sources"),
    (lambda p: (p / "flipkit/c.py").write_text("Y = 3\n"), "sources"),
    (lambda p: (p / "flipkit/__init__.py").write_text("V = 1\n"), "sources"),
    (lambda p: (p / "flipkit/data/table.csv").write_text("x,y\n1,3\n"), "data"),
    (lambda p: (p / "environment.lock").write_text("numpy==2.1 --hash=sha256:01\n"),
     "environment_lock"),
])
def test_the_hash_changes_with_each_input(project, change, part):
    before = digest(project)
    change(project)
    after = digest(project)
    assert after.digest != before.digest
    assert [p for p in inputs.PARTS if after.parts[p] != before.parts[p]] == [part]
    assert inputs.changed(before.record(), after) == [inputs.PART_NAMES[part]]


def test_the_hash_changes_with_a_parameter_but_not_with_out_dir(project):
    base = digest(project).digest
    assert digest(project, {**PARAMS, "quick": True}).digest != base  # quick vs full
    assert digest(project, {**PARAMS, "scheduler": "tcp://h:8786"}).digest != base
    assert digest(project, {**PARAMS, "out_dir": "/elsewhere"}).digest == base


def test_the_hash_ignores_unrelated_modules_and_notebook_metadata(project):
    base = digest(project).digest
    (project / "flipkit/unrelated.py").write_text("Z = 4\n")
    (project / "flipkit/new_module.py").write_text("W = 5\n")
    nb = nbformat.read(project / "nb.ipynb", as_version=4)
    nb.metadata["kernelspec"] = {"name": "flipkit-python3", "display_name": "x",
                                 "language": "python"}
    nb.cells[2].outputs = [nbformat.v4.new_output("stream", text="hi")]
    nb.cells[2].execution_count = 7
    nbformat.write(nb, project / "nb.ipynb")
    assert digest(project).digest == base


def test_a_cell_that_is_not_python_is_a_one_line_error(project):
    write_notebook(project / "nb.ipynb", "from flipkit.sub import a", "def broken(:\n")
    with pytest.raises(inputs.NotebookInputsError, match=r"^notebook nb.ipynb: code cell 4 "
                                                         r"is not Python \(line 1: [^\n]*$"):
        digest(project)


def test_the_real_notebooks_import_what_they_draw_with():
    graph = import_graph()
    cell = inputs.notebook_modules(REPO / "notebooks" / "cell.ipynb", graph)
    assert {"flipkit", "flipkit.figures", "flipkit.figures.draw", "flipkit.model.robot",
            "flipkit.config.cell"} <= cell
    assert not any(m.startswith(("flipkit.cli", "flipkit.baseline")) for m in cell)
    assert closure(graph, ["flipkit.errors"]) == {"flipkit", "flipkit.errors"}


@pytest.fixture
def runner(tmp_path, monkeypatch):
    """run_notebooks on a tiny ``cell.ipynb`` with an executor that only writes the files."""
    notebooks = tmp_path / "notebooks"
    notebooks.mkdir()
    write_notebook(notebooks / "cell.ipynb", "from flipkit.figures import catalog")
    calls = []

    def fake_execute(notebook, executed, parameters, kernel, cwd):
        out = Path(parameters["out_dir"])
        for name in ("cell.pdf", "cell.png"):
            (out / name).write_bytes(b"figure")
        sidecar = {"files": ["cell.pdf", "cell.png"], "caption": "c", "numbers": {"n": 1}}
        (out / "cell.json").write_text(json.dumps(sidecar))
        calls.append(dict(parameters))

    monkeypatch.setattr(pipeline, "execute_notebook", fake_execute)
    monkeypatch.setattr(pipeline, "kernel_name", lambda: "python3")

    def run(**kwargs):
        lines = []
        report = pipeline.run_notebooks(only=["cell"], out_dir=tmp_path / "figures",
                                        build_dir=tmp_path / "build", notebooks_dir=notebooks,
                                        log=lines.append, **kwargs)
        return report, lines

    return run, calls, notebooks, tmp_path / "figures"


def test_the_runner_skips_an_up_to_date_notebook(runner):
    run, calls, notebooks, out = runner
    report, lines = run()
    assert report.ran == {"cell.ipynb": "no figure 'cell' in " + str(out)} and len(calls) == 1
    assert list(report.times_s) == ["cell.ipynb"] and lines[-1].startswith("made cell.ipynb in ")
    entry = json.loads((out / "manifest.json").read_text())["figures"]["cell"]
    assert entry["inputs"]["hash"].startswith("sha256:") and entry["numbers"] == {"n": 1}

    report, lines = run()
    assert len(calls) == 1 and report.made == [] and list(report.skipped) == ["cell.ipynb"]
    assert lines == [f"skip cell.ipynb: {report.skipped['cell.ipynb']}"]
    assert report.skipped["cell.ipynb"].startswith("up to date (inputs sha256:")
    assert json.loads((out / "manifest.json").read_text())["figures"]["cell"] == entry

    assert run(force=True)[0].ran == {"cell.ipynb": "--force"} and len(calls) == 2


def test_quick_and_full_outputs_are_not_mistaken_for_each_other(runner):
    run, calls, _, _ = runner
    run()
    report, _ = run(quick=True)
    assert report.ran == {"cell.ipynb": "changed: parameters (quick False -> True)"}
    assert [c["quick"] for c in calls] == [False, True]
    assert run(quick=True)[0].skipped and not run(quick=False)[0].skipped


def test_the_runner_remakes_a_missing_file_or_an_edited_notebook(runner):
    run, calls, notebooks, out = runner
    run()
    (out / "cell.png").unlink()
    assert run()[0].ran == {"cell.ipynb": "cell.png is missing"}
    write_notebook(notebooks / "cell.ipynb", "from flipkit.figures import catalog  # edited")
    assert run()[0].ran == {"cell.ipynb": "changed: the notebook"}
    entry = json.loads((out / "cell.json").read_text())
    del entry["inputs"]
    (out / "cell.json").write_text(json.dumps(entry))
    assert "no inputs hash" in run()[0].ran["cell.ipynb"]
    assert len(calls) == 4 and run()[0].skipped


def test_the_command_prints_each_skip_and_a_summary(tmp_path, monkeypatch, capsys):
    def fake_execute(notebook, executed, parameters, kernel, cwd):
        out = Path(parameters["out_dir"])
        for name in ("cell.pdf", "cell.png"):
            (out / name).write_bytes(b"figure")
        (out / "cell.json").write_text(json.dumps({"files": ["cell.pdf", "cell.png"]}))

    monkeypatch.setattr(pipeline, "execute_notebook", fake_execute)
    monkeypatch.setattr(pipeline, "kernel_name", lambda: "python3")
    monkeypatch.chdir(tmp_path)
    argv = ["figures", "--quick", "--only", "cell", "--out", "figs", "--notebooks",
            str(REPO / "notebooks")]
    assert cli.main(argv) == 0
    assert "run  cell.ipynb: no figure 'cell'" in capsys.readouterr().out
    assert cli.main(argv) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].startswith("flipkit figures: skip cell.ipynb: up to date (inputs sha256:")
    assert lines[1].startswith("flipkit figures: ran 0 notebooks, skipped 1 up to date;")
    assert len(lines) == 2 and os.path.isfile(tmp_path / "figs" / "manifest.json")


def test_a_notebook_of_two_figures_records_both_and_reports_the_one_asked_for(tmp_path,
                                                                             monkeypatch):
    notebooks = tmp_path / "notebooks"
    notebooks.mkdir()
    write_notebook(notebooks / "landing.ipynb", "from flipkit.figures import catalog")

    def fake_execute(notebook, executed, parameters, kernel, cwd):
        out = Path(parameters["out_dir"])
        for fig_id in ("landing", "filmstrip"):
            (out / f"{fig_id}.pdf").write_bytes(b"figure")
            (out / f"{fig_id}.json").write_text(json.dumps({"files": [f"{fig_id}.pdf"]}))

    monkeypatch.setattr(pipeline, "execute_notebook", fake_execute)
    monkeypatch.setattr(pipeline, "kernel_name", lambda: "python3")
    kwargs = dict(only=["filmstrip"], out_dir=tmp_path / "f", build_dir=tmp_path / "b",
                  notebooks_dir=notebooks)
    assert pipeline.run_notebooks(**kwargs).made == ["filmstrip"]
    manifest = json.loads((tmp_path / "f" / "manifest.json").read_text())["figures"]
    assert manifest["landing"]["inputs"] == manifest["filmstrip"]["inputs"]
    assert list(pipeline.run_notebooks(**{**kwargs, "only": ["landing"]}).skipped) == [
        "landing.ipynb"]
