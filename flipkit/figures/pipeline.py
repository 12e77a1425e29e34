"""The notebook runner: every figure made by its papermill notebook, and the manifest.

:func:`run_notebooks` executes the notebooks of :mod:`flipkit.figures.catalog` with
papermill and merges the figures' sidecars (:func:`flipkit.figures.style.save`) into
``manifest.json``: every figure, its caption, notebook, parameters and numbers.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from tqdm import tqdm

from flipkit import __version__
from flipkit.errors import FlipkitError, InvalidChoiceError
from flipkit.figures.catalog import FIGURE_IDS, FIGURES, NOTEBOOKS_DIR, REPO_ROOT
from flipkit.provenance import git_commit

# The kernel's own log (plain-TCP warning, interrupt on shutdown) is noise here; cell errors
# still reach us through the notebook, a dead kernel through nbclient.
KERNEL_QUIET = ["--IPKernelApp.log_level=CRITICAL"]


class NotebookError(FlipkitError):
    """A figure notebook that failed to execute or did not save its figure."""

def kernel_name() -> str:
    """Name of a Jupyter kernelspec that runs this Python (the venv's).

    ``python3`` if it resolves to this interpreter (argv ``python`` is replaced by
    ``sys.executable`` by jupyter_client); otherwise a ``flipkit-python3`` kernelspec, installed
    into ``sys.prefix/share/jupyter/kernels`` on first use.
    """
    # Jupyter and papermill load in 0.3-1.5 s, and `flipkit --help` imports this module.
    from jupyter_client.kernelspec import KernelSpecManager, NoSuchKernel

    manager = KernelSpecManager()
    generic = {"python", f"python{sys.version_info[0]}", "python%d.%d" % sys.version_info[:2]}
    for name in ("python3", "flipkit-python3"):
        try:
            argv0 = manager.get_kernel_spec(name).argv[0]
        except NoSuchKernel:
            continue
        if argv0 in generic or Path(argv0).absolute() == Path(sys.executable).absolute():
            return name
    from ipykernel.kernelspec import install  # only when no kernelspec runs this Python

    install(kernel_spec_manager=manager, kernel_name="flipkit-python3", prefix=sys.prefix,
            display_name="Python 3 (flipkit)")
    return "flipkit-python3"


@dataclass
class RunReport:
    """What :func:`run_notebooks` did.

    Attributes:
        made: Figure ids made in this run. missing: Requested ids whose notebook does not exist.
        manifest: Path of the manifest written. wall_time_s: Wall time of the run (s).
    """

    made: list[str] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    manifest: Path | None = None
    wall_time_s: float = 0.0


def _one_line(text) -> str:
    return " ".join(str(text).split())


def _execute(notebook: Path, executed: Path, parameters: dict, kernel: str) -> None:
    """Run one notebook with papermill; any failure becomes a one-line NotebookError."""
    import papermill  # 1.5 s to import, and `flipkit --help` imports this module

    try:
        papermill.execute_notebook(str(notebook), str(executed), parameters=parameters,
                                   kernel_name=kernel, language="python", cwd=str(REPO_ROOT),
                                   progress_bar=False, extra_arguments=KERNEL_QUIET)
    except papermill.PapermillExecutionError as exc:
        raise NotebookError(
            f"notebook {notebook.name} failed at cell In [{exc.exec_count}]: {exc.ename}: "
            f"{_one_line(exc.evalue)} (executed copy: {executed})") from None
    except Exception as exc:  # kernel died, missing kernel, unreadable notebook, ...
        raise NotebookError(f"notebook {notebook.name} could not run: {type(exc).__name__}: "
                            f"{_one_line(exc)}") from exc


def run_notebooks(quick: bool = False, only=None, scheduler: str | None = None,
                  out_dir="figures", build_dir="build/notebooks") -> RunReport:
    """Execute the figure notebooks and write ``<out_dir>/manifest.json``.

    Args:
        quick: Passed to the notebooks: fewer nodes, trials and locations (minutes, not hours).
        only: Figure ids to make (default: all); their notebooks run once each.
        scheduler: Dask scheduler address passed to the notebooks (None: local processes).
        out_dir: Figure directory (relative to the current directory).
        build_dir: Where the executed notebooks are written.

    Returns:
        A :class:`RunReport`; ids whose notebook does not exist yet are in ``missing``.
        The manifest also keeps the figures of earlier runs into ``out_dir`` (each entry with
        its own parameters) as long as their files exist.

    Raises:
        InvalidChoiceError: An unknown figure id in ``only``.
        NotebookError: A notebook failed (its name and the failing cell's error, one line)
            or did not save the figure it is listed for.
    """
    start = time.perf_counter()
    wanted = list(dict.fromkeys(only)) if only else list(FIGURE_IDS)
    for fig_id in wanted:
        if fig_id not in FIGURES:
            raise InvalidChoiceError("figure id", fig_id, FIGURE_IDS)
    out, build = Path(out_dir).absolute(), Path(build_dir).absolute()
    report = RunReport(missing=[i for i in wanted if not (NOTEBOOKS_DIR / FIGURES[i]).is_file()])
    jobs: dict[str, list[str]] = {}
    for fig_id in wanted:
        if fig_id not in report.missing:
            jobs.setdefault(FIGURES[fig_id], []).append(fig_id)
    out.mkdir(parents=True, exist_ok=True)
    build.mkdir(parents=True, exist_ok=True)
    params = {"quick": bool(quick), "out_dir": str(out), "scheduler": scheduler}
    recorded = {"quick": bool(quick), "out_dir": str(out_dir), "scheduler": scheduler}
    kernel = kernel_name() if jobs else "python3"
    bar = tqdm(jobs.items(), desc="notebooks", unit="nb", disable=not jobs, file=sys.stderr)
    for notebook, ids in bar:
        bar.set_postfix_str(notebook)
        for fig_id in ids:
            (out / f"{fig_id}.json").unlink(missing_ok=True)
        _execute(NOTEBOOKS_DIR / notebook, build / notebook, params, kernel)
        for fig_id in ids:
            sidecar = out / f"{fig_id}.json"
            if not sidecar.is_file():
                raise NotebookError(f"notebook {notebook} ran but did not save figure "
                                    f"{fig_id!r} (no figures.save(fig, {fig_id!r}, ...))")
            entry = json.loads(sidecar.read_text())
            entry.update(notebook=f"notebooks/{notebook}", parameters=recorded)
            sidecar.write_text(json.dumps(entry, indent=2, sort_keys=True) + "\n")
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
