"""The notebook runner: every figure made by its papermill notebook, and the manifest.

:func:`run_notebooks` executes the notebooks of :mod:`flipkit.figures.catalog` with
papermill (:mod:`flipkit.figures.execute`) and merges the figures' sidecars
(:func:`flipkit.figures.style.save`) into ``manifest.json``: every figure, its caption,
notebook, parameters, numbers and the hash of its inputs (:mod:`flipkit.figures.inputs`).
A notebook whose figures exist and carry the current hash is skipped, not re-executed.

Notebooks that declare a ``cache_dir`` parameter get one sweep cache
(:func:`flipkit.experiments.sweep.run_sweep`) shared by the run, :func:`sweep_cache`:
``<build>/../figure-cache/<code version>``, so a plan or a trial that several figures need
(the Table I plans, the Table I trials that the landing and sensitivity figures repeat) is
computed once. The directory is named by :func:`flipkit.figures.inputs.code_digest` of the
whole package, the package data and ``environment.lock``; directories of other versions are
removed, so no result of other code is ever read, and ``force`` starts the version's
directory empty, so that a forced run computes every result again (once).
"""

from __future__ import annotations

import json
import re
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from tqdm import tqdm

from flipkit import __version__
from flipkit.errors import InvalidChoiceError
from flipkit.figures.catalog import FIGURE_IDS, FIGURES
from flipkit.figures.execute import NotebookError, execute_notebook, kernel_name
from flipkit.figures.inputs import (UNHASHED_PARAMETERS, Inputs, changed, code_digest,
                                    hash_inputs)
from flipkit.import_graph import import_graph
from flipkit.provenance import git_commit


@dataclass
class RunReport:
    """What :func:`run_notebooks` did.

    Attributes:
        made: Requested figure ids made in this run (a notebook's other figures are
            remade and recorded too). missing: Requested ids whose notebook does not exist.
        ran: Notebook name → why it ran. skipped: Notebook name → why it was skipped.
        manifest: Path of the manifest written. wall_time_s: Wall time of the run (s).
        times_s: Notebook name → wall time of its execution (s), for those that ran.
    """

    made: list[str] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    ran: dict[str, str] = field(default_factory=dict)
    skipped: dict[str, str] = field(default_factory=dict)
    manifest: Path | None = None
    wall_time_s: float = 0.0
    times_s: dict[str, float] = field(default_factory=dict)


def stale_reason(out: Path, ids, inputs: Inputs, parameters: dict) -> str | None:
    """Why the figures ``ids`` of one notebook in ``out`` must be made again, or None if each
    exists (its sidecar and files) and was made from ``inputs``."""
    for fig_id in ids:
        try:
            entry = json.loads((out / f"{fig_id}.json").read_text())
        except (OSError, ValueError):
            return f"no figure {fig_id!r} in {out}"
        lost = [name for name in entry.get("files", []) if not (out / name).is_file()]
        if lost:
            return f"{lost[0]} is missing"
        if not entry.get("inputs"):
            return f"{fig_id!r} has no inputs hash (made before incremental builds)"
        parts = changed(entry["inputs"], inputs)
        if "parameters" in parts:
            old = entry.get("parameters") or {}
            parts[parts.index("parameters")] = "parameters (" + ", ".join(
                f"{k} {old.get(k)!r} -> {v!r}" for k, v in parameters.items()
                if k not in UNHASHED_PARAMETERS and old.get(k) != v) + ")"
        if parts or entry["inputs"].get("hash") != inputs.digest:
            return "changed: " + (", ".join(parts) or "inputs hash")
    return None


CACHE_VERSION_NAME = re.compile(r"[0-9a-f]{16}")  # sweep_cache's directory names


def sweep_cache(root, digest: str, fresh: bool = False) -> Path:
    """The sweep cache directory of the current code, ``root/<digest[:16]>``, created.

    Args:
        root: Directory holding one cache directory per code version.
        digest: The code version (:func:`flipkit.figures.inputs.code_digest`).
        fresh: Empty this version's directory first (a forced run).

    The directories of other versions under ``root`` (names of 16 hex digits; nothing else
    is touched) are removed: their results were computed by other code.
    """
    root = Path(root)
    name = digest[:16]
    if root.is_dir():
        for old in root.iterdir():
            if old.is_dir() and CACHE_VERSION_NAME.fullmatch(old.name) and (
                    fresh or old.name != name):
                shutil.rmtree(old)
    path = root / name
    path.mkdir(parents=True, exist_ok=True)
    return path


def declared_parameters(notebook: Path) -> set[str]:
    """The names assigned in a notebook's ``parameters``-tagged cell."""
    try:
        cells = json.loads(Path(notebook).read_text(encoding="utf-8"))["cells"]
    except (OSError, ValueError, KeyError):
        return set()
    names = set()
    for cell in cells:
        if "parameters" in (cell.get("metadata") or {}).get("tags", []):
            for line in "".join(cell.get("source", "")).splitlines():
                match = re.match(r"([A-Za-z_]\w*)\s*(?::[^=]*)?=", line)
                if match:
                    names.add(match.group(1))
    return names


def run_notebooks(quick: bool = False, only=None, scheduler: str | None = None,
                  out_dir="figures", build_dir="build/notebooks", force: bool = False,
                  log: Callable[[str], None] | None = None,
                  notebooks_dir="notebooks", cache_root=None) -> RunReport:
    """Execute the figure notebooks whose inputs changed and write ``<out_dir>/manifest.json``.

    Args:
        quick: Passed to the notebooks: fewer nodes, trials and locations (minutes, not hours).
        only: Figure ids to make (default: all); their notebooks run once each (a
            notebook that runs remakes all its figures, ``landing`` and ``filmstrip``).
        scheduler: Dask scheduler address passed to the notebooks (None: local processes).
        out_dir: Figure directory (relative to the current directory).
        build_dir: Where the executed notebooks are written.
        force: Execute every selected notebook, up to date or not.
        log: Called with one line per notebook, before any runs: skipped and why, or to
            run and why; then one line as each notebook is made, with its wall time.
        notebooks_dir: Where the notebooks of :data:`~flipkit.figures.catalog.FIGURES` are
            (default: ``notebooks`` in the current directory). Its parent is the project:
            the notebooks run there, and its ``environment.lock`` is hashed with them.
        cache_root: Where the shared sweep cache lives (:func:`sweep_cache`; default
            ``figure-cache`` beside ``build_dir``). ``force`` empties it for this version.

    Returns:
        A :class:`RunReport`; ids whose notebook does not exist yet are in ``missing``.
        The manifest also keeps the figures of earlier runs into ``out_dir`` (each entry with
        its own parameters and inputs hash) as long as their files exist.

    Raises:
        InvalidChoiceError: An unknown figure id in ``only``.
        NotebookError: A notebook failed (its name and the failing cell's error, one line)
            or did not save the figure it is listed for.
        NotebookInputsError: A notebook's cells cannot be read to hash them.
    """
    start, log = time.perf_counter(), log or (lambda line: None)
    wanted = list(dict.fromkeys(only)) if only else list(FIGURE_IDS)
    for fig_id in wanted:
        if fig_id not in FIGURES:
            raise InvalidChoiceError("figure id", fig_id, FIGURE_IDS)
    out, build = Path(out_dir).absolute(), Path(build_dir).absolute()
    notebooks_dir = Path(notebooks_dir).absolute()
    project = notebooks_dir.parent
    lock = project / "environment.lock"
    report = RunReport(missing=[i for i in wanted
                                if not (notebooks_dir / FIGURES[i]).is_file()])
    recorded = {"quick": bool(quick), "out_dir": str(out_dir), "scheduler": scheduler}
    graph, jobs = import_graph(), {}
    for notebook in dict.fromkeys(FIGURES[i] for i in wanted if i not in report.missing):
        ids = [i for i in FIGURE_IDS if FIGURES[i] == notebook]
        inputs = hash_inputs(notebooks_dir / notebook, recorded, lock, graph)
        reason = "--force" if force else stale_reason(out, ids, inputs, recorded)
        if reason is None:
            report.skipped[notebook] = (f"up to date (inputs {inputs.digest[:19]}, "
                                        f"{len(inputs.modules)} flipkit modules)")
            log(f"skip {notebook}: {report.skipped[notebook]}")
        else:
            jobs[notebook], report.ran[notebook] = (ids, inputs), reason
            log(f"run  {notebook}: {reason}")
    out.mkdir(parents=True, exist_ok=True)
    build.mkdir(parents=True, exist_ok=True)
    params = {"quick": bool(quick), "out_dir": str(out), "scheduler": scheduler}
    cached = {nb for nb in jobs if "cache_dir" in declared_parameters(notebooks_dir / nb)}
    cache = (sweep_cache(Path(cache_root or build.parent / "figure-cache").absolute(),
                         code_digest(lock), fresh=force) if cached else None)
    kernel = kernel_name() if jobs else "python3"
    bar = tqdm(jobs.items(), desc="notebooks", unit="nb", disable=not jobs, file=sys.stderr)
    for notebook, (ids, inputs) in bar:
        bar.set_postfix_str(notebook)
        for fig_id in ids:
            (out / f"{fig_id}.json").unlink(missing_ok=True)
        extra = {"cache_dir": str(cache)} if notebook in cached else {}
        began = time.perf_counter()
        execute_notebook(notebooks_dir / notebook, build / notebook, {**params, **extra},
                         kernel, cwd=project)
        report.times_s[notebook] = time.perf_counter() - began
        log(f"made {notebook} in {report.times_s[notebook]:.1f} s")
        for fig_id in ids:
            sidecar = out / f"{fig_id}.json"
            if not sidecar.is_file():
                raise NotebookError(f"notebook {notebook} ran but did not save figure "
                                    f"{fig_id!r} (no figures.save(fig, {fig_id!r}, ...))")
            entry = json.loads(sidecar.read_text())
            entry.update(notebook=f"notebooks/{notebook}", parameters=recorded,
                         inputs=inputs.record())
            sidecar.write_text(json.dumps(entry, indent=2, sort_keys=True) + "\n")
            if fig_id in wanted:
                report.made.append(fig_id)
    report.manifest = write_manifest(out)
    report.wall_time_s = time.perf_counter() - start
    return report


def write_manifest(out_dir="figures") -> Path:
    """Merge the sidecars of ``out_dir`` (figures whose files exist) into ``manifest.json``."""
    out = Path(out_dir)
    entries = {}
    for fig_id in FIGURE_IDS:
        sidecar = out / f"{fig_id}.json"
        if not sidecar.is_file():
            continue
        entry = json.loads(sidecar.read_text())
        if all((out / name).is_file() for name in entry.get("files", [])):
            entry.setdefault("notebook", f"notebooks/{FIGURES[fig_id]}")
            entry.setdefault("parameters", None)
            entries[fig_id] = entry
    manifest = {"flipkit": __version__, "git": git_commit(), "figures": entries}
    path = out / "manifest.json"
    path.write_text(json.dumps(manifest, indent=2, sort_keys=True) + "\n")
    return path
