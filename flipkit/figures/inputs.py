"""What a figure is made from, hashed, so that a notebook re-runs only when that changes.

A notebook's inputs are

* its cells: type and source (outputs, execution counts and metadata are not inputs, so
  opening and saving it in JupyterLab changes nothing);
* the flipkit modules its code cells import, transitively: the closure of the package's
  import graph (:mod:`flipkit.import_graph`, read with ``ast``), parent packages included;
* the package data, ``flipkit/data/*`` (read by path, never imported);
* the parameters papermill passes (``quick``, ``scheduler``), but not ``out_dir`` and
  ``cache_dir``, which say where the figure and the sweeps' results go, not what they show;
* ``environment.lock``: every third-party version.

Their SHA-256 is stored with each figure in ``manifest.json`` (``"inputs"``), and
:func:`flipkit.figures.pipeline.run_notebooks` skips a notebook whose figures exist and
carry the current hash. jupyter-cache (on PyPI) keys its cache on a notebook's code cells
only, so a change in an imported flipkit module would not re-run a notebook; this manifest
hash is its equivalent with the imported sources in the key. Not seen: names that
``importlib`` loads from strings, files outside the package and the lock, the machine.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

from flipkit.errors import FlipkitError
from flipkit.import_graph import PACKAGE, closure, import_graph, package_modules, source_imports

UNHASHED_PARAMETERS = ("out_dir", "cache_dir")  # where results go, not what they show
PARTS = ("notebook", "sources", "data", "parameters", "environment_lock")
PART_NAMES = {"notebook": "the notebook", "sources": "flipkit sources",
              "data": "package data", "parameters": "parameters",
              "environment_lock": "environment.lock"}


class NotebookInputsError(FlipkitError):
    """A notebook whose cells cannot be read (not JSON, or a code cell that is not Python)."""


@dataclass(frozen=True)
class Inputs:
    """The hashed inputs of one notebook.

    Attributes:
        digest: ``sha256:<hex>`` of all parts. parts: Part name → SHA-256 hex of that part
            (names in :data:`PARTS`). modules: The flipkit modules hashed, sorted.
    """

    digest: str
    parts: dict[str, str]
    modules: tuple[str, ...]

    def record(self) -> dict:
        """The manifest entry: the digest, each part's digest, the number of modules."""
        return {"hash": self.digest, "parts": dict(self.parts), "modules": len(self.modules)}


def sha256(data: bytes) -> str:
    """Hex SHA-256 of ``data``."""
    return hashlib.sha256(data).hexdigest()


def notebook_cells(path: Path) -> list[tuple[str, str]]:
    """(cell type, source) of every cell of an ``.ipynb`` file, in order."""
    try:
        cells = json.loads(Path(path).read_text(encoding="utf-8"))["cells"]
        return [(c["cell_type"], "".join(c["source"])) for c in cells]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise NotebookInputsError(f"notebook {Path(path).name}: cannot read its cells "
                                  f"({type(exc).__name__}: {exc})") from None


def python_of_cell(source: str) -> str:
    """A code cell's Python: IPython magics and shell lines (``%``, ``!``) blanked, a cell
    magic (``%%``) cell dropped."""
    if source.lstrip().startswith("%%"):
        return ""
    return "\n".join("" if line.lstrip()[:1] in ("%", "!") else line
                     for line in source.splitlines())


def notebook_modules(path: Path, graph: dict[str, set[str]], root: Path = PACKAGE) -> set[str]:
    """The modules of the package at ``root`` that running the notebook's code imports."""
    modules, start = package_modules(root), set()
    for k, (kind, source) in enumerate(notebook_cells(path)):
        if kind != "code":
            continue
        try:
            start |= {i.target for i in source_imports(python_of_cell(source), root=root,
                                                       modules=modules)}
        except SyntaxError as exc:
            raise NotebookInputsError(f"notebook {Path(path).name}: code cell {k + 1} is not "
                                      f"Python (line {exc.lineno}: {exc.msg})") from None
    return closure(graph, start)


def hash_inputs(notebook: Path, parameters: dict, lock: Path,
                graph: dict[str, set[str]] | None = None, root: Path = PACKAGE) -> Inputs:
    """Hash a notebook's inputs (see the module's docstring).

    Args:
        notebook: The ``.ipynb`` file.
        parameters: The parameters papermill passes; ``out_dir`` is left out.
        lock: The project's ``environment.lock`` (a missing one hashes as absent).
        graph: The package's import graph (default: :func:`flipkit.import_graph.import_graph`
            of ``root``; pass it when hashing several notebooks).
        root: The package directory.

    Raises:
        NotebookInputsError: The notebook cannot be read, or a code cell is not Python.
    """
    graph = import_graph(root) if graph is None else graph
    modules = tuple(sorted(notebook_modules(notebook, graph, root)))
    files = {m: module_file(m, root) for m in modules}
    data = sorted(p for p in (Path(root) / "data").rglob("*") if p.is_file())
    kept = {k: v for k, v in parameters.items() if k not in UNHASHED_PARAMETERS}
    parts = {
        "notebook": sha256(json.dumps(notebook_cells(notebook)).encode()),
        "sources": sha256(json.dumps([(m, sha256(files[m].read_bytes())) for m in modules])
                          .encode()),
        "data": sha256(json.dumps([(p.relative_to(root).as_posix(), sha256(p.read_bytes()))
                                   for p in data]).encode()),
        "parameters": sha256(json.dumps(kept, sort_keys=True, default=str).encode()),
        "environment_lock": sha256(Path(lock).read_bytes()) if Path(lock).is_file()
        else "absent",
    }
    digest = "sha256:" + sha256(json.dumps(parts, sort_keys=True).encode())
    return Inputs(digest, parts, modules)


def code_digest(lock: Path, root: Path = PACKAGE) -> str:
    """SHA-256 hex of every file of the package at ``root`` (sources and data, by relative
    path) and of ``lock``: the code version a cached sweep result was computed with.

    Wider than a notebook's :func:`hash_inputs` on purpose: a sweep worker may load code the
    notebook does not import, so any change anywhere in the package makes a new version.
    """
    root = Path(root)
    files = sorted(p for p in root.rglob("*") if p.is_file() and "__pycache__" not in p.parts
                   and p.suffix not in (".pyc", ".pyo"))
    listed = [(p.relative_to(root).as_posix(), sha256(p.read_bytes())) for p in files]
    locked = sha256(Path(lock).read_bytes()) if Path(lock).is_file() else "absent"
    return sha256(json.dumps([listed, locked]).encode())


def module_file(module: str, root: Path = PACKAGE) -> Path:
    """The source file of a dotted module of the package at ``root``."""
    base = Path(root).parent.joinpath(*module.split("."))
    return base / "__init__.py" if base.is_dir() else base.with_suffix(".py")


def changed(recorded: dict | None, current: Inputs) -> list[str]:
    """The names (:data:`PART_NAMES`) of the parts that differ from a recorded entry."""
    parts = (recorded or {}).get("parts") or {}
    return [PART_NAMES[p] for p in PARTS if parts.get(p) != current.parts[p]]
