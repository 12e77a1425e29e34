"""The figure notebooks end to end (quick mode, through papermill) and the report that cites
them: every figure of the report has a notebook that runs and saves a non-empty PDF and PNG into
the manifest; paper/main.tex includes and names every figure; the macro file generated from
the manifest has one macro per number and defines every number the report quotes."""

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

import flipkit
from flipkit import figures

# The figures of the report (paper/main.tex), in its order.
REPORT_FIGURE_IDS = ("cell", "forces", "subbehaviors", "defects", "translate", "flip", "table1",
                     "ik_failure", "solve_times", "solve_scaling", "cone_forms", "landing",
                     "filmstrip",
                     "sensitivity", "schedule", "throughput", "kitchen")
REPO = Path(flipkit.__file__).resolve().parents[1]
PAPER_DIR = REPO / "paper"
MAIN_TEX = PAPER_DIR / "main.tex"
MACRO_USE = re.compile(r"\\fk(num|mm|pct)\{([^}]*)\}\{([^}]*)\}")
MACRO_DEF = re.compile(r"^\\fkdef(|mm|pct)\{([^}]*)\}\{([^}]*)\}\{", re.M)
INCLUDE = re.compile(r"\\includegraphics(?:\[[^\]]*\])?\{([^}]*)\}")


def tex():
    return MAIN_TEX.read_text()


def uses(fig_id=None):
    """(kind, figure, key) of every number macro main.tex uses (kind '' is \\fknum)."""
    out = [("" if kind == "num" else kind, f, k) for kind, f, k in MACRO_USE.findall(tex())]
    return [u for u in out if fig_id is None or u[1] == fig_id]


# ---------------------------------------------------------------- fast checks
def test_design_figures_have_notebooks():
    assert figures.FIGURE_IDS == REPORT_FIGURE_IDS
    for fig_id in REPORT_FIGURE_IDS:
        path = REPO / "notebooks" / figures.FIGURES[fig_id]
        assert path.is_file(), f"no notebook for figure {fig_id!r}"
        text = path.read_text()
        assert f'figures.save(fig, \\"{fig_id}\\"' in text


def test_every_figure_is_included_and_named_in_the_paper():
    text = tex()
    targets = INCLUDE.findall(text)
    assert sorted(targets) == sorted(f"../figures/{i}.pdf" for i in REPORT_FIGURE_IDS)
    for fig_id in REPORT_FIGURE_IDS:
        notebook = "notebooks/" + figures.FIGURES[fig_id]
        assert notebook.replace("notebooks/", r"\nb{").replace("_", r"\_") + "}" in text, notebook
        assert f"\\fkcaption{{{fig_id}}}" in text
        assert f"\\label{{fig:{fig_id}}}" in text


def test_paper_quotes_only_numbers_of_known_figures():
    found = uses()
    assert len(found) > 40
    assert {f for _, f, _ in found} <= set(REPORT_FIGURE_IDS)
    assert (PAPER_DIR / "main.tex").read_text().count(r"\input{numbers}") == 1


def test_paper_has_the_differences_section():
    text = tex()
    assert r"\section{What differs from the paper and why}" in text
    for topic in ("UR10", "turn back", "tip", "rest", "Braking", "cone", "MuJoCo", "ma57",
                  "MUMPS", "L-BFGS", r"\fkmeta{config.grill_mu}"):
        assert topic in text, topic


# ---------------------------------------------------------------- notebooks, quick mode
@pytest.mark.slow
@pytest.mark.parametrize("fig_id", REPORT_FIGURE_IDS)
def test_notebook_runs_quick_and_feeds_the_paper(fig_id, tmp_path):
    out = tmp_path / "figures"
    report = figures.run_notebooks(quick=True, only=[fig_id], out_dir=out,
                                   build_dir=tmp_path / "build", notebooks_dir=REPO / "notebooks")
    assert report.made == [fig_id] and report.missing == []
    manifest = json.loads(report.manifest.read_text())
    entry = manifest["figures"][fig_id]

    # the figure: non-empty PDF and PNG, listed in the manifest with its notebook
    assert entry["files"] == [f"{fig_id}.pdf", f"{fig_id}.png"]
    pdf, png = out / f"{fig_id}.pdf", out / f"{fig_id}.png"
    assert pdf.stat().st_size > 5000 and pdf.read_bytes().startswith(b"%PDF")
    assert png.stat().st_size > 5000 and png.read_bytes().startswith(b"\x89PNG")
    assert entry["notebook"] == f"notebooks/{figures.FIGURES[fig_id]}"
    assert entry["parameters"]["quick"] is True
    assert len(entry["caption"]) > 80 and entry["numbers"]

    # the paper's \includegraphics of this figure resolves to the file just made
    for target in INCLUDE.findall(tex()):
        if target == f"../figures/{fig_id}.pdf":
            assert (out / target.split("/")[-1]).is_file()

    # the macro file: one \fkdef per number, and every number the paper quotes is defined
    macros = figures.write_macros(manifest, tmp_path / "numbers.tex").read_text()
    defs = [(kind, f, k) for kind, f, k in MACRO_DEF.findall(macros)]
    plain = [(f, k) for kind, f, k in defs if kind == "" and f == fig_id]  # a notebook
    # may make several figures (landing.ipynb: landing and filmstrip)
    leaves = figures.flatten_numbers(entry["numbers"])
    assert len(plain) == len(leaves) == len(set(plain))
    assert {k for _, k in plain} == {k for k, _ in leaves}
    missing = set(uses(fig_id)) - set(defs)
    assert not missing, f"paper/main.tex quotes numbers {fig_id} does not make: {missing}"
    assert f"\\fkdefcaption{{{fig_id}}}" in macros


@pytest.mark.slow
def test_paper_compiles_with_the_current_figures(tmp_path):
    """With LaTeX installed and a complete figures/ (make figures), the report builds and
    quotes no undefined number."""
    manifest_path = REPO / "figures" / "manifest.json"
    if shutil.which("latexmk") is None:
        pytest.skip("latexmk not installed (make paper installs it)")
    if not manifest_path.is_file():
        pytest.skip("no figures/manifest.json (run make figures)")
    manifest = json.loads(manifest_path.read_text())
    if set(manifest["figures"]) != set(REPORT_FIGURE_IDS):
        pytest.skip("figures/ is incomplete (run make figures)")
    paper = tmp_path / "paper"
    paper.mkdir()
    shutil.copy(MAIN_TEX, paper / "main.tex")
    (tmp_path / "figures").symlink_to(REPO / "figures")
    figures.write_macros(manifest, paper / "numbers.tex")
    run = subprocess.run(["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error",
                          "main.tex"], cwd=paper, capture_output=True, text=True, timeout=300)
    log = (paper / "main.log").read_text(errors="replace")
    assert run.returncode == 0, log[-3000:]
    assert "flipkit: undefined number macro" not in log
    assert (paper / "main.pdf").stat().st_size > 100_000
