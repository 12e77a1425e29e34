"""The package's layers: no module imports a module of a higher layer (README, "Layers").

Every import is read from the source with ``ast`` — at module level and inside functions
alike (a lazy import that runs up a layer is still a dependency on that layer).
"""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "flipkit"
# Lowest first. A module may import its own layer and the layers below it.
LAYERS = (
    ("errors", "provenance", "fileio"),
    ("config", ""),  # "" is the package root (flipkit/__init__.py: version, CellConfig)
    ("model",),
    ("transcription",),
    ("behaviors",),
    ("solvers",),
    ("planning",),
    ("baseline",),
    ("simulation",),
    ("experiments",),
    ("figures",),
    ("cli", "__main__"),
)
RANK = {name: rank for rank, names in enumerate(LAYERS) for name in names}


def layer_of(module: str) -> str:
    """The layer name of a dotted module ``flipkit.<layer>[...]``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def imports(path: Path) -> list[tuple[int, str]]:
    """(line, absolute module) of every flipkit import in the file."""
    mod = module_name(path)
    package = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target == "flipkit":  # from flipkit import x: x may be a subpackage
                out += [(node.lineno, f"flipkit.{a.name}") if f"{a.name}" in RANK
                        else (node.lineno, "flipkit") for a in node.names]
            elif target.startswith("flipkit."):
                out.append((node.lineno, target))
        elif isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names if a.name.startswith("flipkit")]
    return out


FILES = sorted(PACKAGE.rglob("*.py"))


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


def test_no_module_exceeds_400_lines():
    long = {str(f.relative_to(PACKAGE)): n for f in FILES
            if (n := len(f.read_text().splitlines())) > 400}
    assert not long, f"modules over 400 lines: {long}"
