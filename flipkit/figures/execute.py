"""One figure notebook executed by papermill, in a kernel that runs this Python (the venv's).

:func:`kernel_name` finds (or installs) the kernelspec; ``make lab`` registers the same one,
``flipkit-python3`` ("Python 3 (flipkit)"), for JupyterLab; the notebooks' kernelspec names
it. :func:`execute_notebook` runs a notebook from the project's root in the kernel that
:func:`kernel_name` found (papermill's ``kernel_name`` replaces the notebook's own, so a
fresh clone where ``make lab`` never ran needs no registered kernel) and turns any failure
into a one-line :class:`NotebookError`.
"""

from __future__ import annotations

import sys
from pathlib import Path

from flipkit.errors import FlipkitError

# The kernel's own log (plain-TCP warning, interrupt on shutdown) is noise here; cell errors
# still reach us through the notebook, a dead kernel through nbclient.
KERNEL_QUIET = ["--IPKernelApp.log_level=CRITICAL"]
KERNEL_NAME, KERNEL_DISPLAY_NAME = "flipkit-python3", "Python 3 (flipkit)"


class NotebookError(FlipkitError):
    """A figure notebook that failed to execute or did not save its figure."""


def kernel_name() -> str:
    """Name of a Jupyter kernelspec that runs this Python (the venv's).

    ``python3`` if it resolves to this interpreter (argv ``python`` is replaced by
    ``sys.executable`` by jupyter_client); otherwise a ``flipkit-python3`` kernelspec, installed
    into ``sys.prefix/share/jupyter/kernels`` on first use.
    """
    # Jupyter and papermill are slow to import, and `flipkit --help` imports this module.
    from jupyter_client.kernelspec import KernelSpecManager, NoSuchKernel

    manager = KernelSpecManager()
    generic = {"python", f"python{sys.version_info[0]}", "python%d.%d" % sys.version_info[:2]}
    for name in ("python3", KERNEL_NAME):
        try:
            argv0 = manager.get_kernel_spec(name).argv[0]
        except NoSuchKernel:
            continue
        if argv0 in generic or Path(argv0).absolute() == Path(sys.executable).absolute():
            return name
    from ipykernel.kernelspec import install  # only when no kernelspec runs this Python

    install(kernel_spec_manager=manager, kernel_name=KERNEL_NAME, prefix=sys.prefix,
            display_name=KERNEL_DISPLAY_NAME)
    return KERNEL_NAME


def one_line(text) -> str:
    """``text`` with every run of whitespace (newlines included) as one space."""
    return " ".join(str(text).split())


def execute_notebook(notebook: Path, executed: Path, parameters: dict, kernel: str,
                     cwd: Path) -> None:
    """Run one notebook with papermill in the directory ``cwd`` (the project's root).

    Args:
        notebook: The ``.ipynb`` to run. executed: Where papermill writes the executed copy.
        parameters: Injected after the ``parameters``-tagged cell. kernel: Kernelspec name
            (the notebooks' own kernelspec names ``flipkit-python3``; this one replaces it).
        cwd: The directory the kernel starts in.

    Raises:
        NotebookError: One line: the notebook, the failing cell and its error, or why the
            notebook could not run at all.
    """
    import papermill  # slow to import, and `flipkit --help` imports this module

    try:
        papermill.execute_notebook(str(notebook), str(executed), parameters=parameters,
                                   kernel_name=kernel, language="python", cwd=str(cwd),
                                   progress_bar=False, extra_arguments=KERNEL_QUIET)
    except papermill.PapermillExecutionError as exc:
        raise NotebookError(
            f"notebook {notebook.name} failed at cell In [{exc.exec_count}]: {exc.ename}: "
            f"{one_line(exc.evalue)} (executed copy: {executed})") from None
    except Exception as exc:  # kernel died, missing kernel, unreadable notebook, ...
        raise NotebookError(f"notebook {notebook.name} could not run: {type(exc).__name__}: "
                            f"{one_line(exc)}") from exc
