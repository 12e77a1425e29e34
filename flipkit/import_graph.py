"""The package's import graph, read from the source with ``ast`` (nothing is imported).

Every import statement counts, at module level and inside functions alike (a lazy import
that runs is still a dependency); imports under ``if TYPE_CHECKING:`` are marked
``typing_only`` and left out of :func:`import_graph`. Names loaded by ``importlib`` from a
string (``flipkit.__getattr__``) are not seen. ``tests/test_layers.py`` checks the layer
rules on this graph, and (with :func:`external_imports`) that importing the core
(:mod:`flipkit.extras`) imports only the core's dependencies; :mod:`flipkit.figures.inputs`
hashes the sources a notebook imports.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Iterator

PACKAGE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Import:
    """One name brought in by an import statement of a flipkit module.

    ``target`` is the flipkit module the name comes from — the submodule itself for
    ``from flipkit.x import y`` when ``y`` is a module — and ``name`` the imported attribute
    (``None`` for a module). ``local``: inside a function. ``typing_only``: under
    ``if TYPE_CHECKING:`` (never executed). ``line``: the statement's line (1-based).
    """

    line: int
    target: str
    name: str | None
    local: bool
    typing_only: bool


def package_files(root: Path = PACKAGE) -> list[Path]:
    """Every ``.py`` file of the package at ``root``, sorted."""
    return sorted(Path(root).rglob("*.py"))


def module_name(path: Path, root: Path = PACKAGE) -> str:
    """The dotted name of a module file of the package at ``root`` (``flipkit.model.robot``)."""
    rel = Path(path).relative_to(Path(root).parent).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def package_modules(root: Path = PACKAGE) -> frozenset[str]:
    """The dotted names of every module of the package at ``root``."""
    return frozenset(module_name(f, root) for f in package_files(root))


def is_type_checking(test: ast.expr) -> bool:
    """Whether an ``if`` test is ``TYPE_CHECKING`` or ``typing.TYPE_CHECKING``."""
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def import_statements(tree: ast.AST) -> Iterator[tuple[ast.stmt, bool, bool]]:
    """(import statement, inside a function, under ``if TYPE_CHECKING``) of every import."""
    def walk(node, local, typing_only):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                yield child, local, typing_only
            in_function = isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
            if isinstance(child, ast.If) and is_type_checking(child.test):
                for stmt in child.body:
                    yield from walk(ast.Module(body=[stmt], type_ignores=[]), local, True)
                for stmt in child.orelse:  # the else branch runs
                    yield from walk(ast.Module(body=[stmt], type_ignores=[]), local,
                                    typing_only)
                continue
            yield from walk(child, local or in_function, typing_only)

    yield from walk(tree, False, False)


def resolve(dotted: str, modules: Iterable[str]) -> str:
    """The longest prefix of ``dotted`` that is one of ``modules``."""
    while dotted not in modules and "." in dotted:
        dotted = dotted.rpartition(".")[0]
    return dotted


def source_imports(source: str, module: str = "", is_package: bool = False,
                   root: Path = PACKAGE, modules: Iterable[str] | None = None) -> list[Import]:
    """Every import of a module of the package at ``root`` in Python ``source``.

    Args:
        source: Python source text.
        module: Its dotted name if it is a module of the package (relative imports resolve
            against it), ``""`` for code outside the package (a notebook's cells).
        is_package: ``module`` is a package (its ``__init__.py``).
        root: The package directory; its name is the top-level name (``flipkit``).
        modules: The package's module names (default: :func:`package_modules` of ``root``).
    """
    modules = package_modules(Path(root)) if modules is None else modules
    top = Path(root).name
    package = module if is_package else module.rpartition(".")[0]
    out = []
    for node, local, typing_only in import_statements(ast.parse(source)):
        if isinstance(node, ast.Import):
            out += [Import(node.lineno, resolve(a.name, modules), None, local, typing_only)
                    for a in node.names if a.name.split(".")[0] == top]
            continue
        if node.level:
            base = package.split(".")[: len(package.split(".")) - node.level + 1]
            target = ".".join(base + ([node.module] if node.module else []))
        else:
            target = node.module or ""
        if target.split(".")[0] != top:
            continue
        for a in node.names:
            sub = f"{target}.{a.name}"
            out.append(Import(node.lineno, sub, None, local, typing_only) if sub in modules
                       else Import(node.lineno, resolve(target, modules), a.name, local,
                                   typing_only))
    return out


def flipkit_imports(path: Path, root: Path = PACKAGE,
                    modules: Iterable[str] | None = None) -> list[Import]:
    """Every flipkit name imported by a module file of the package, with its module."""
    path = Path(path)
    return source_imports(path.read_text(), module_name(path, root), path.name == "__init__.py",
                          root, modules)


def external_imports(path: Path) -> list[tuple[int, str, bool]]:
    """(line, top-level name, inside a function) of every import of a package other than
    flipkit in the file (``import a.b`` and ``from a.b import c``: ``a``); relative imports
    and ``TYPE_CHECKING`` imports are left out."""
    out = []
    for node, local, typing_only in import_statements(ast.parse(Path(path).read_text())):
        if typing_only:
            continue
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            names = [node.module] if node.module and not node.level else []
        out += [(node.lineno, n.split(".")[0], local) for n in names
                if n.split(".")[0] != PACKAGE.name]
    return out


def local_imports(path: Path) -> list[int]:
    """Lines of the import statements (of any package) inside a function of the file."""
    return [node.lineno for node, local, _ in import_statements(ast.parse(Path(path).read_text()))
            if local]


def import_graph(root: Path = PACKAGE) -> dict[str, set[str]]:
    """Module → the other modules of the package it imports when it runs (``TYPE_CHECKING``
    imports are annotations, not dependencies)."""
    modules, graph = package_modules(root), {}
    for f in package_files(root):
        name = module_name(f, root)
        graph[name] = {i.target for i in flipkit_imports(f, root, modules)
                       if not i.typing_only and i.target != name}
    return graph


def closure(graph: dict[str, set[str]], start: Iterable[str]) -> set[str]:
    """The modules that importing ``start`` runs: the modules reachable in ``graph``, each
    with its parent packages (``import a.b.c`` runs ``a``, ``a.b`` and ``a.b.c``)."""
    seen: set[str] = set()
    todo = list(start)
    while todo:
        module = todo.pop()
        if module in seen or module not in graph:
            continue
        seen.add(module)
        parts = module.split(".")
        todo += [".".join(parts[:k]) for k in range(1, len(parts))]
        todo += graph[module]
    return seen
