"""The package's structure (docs/architecture.md, "Layers" and "One concept per module"):

* no module imports a module of a higher layer;
* no import cycle between modules;
* no private name (leading underscore) imported from another module;
* function-local imports only where a heavy optional dependency needs them, at most
  :data:`MAX_LOCAL_IMPORTS` in the package;
* the core (:mod:`flipkit.extras`) imports no package of an extra when it is imported, and
  the extras named there are pyproject's.

Every import is read from the source with ``ast`` by :mod:`flipkit.import_graph` — at module
level and inside functions alike (a lazy import that runs up a layer, or closes a cycle, is
still a dependency); the figure runner hashes the sources a notebook imports with the same
graph.
"""

from __future__ import annotations

from pathlib import Path

import re
import sys
import tomllib
from importlib.metadata import distribution, packages_distributions

import pytest
from packaging.requirements import Requirement

from flipkit.extras import EXTRAS, extra_of, is_core
from flipkit.import_graph import PACKAGE, closure, external_imports, flipkit_imports
from flipkit.import_graph import import_graph, local_imports, module_name, package_files

# Lowest first. A module may import its own layer and the layers below it.
LAYERS = (
    ("errors", "provenance", "fileio", "jsonread", "decimal_text", "csv_header", "import_graph",
     "extras"),
    ("config", ""),  # "" is the package root (flipkit/__init__.py: version, CellConfig)
    ("model",),
    ("transcription",),
    ("behaviors",),
    ("solvers",),
    ("planning",),
    ("viz",),
    ("baseline",),
    ("simulation",),
    ("experiments",),
    ("figures",),
    ("cli", "__main__"),
)
RANK = {name: rank for rank, names in enumerate(LAYERS) for name in names}
MAX_LOCAL_IMPORTS = 15  # function-local imports in the whole package
FILES = package_files()


def layer_of(module: str) -> str:
    """The layer name of a dotted module ``flipkit.<layer>[...]``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def imports(path: Path) -> list[tuple[int, str]]:
    """(line, absolute module) of every flipkit import in the file."""
    return [(i.line, i.target) for i in flipkit_imports(path)]


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(out)


def private(name: str | None) -> bool:
    """A leading underscore, dunders (``__version__``) excepted."""
    return bool(name) and name.startswith("_") and not (name.startswith("__")
                                                        and name.endswith("__"))


def test_every_module_belongs_to_a_declared_layer():
    unknown = sorted({layer_of(module_name(f)) for f in FILES} - set(RANK))
    assert not unknown, f"modules outside the declared layers: {unknown}"


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_import_runs_up_a_layer(path):
    own = RANK[layer_of(module_name(path))]
    bad = [f"line {line}: {target} (layer {layer_of(target)!r})"
           for line, target in imports(path) if RANK[layer_of(target)] > own]
    assert not bad, f"{module_name(path)} imports a higher layer: " + "; ".join(bad)


def test_the_checker_catches_an_upward_import(tmp_path, monkeypatch):
    """A planted model module importing the planner is reported (the test can fail)."""
    fake = PACKAGE / "model" / "robot.py"
    src = "from flipkit.planning.planners.planner import plan_flip\nfrom ..errors import FlipkitError\n"
    monkeypatch.setattr(Path, "read_text", lambda self, *a, **k: src)
    found = imports(fake)
    assert (1, "flipkit.planning.planners.planner") in found and (2, "flipkit.errors") in found
    assert RANK[layer_of(found[0][1])] > RANK[layer_of(module_name(fake))]


def test_no_import_cycles_between_modules():
    found = cycles(import_graph())
    assert not found, "import cycles: " + "; ".join(" <-> ".join(c) for c in found)


def test_no_private_name_is_imported_across_modules():
    bad = [f"{f.relative_to(PACKAGE.parent)}:{i.line}: {i.name} from {i.target}"
           for f in FILES for i in flipkit_imports(f)
           if private(i.name) and i.target != module_name(f)]
    assert not bad, "private names imported from another module: " + "; ".join(bad)


def test_function_local_imports_are_few():
    """Only a heavy optional dependency (MuJoCo, Dask, papermill, matplotlib on a CLI path,
    ...) justifies an import inside a function; everything else is imported at the top."""
    found = [f"{f.relative_to(PACKAGE.parent)}:{line}" for f in FILES for line in local_imports(f)]
    assert len(found) <= MAX_LOCAL_IMPORTS, (
        f"{len(found)} function-local imports (at most {MAX_LOCAL_IMPORTS}): " + ", ".join(found))


def test_the_checkers_catch_a_cycle_a_private_import_and_a_local_import(monkeypatch):
    """Planted sources: a cycle through a submodule import, a private name and two local
    imports are reported; a TYPE_CHECKING import and a dunder are not (the tests can fail)."""
    sources = {
        PACKAGE / "model" / "robot.py":
            "from flipkit.model import bezier\nfrom flipkit.model.contact import _helper\n"
            "from flipkit import __version__\n"
            "def f():\n    import mujoco\n    def g():\n        from flipkit.errors import X\n",
        PACKAGE / "model" / "bezier.py":
            "import flipkit.model.robot\nfrom typing import TYPE_CHECKING\n"
            "if TYPE_CHECKING:\n    from flipkit.model.ik import solve_pose\n",
        PACKAGE / "model" / "ik.py": "from flipkit.model.bezier import Bezier\n",
    }
    monkeypatch.setattr(Path, "read_text", lambda self, *a, **k: sources[self])
    graph = {module_name(p): {i.target for i in flipkit_imports(p) if not i.typing_only}
             for p in sources}
    assert cycles(graph) == [["flipkit.model.bezier", "flipkit.model.robot"]]
    robot = flipkit_imports(PACKAGE / "model" / "robot.py")
    assert [i.name for i in robot if private(i.name)] == ["_helper"]
    assert local_imports(PACKAGE / "model" / "robot.py") == [5, 7]
    assert [i.typing_only for i in flipkit_imports(PACKAGE / "model" / "bezier.py")] == [
        False, True]


# ---------------------------------------------------------------- the core and the extras
PROJECT = tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["project"]


def dist_name(name: str) -> str:
    """A distribution's name, normalised (PEP 503)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def core_distributions() -> set[str]:
    """The distributions ``pip install flipkit`` installs: pyproject's dependencies and theirs,
    transitively (from the installed metadata, extras left out)."""
    seen, todo = set(), [Requirement(r) for r in PROJECT["dependencies"]]
    while todo:
        req = todo.pop()
        name = dist_name(req.name)
        if name in seen:
            continue
        seen.add(name)
        for line in distribution(name).requires or ():
            sub = Requirement(line)
            if sub.marker is None or sub.marker.evaluate({"extra": ""}):
                todo.append(sub)
    return seen


def import_names(name: str) -> set[str]:
    """The top-level import names of an installed distribution, from its files (cmeel's
    wheels, pinocchio and placo, put theirs under ``cmeel.prefix/.../site-packages``)."""
    names = set()
    for f in distribution(name).files or ():
        parts = f.parts
        if "site-packages" in parts:
            parts = parts[parts.index("site-packages") + 1:]
        if not parts or parts[0].endswith((".dist-info", ".pth", ".data")) or parts[0] in (
                "..", "__pycache__", "cmeel.prefix", "bin"):
            continue
        if len(parts) > 1 or parts[0].endswith((".py", ".so")):
            names.add(parts[0].split(".")[0])
    return names


def core_import_names() -> set[str]:
    """The top-level names a core module may import: the standard library's, and those of
    the core's distributions."""
    core = core_distributions()
    return set(sys.stdlib_module_names) | {"flipkit", "__future__"} | {
        top for top, dists in packages_distributions().items()
        if any(dist_name(d) in core for d in dists)} | {
        top for name in core for top in import_names(name)}


def outside_the_core(paths: dict[str, Path], allowed: set[str]) -> dict[str, list[str]]:
    """Core module -> ``"<module>:<line> <package> (<extra>)"`` for every import of a package
    outside ``allowed`` that importing it runs (its own module-level imports and those of
    every flipkit module it imports at module level, transitively)."""
    graph = {name: {i.target for i in flipkit_imports(path) if not (i.local or i.typing_only)
                    and i.target != name} for name, path in paths.items()}
    found = {name: [f"{name}:{line} {top} ({extra_of(top) or 'not a core dependency'})"
                    for line, top, local in external_imports(path)
                    if not local and top not in allowed] for name, path in paths.items()}
    return {m: sorted(x for dep in closure(graph, [m]) for x in found.get(dep, ()))
            for m in paths if is_core(m)}


def test_the_core_imports_only_the_cores_dependencies():
    """Importing a core module (``flipkit.extras``) imports the standard library and the
    core's dependencies alone: no package of an extra, nor one an extra brings along."""
    paths = {module_name(f): f for f in FILES}
    core = [m for m in paths if is_core(m)]
    assert {"flipkit.model.robot", "flipkit.cli.commands.plan", "flipkit.cli.figures",
            "flipkit.planning.plans.verify", "flipkit.baseline.ik_track"} <= set(core)
    assert not is_core("flipkit.simulation.scene") and not is_core("flipkit.cli.commands.view")
    allowed = core_import_names()
    assert {"numpy", "pinocchio", "casadi", "cvxpy", "yaml", "placo"} <= allowed
    assert not {"mujoco", "matplotlib", "cycler", "ortools", "papermill", "dask"} & allowed
    bad = {m: v for m, v in outside_the_core(paths, allowed).items() if v}
    assert not bad, "core modules that import beyond the core's dependencies:\n" + "\n".join(
        f"{m}: {'; '.join(v)}" for m, v in sorted(bad.items()))


def test_the_core_check_catches_an_extra_reached_through_a_module(monkeypatch):
    """A core module importing (at its top) a module that imports MuJoCo at its top is
    reported; one that imports MuJoCo inside a function is not (the test can fail)."""
    sources = {
        PACKAGE / "model" / "robot.py": "from flipkit.model import scoop\nimport numpy\n",
        PACKAGE / "model" / "scoop.py": "import flipkit.simulation.scene\n",
        PACKAGE / "simulation" / "scene.py": "import os\nfrom mujoco import MjModel\n",
        PACKAGE / "model" / "ik.py": "def f():\n    import meshcat\n",
        PACKAGE / "model" / "bezier.py": "import cycler.x\n",
    }
    monkeypatch.setattr(Path, "read_text", lambda self, *a, **k: sources[self])
    found = outside_the_core({module_name(p): p for p in sources}, {"os", "numpy", "meshcat"})
    assert found["flipkit.model.robot"] == ["flipkit.simulation.scene:2 mujoco (sim)"]
    assert found["flipkit.model.scoop"] == found["flipkit.model.robot"]
    assert found["flipkit.model.ik"] == [] and "flipkit.simulation.scene" not in found
    assert found["flipkit.model.bezier"] == [
        "flipkit.model.bezier:1 cycler (not a core dependency)"]


def test_the_extras_are_pyprojects():
    """:data:`flipkit.extras.EXTRAS` names pyproject's extras, each import name installed by a
    distribution its extra requires; the core requires none of them."""
    project = PROJECT
    optional = project["optional-dependencies"]
    assert set(optional) == set(EXTRAS) | {"all"}
    assert optional["all"] == [f"flipkit[{','.join(EXTRAS)}]"]

    def dist(requirement: str) -> str:
        return requirement.split("[")[0].split("=")[0].split("<")[0].split(">")[0].lower()

    installed = {k: {d.lower() for d in v} for k, v in packages_distributions().items()}
    core = {dist(r) for r in project["dependencies"]}
    for extra, names in EXTRAS.items():
        required = {dist(r) for r in optional[extra]}
        for name in names:
            dists = installed.get(name, {name.lower()})
            assert dists & required or name in ("nbclient", "jupyter_client", "distributed"), (
                extra, name)
            assert not dists & core, (extra, name)
