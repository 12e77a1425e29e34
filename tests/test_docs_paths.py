"""The docs name what the code has.

* Every module path (``flipkit.x.y``, ``flipkit.x.y.Name``, or a dotted path inside the
  package such as ``planning.plans.verify``), every module run with ``python -m`` (the
  benchmarks: ``bench.bench``) and every repository file named in ``docs/*.md``,
  ``README.md``, ``notebooks/README.md`` and ``bench/README.md`` exists.
* ``docs/adding-a-behaviour.md`` quotes the code: its declarations are the code's, and the
  numbers in its prose are the code's.
* ``notebooks/README.md`` lists every notebook, and every notebook names the project's kernel.

``docs/benchmarks/`` is left out: its notes are dated records of a run and name the paths of
their day.
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import json
import os
import re
from pathlib import Path, PurePosixPath

import flipkit

REPO = Path(flipkit.__file__).resolve().parents[1]
PACKAGE = REPO / "flipkit"
DOCS = sorted((REPO / "docs").glob("*.md")) + [REPO / "README.md", REPO / "notebooks" / "README.md",
                                               REPO / "bench" / "README.md"]

# The subpackages and top-level modules of flipkit: a dotted name in a code span that starts
# with one of them (``planning.plans.verify``) is a path inside the package.
TOP_NAMES = sorted({p.stem for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
                   | {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()})
CODE_SPAN = re.compile(r"(`+)([^`\n]+?)\1")
LINK = re.compile(r"\]\(([^)\s]+)\)")
RUN_MODULE = re.compile(r"python -m ([A-Za-z_][\w.]*)")
DOTTED = re.compile(r"(?<![\w.])(flipkit(?:\.[A-Za-z_]\w*)+)")
SHORT_DOTTED = re.compile(r"(?:%s)(?:\.[A-Za-z_]\w*)+" % "|".join(TOP_NAMES))
FILE_SUFFIXES = (".py", ".md", ".json", ".csv", ".npz", ".ipynb", ".tex", ".toml", ".txt",
                 ".lock", ".cff", ".in", ".urdf", ".yaml", ".yml", ".gif", ".png", ".pdf")
# Code spans that look like paths and are not files of this repository, each with why.
NOT_REPO_FILES = {
    "config/ur10/joint_limits.yaml": "Universal Robots' ROS 2 description",
    "config/ur10e/joint_limits.yaml": "Universal Robots' ROS 2 description",
    "robot.urdf": "a field of the plan file",
    # written by a command, absent from a clone
    ".venv/bin/flipkit": "made by `make venv`",
    "figures/manifest.json": "written by `flipkit figures`",
    "manifest.json": "written by `flipkit figures`",
    "figures/ik_failure.json": "written by `flipkit figures`",
    "notebooks/figures/": "written by a notebook run in JupyterLab",
    "paper/numbers.tex": "written by `make paper`",
    "numbers.tex": "written by `make paper`",
    "summary.csv": "written by `flipkit plan batch`",
    "build/notebooks/": "written by `flipkit figures`",
    "kitchen.gif": "written by `flipkit figures`",
    "OUT.run-cache/": "written by a sweep command without --cache, beside its output OUT",
    "paper/main.pdf": "written by `make paper`",
}
NOT_PATHS = (re.compile(r"^[\w-]+/\d+$"),  # a format's name and version: flipkit-plan/2
             re.compile(r"^\w+_msgs/"),  # a ROS message or action type
             re.compile(r"^\.\w+$"),  # a file extension
             re.compile(r"^/"))  # a system path: /proc


def repo_files() -> list[PurePosixPath]:
    """Every file and folder of the repository (not .git, the venv or build output)."""
    out = []
    for root, dirs, files in os.walk(REPO):
        dirs[:] = [d for d in dirs if not d.startswith(".") and d not in ("build", "__pycache__")]
        rel = PurePosixPath(Path(root).relative_to(REPO).as_posix())
        out += [rel / d for d in dirs] + [rel / f for f in files]
    return out


REPO_FILES = repo_files()


def code_spans(text: str) -> list[str]:
    return [m.group(2).strip() for m in CODE_SPAN.finditer(text)]


def module_paths(text: str, macro_keys: bool = False) -> set[str]:
    """Every dotted name in ``text`` that names something in flipkit.

    With ``macro_keys``, ``config.<key>`` is a key of the report's macros
    (``docs/citing.md``; :func:`test_citing_names_only_config_keys_the_macros_define`), not
    a path.
    """
    names = set(DOTTED.findall(text))
    for span in code_spans(text):
        span = re.sub(r"\(.*$", "", span).rstrip(".,;:")  # a call: verify.verify_plan(plan)
        if macro_keys and re.fullmatch(r"config\.\w+", span):
            continue
        if SHORT_DOTTED.fullmatch(span):
            names.add("flipkit." + span)
    return names


def resolves(dotted: str) -> bool:
    """``dotted`` names a module of flipkit, or an attribute of one (a dataclass field too)."""
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        stem = PACKAGE.parent.joinpath(*parts[:k])
        if stem.with_suffix(".py").is_file() or (stem / "__init__.py").is_file():
            break
    else:
        return False
    obj = importlib.import_module(".".join(parts[:k]))
    for attr in parts[k:]:
        fields = getattr(obj, "__dataclass_fields__", {})
        if attr in fields and not hasattr(obj, attr):
            return attr is parts[-1]
        if not hasattr(obj, attr):
            return False
        obj = getattr(obj, attr)
    return True


def runs_a_module(dotted: str, root: Path = REPO) -> bool:
    """``python -m dotted`` from the repository's root finds a module: one of flipkit's, a
    module file or package of the repository (``bench.bench``), or an installed one."""
    if dotted.split(".")[0] == "flipkit":
        return resolves(dotted)
    stem = root.joinpath(*dotted.split("."))
    if stem.with_suffix(".py").is_file() or (stem / "__main__.py").is_file():
        return True
    return dotted.split(".")[0] not in {p.name for p in root.iterdir()} and (
        importlib.util.find_spec(dotted.split(".")[0]) is not None)


def file_paths(text: str) -> tuple[set[str], set[str]]:
    """(code spans that look like a path, relative link targets) in ``text``."""
    spans = set()
    for span in code_spans(text):
        span = span.rstrip(".,;:")
        if (" " in span or any(c in span for c in "<>{}$=|\\'\"()") or "://" in span
                or any(p.search(span) for p in NOT_PATHS)):
            continue
        if "/" in span or span.endswith(FILE_SUFFIXES):
            spans.add(span)
    links = {t.split("#")[0] for t in LINK.findall(text)}
    return spans, {t for t in links if t and "://" not in t and not t.startswith("mailto:")}


def names_a_file(path: str) -> bool:
    """``path`` is the end of a path in the repository (a glob's ``*`` stays in one folder)."""
    pattern = path.rstrip("/")
    return any(f.match(pattern) for f in REPO_FILES)


def dead_paths(doc: Path, root: Path = REPO) -> list[str]:
    """Every dead path of ``doc`` as ``"<doc>: <kind> <path>"`` (``root``: where docs live)."""
    text = doc.read_text(encoding="utf-8")
    where = doc.relative_to(root)
    dead = [f"{where}: module {m}"
            for m in sorted(module_paths(text, macro_keys=doc.name == "citing.md"))
            if not resolves(m)]
    spans, links = file_paths(text)
    dead += [f"{where}: file {p}" for p in sorted(spans)
             if p not in NOT_REPO_FILES and not names_a_file(p)]
    dead += [f"{where}: link {p}" for p in sorted(links) if not (doc.parent / p).exists()]
    dead += [f"{where}: python -m {m}" for m in sorted(set(RUN_MODULE.findall(text)))
             if not runs_a_module(m, root)]
    return dead


def test_every_path_named_in_the_docs_exists():
    dead = [d for doc in DOCS for d in dead_paths(doc)]
    assert not dead, f"{len(dead)} dead paths in the docs:\n" + "\n".join(dead)


def test_a_dead_path_is_found(tmp_path):
    doc = tmp_path / "docs" / "x.md"
    doc.parent.mkdir()
    doc.write_text("`planning.chain.Planner`, `flipkit.planning.planners.chain.Plannr`, "
                   "`flipkit/planning/verify.py`, `plans/nowhere.py`, [a](missing.md), "
                   "`flipkit.planning.planners.chain.Planner`, `planning/plans/verify.py`, "
                   "`behaviors.spec.Subbehavior.duration`, `verify*.py`, `flipkit-plan/2`, "
                   "`python -m bench.nowhere`, `python -m pytest`, `python -m flipkit.nowhere`")
    (tmp_path / "bench").mkdir()
    found = [d.split(": ", 1)[1] for d in dead_paths(doc, root=tmp_path)]
    assert found == ["module flipkit.nowhere", "module flipkit.planning.chain.Planner",
                     "module flipkit.planning.planners.chain.Plannr",
                     "file flipkit/planning/verify.py", "file plans/nowhere.py",
                     "link missing.md", "python -m bench.nowhere", "python -m flipkit.nowhere"]


def test_the_walk_of_plan_flip_runs_from_the_command_line_to_osqp_in_twelve_steps():
    """``docs/architecture.md`` walks ``flipkit plan flip`` in at most 12 numbered steps, from
    the command line's entry point to the OSQP solver (the names in it resolve: above)."""
    text = (REPO / "docs" / "architecture.md").read_text(encoding="utf-8")
    start = text.index("## The walk of `flipkit plan flip`")
    section = text[start:text.index("\n## ", start + 1)]
    steps = re.findall(r"^(\d+)\. ", section, re.M)
    assert 1 <= len(steps) <= 12 and steps == [str(k) for k in range(1, len(steps) + 1)]
    assert "`flipkit.cli.main`" in section
    assert "`flipkit.solvers.osqp_slots.RowSlots.solve`" in section


def test_citing_names_only_config_keys_the_macros_define():
    from flipkit.figures.macros import config_constants

    text = (REPO / "docs" / "citing.md").read_text(encoding="utf-8")
    named = set(re.findall(r"config\.(\w+)", text)) - {"name"}
    assert named and named <= set(config_constants()), named - set(config_constants())


# ---------------------------------------------------------------- adding-a-behaviour.md
ADDING = REPO / "docs" / "adding-a-behaviour.md"
PYTHON_BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def code_statements() -> set[str]:
    """``ast.dump`` of every statement in the package, at any depth."""
    out = set()
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.stmt):
                out.add(ast.dump(node))
    return out


def test_adding_a_behaviour_quotes_the_code():
    """Every statement in the page's Python blocks is a statement of the package, verbatim
    up to layout and comments: a changed bound or field fails here."""
    blocks = PYTHON_BLOCK.findall(ADDING.read_text(encoding="utf-8"))
    assert len(blocks) >= 3
    known = code_statements()
    quoted = [stmt for block in blocks for stmt in ast.parse(block).body]
    stale = [ast.unparse(s) for s in quoted if ast.dump(s) not in known]
    assert not stale, "not in the code:\n" + "\n".join(stale)


def test_adding_a_behaviour_numbers_are_the_codes():
    from flipkit.behaviors.library import SUBBEHAVIORS
    from flipkit.config import CellConfig

    text = ADDING.read_text(encoding="utf-8")
    assert f'"carry", duration={SUBBEHAVIORS["carry"].duration!r}' in text
    limits = {float(v) for v in re.findall(r"(\d+(?:\.\d+)?) rad/s²", text)}
    assert limits == {CellConfig().robot.accel_limit}


def test_adding_a_behaviour_names_and_counts_are_the_codes():
    """The constants the page names exist, and the serve is what the page says: its first
    three steps are the flip's, its last three declared in ``flipkit/behaviors/table.py``."""
    from flipkit.behaviors import table
    from flipkit.behaviors.library import BEHAVIORS

    text = ADDING.read_text(encoding="utf-8")
    constants = {span for span in code_spans(text) if re.fullmatch(r"[A-Z][A-Z0-9_]+", span)}
    assigned = {t.id for path in PACKAGE.rglob("*.py")
                for node in ast.parse(path.read_text(encoding="utf-8")).body
                if isinstance(node, (ast.Assign, ast.AnnAssign))
                for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
                if isinstance(t, ast.Name)}
    assert {"FLIP_TOOL_FRACTION", "GO_TO_BURGER", "SCOOP", "PICKUP"} <= constants
    assert constants <= assigned, constants - assigned
    serve, flip = BEHAVIORS["serve"].steps, BEHAVIORS["flip"].steps
    assert "Its first three\nsegments are the flip's" in text and "Its last three" in text
    assert serve[:3] == flip[:3] and len(serve) == 6
    assert all(any(step is v for v in vars(table).values()) for step in serve[3:])


def test_a_changed_bound_is_not_the_code():
    """The quote check fails on the carry with another duration bound."""
    block = PYTHON_BLOCK.findall(ADDING.read_text(encoding="utf-8"))[0]
    assert "duration=(0.6, 1.2)" in block
    tampered = ast.parse(block.replace("duration=(0.6, 1.2)", "duration=(0.6, 1.6)")).body[0]
    assert ast.dump(tampered) not in code_statements()


# ---------------------------------------------------------------- notebooks
NOTEBOOKS = sorted((REPO / "notebooks").glob("*.ipynb"))


def test_the_notebooks_readme_lists_every_notebook():
    text = (REPO / "notebooks" / "README.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"^\| `([\w-]+\.ipynb)` \|", text, re.M))
    assert len(NOTEBOOKS) >= 16
    assert listed == {p.name for p in NOTEBOOKS}


def test_every_notebook_names_the_projects_kernel():
    """The kernel ``make lab`` registers and :func:`flipkit.figures.kernel_name` installs."""
    from flipkit.figures.execute import KERNEL_DISPLAY_NAME, KERNEL_NAME

    makefile = (REPO / "Makefile").read_text(encoding="utf-8")
    assert f'--name {KERNEL_NAME} --display-name "{KERNEL_DISPLAY_NAME}"' in makefile
    for path in NOTEBOOKS:
        spec = json.loads(path.read_text(encoding="utf-8"))["metadata"]["kernelspec"]
        assert (spec["name"], spec["display_name"]) == (KERNEL_NAME, KERNEL_DISPLAY_NAME), path.name


# ---------------------------------------------------------------- the code's comments
# What a dated note looks like in a comment or docstring: a date, an issue number, a benchmark
# note, or a measurement ("(measured", "measured:", "Measured on ...", "(seen: ...", a time
# something took or costs, a run on the 2-core machine or at some load, a distance or share
# seen in MuJoCo or in simulation, a count of trials solved, a bound "shortened from" a
# value). A burger "measured on the blade" (sensed) is not one.
DIARY = re.compile(r"20\d\d-\d\d-\d\d|[Ii]ssue #?\d+|docs/benchmarks/|\(measured|[Mm]easured[:,)]"
                   r"|Measured (?:on|at|in)\b|measured (?:on|at|in) (?:a |one |Table|MuJoCo)"
                   r"|measured \d|\(seen[:,]|2-core machine|two cores|at load \d"
                   r"|\b(?:took|ran|overran) (?:about |over |~)?\d"
                   r"|~ ?\d[\d.]* ?(?:ms|µs|s|×)(?:\W|$)|\bcosts? ~"
                   r"|\d ?(?:cm|mm|%|s|ms)\b[^.;]*\bin (?:MuJoCo|simulation|one MuJoCo trial)\b"
                   r"|\b\d+/\d+ (?:trials|solved|flips|serves)\b|succeeded \d+ ?(?:/|of) ?\d+"
                   r"|(?:shortened|lengthened|raised|lowered) from \d")
# sources: a UR client-library thread, an OR-Tools bug report, a newspaper, a parameter's range
MAX_DIARY_LINES = 5


def diary_lines(root: Path) -> list[str]:
    return [f"{path.relative_to(root.parent)}:{k}: {line.strip()}"
            for path in sorted(root.rglob("*.py"))
            for k, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
            if DIARY.search(line)]


def test_the_code_keeps_its_measurements_in_the_docs():
    """Comments say what the code does and why; the measurements behind a choice are in
    ``docs/history.md`` ("Measurements behind the code's choices")."""
    found = diary_lines(PACKAGE)
    assert len(found) <= MAX_DIARY_LINES, "\n".join(found)


def test_a_diary_comment_is_found(tmp_path):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "m.py").write_text("# solves in 3 s (measured 2026-11-23)\n"
                              "# the burger measured on the blade\nx = 1  # issue 13\n"
                              "# on the 2-core machine a solve took 0.5 s\n"
                              "# a query costs ~1.5× more (seen: blade to table)\n"
                              "# the burger came to rest 3.8 cm beyond its spot in MuJoCo\n"
                              "# a flip planned with μ 0.4 succeeded 0/100\n"
                              "# the bounds before the chain was shortened from 4.0 s\n"
                              "# the scoop drags the burger forward by centimetres\n")
    assert [d.split(":")[1] for d in diary_lines(pkg)] == ["1", "3", "4", "5", "6", "7", "8"]
