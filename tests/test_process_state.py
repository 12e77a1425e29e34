"""No state hides in the process: the package keeps no process-global mutable cache.

What is reused from one call to the next lives in an object its owner makes and passes down
(:class:`flipkit.planning.planners.caches.PlannerCaches`,
:class:`flipkit.baseline.problems.CompiledProblems`,
:class:`flipkit.planning.kitchen.cpsat_process.Child`). The test reads every module with
``ast`` and fails on what would keep state in the module instead: a ``global`` statement,
``functools.lru_cache`` / ``functools.cache``, ``threading.local()``, or an empty dict, list
or set made at module level to be filled later.
"""

from __future__ import annotations

import ast
from pathlib import Path

import flipkit

PACKAGE = Path(flipkit.__file__).parent
CACHE_DECORATORS = {"lru_cache", "cache"}
EMPTY_CALLS = {"dict", "list", "set", "defaultdict", "OrderedDict", "WeakValueDictionary",
               "WeakKeyDictionary", "local"}


def _name(node) -> str | None:
    """The last name of ``f`` or ``a.b.f`` (a call's function, a decorator)."""
    node = node.func if isinstance(node, ast.Call) else node
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else None


def _empty(value) -> bool:
    """An empty container literal, or a call making one (``dict()``, ``threading.local()``)."""
    if isinstance(value, (ast.Dict, ast.List, ast.Set)):
        return not (getattr(value, "keys", None) or getattr(value, "elts", None))
    return isinstance(value, ast.Call) and not value.args and not value.keywords and \
        _name(value) in EMPTY_CALLS


def process_state(source: str) -> list[tuple[int, str]]:
    """(line, what) of each place in a module's ``source`` that keeps process-global state."""
    tree, found = ast.parse(source), []
    for node in ast.walk(tree):
        if isinstance(node, ast.Global):
            found.append((node.lineno, "global " + ", ".join(node.names)))
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            found += [(d.lineno, f"@{_name(d)}") for d in node.decorator_list
                      if _name(d) in CACHE_DECORATORS]
        elif isinstance(node, ast.Call) and _name(node) == "local":
            found.append((node.lineno, "threading.local()"))
    for node in tree.body:  # module level only: an object's own dict is its owner's
        value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
        if value is not None and _empty(value):
            found.append((node.lineno, "an empty container at module level"))
    return found


def test_the_package_keeps_no_process_global_caches():
    found = [f"{path.relative_to(PACKAGE.parent)}:{line}: {what}"
             for path in sorted(PACKAGE.rglob("*.py"))
             for line, what in process_state(path.read_text())]
    assert not found, "process-global state: " + "; ".join(found)


def test_the_checker_finds_each_kind():
    planted = "\n".join([
        "import functools, threading",
        "_CACHE: dict = {}",
        "SEEN = set()",
        "_local = threading.local()",
        "@functools.lru_cache(maxsize=None)",
        "def f(): pass",
        "@functools.cache",
        "def g(): pass",
        "def h():",
        "    global _CACHE",
        "CONSTANT = {'a': 1}",
        "class C:",
        "    def __init__(self): self._built = {}",
    ])
    # line 4 twice: threading.local() is both a call and a module-level container
    assert sorted(line for line, _ in process_state(planted)) == [2, 3, 4, 4, 5, 7, 10]
