"""The core and the extras: what ``pip install flipkit`` needs, and what each extra adds.

The core (model, transcription, behaviours, solvers, plans, verify, export, planners, the
baseline, and the command line's ``plan``, ``verify``, ``export``, ``atlas`` and
``compare-ik``) installs with the dependencies of ``pyproject.toml``; the simulation, the
kitchen scheduler, the viewer and the lab (figures, notebooks, Dask sweeps) are extras:
``pip install 'flipkit[sim,kitchen,viewer,lab]'``. ``tests/test_layers.py`` checks that
importing a core module imports only the standard library and the core's dependencies, and
that :data:`EXTRAS` lists pyproject's extras; ``tests/test_core_install.py`` installs the
core alone and runs it. A command that needs a missing extra fails with one line,
:func:`missing_extra_message`.
"""

from __future__ import annotations

# Extra of pyproject.toml -> the top-level import names of its packages (the first extra
# that lists a name is the one named when it is missing).
EXTRAS = {
    "sim": ("mujoco", "matplotlib"),
    "kitchen": ("ortools",),
    "viewer": ("meshcat",),
    "lab": ("papermill", "nbformat", "nbclient", "jupyter_client", "ipykernel", "jupyterlab",
            "dask", "distributed", "matplotlib"),
}
# The sub-commands that need an extra, with it (the others need the core alone).
COMMAND_EXTRAS = {"animate": ("sim",), "validate": ("sim",), "schedule": ("kitchen", "sim"),
                  "view": ("viewer",), "figures": ("lab",)}
# The core, packages (with their submodules) then single modules. The command line's
# argument modules (``flipkit.cli`` and ``flipkit.cli.<command>``) are core too: every
# ``flipkit`` run imports them; the work of a command (``flipkit.cli.commands.<command>``) is
# core only where named here.
CORE_PACKAGES = ("flipkit.config", "flipkit.model", "flipkit.transcription",
                 "flipkit.behaviors", "flipkit.solvers", "flipkit.planning.plans",
                 "flipkit.planning.planners", "flipkit.baseline")
CORE_MODULES = ("flipkit", "flipkit.__main__", "flipkit.errors", "flipkit.provenance",
                "flipkit.fileio", "flipkit.jsonread", "flipkit.decimal_text",
                "flipkit.csv_header", "flipkit.import_graph", "flipkit.extras",
                "flipkit.planning", "flipkit.experiments", "flipkit.experiments.sweep",
                "flipkit.experiments.executors", "flipkit.experiments.worker_pool",
                "flipkit.experiments.atlas", "flipkit.experiments.compare_ik",
                "flipkit.cli.commands", "flipkit.cli.commands.plan",
                "flipkit.cli.commands.verify", "flipkit.cli.commands.export",
                "flipkit.cli.commands.atlas", "flipkit.cli.commands.compare_ik")


def is_core(module: str) -> bool:
    """Whether the dotted module belongs to the core (see :data:`CORE_MODULES`)."""
    return (module in CORE_MODULES
            or any(module == p or module.startswith(p + ".") for p in CORE_PACKAGES)
            or (module.startswith("flipkit.cli") and not module.startswith("flipkit.cli.commands")))


def extra_of(name: str) -> str | None:
    """The extra that installs the top-level import name ``name``, or None."""
    return next((extra for extra, names in EXTRAS.items() if name in names), None)


def missing_extra_message(command: str | None, missing: str | None) -> str | None:
    """One line saying which extra the sub-command ``command`` needs, given the name of the
    module that could not be imported (``ModuleNotFoundError.name``): the extra of that
    module, else the command's own (a package its extra brings along, such as matplotlib's
    cycler); None for a module of flipkit, and for a command of the core missing a module of
    no extra (a broken install, not a missing extra)."""
    top = (missing or "").split(".")[0]
    own = COMMAND_EXTRAS.get(command or "", ())
    needed = [e for e in own if top in EXTRAS[e]] or (
        [extra_of(top)] if extra_of(top) else list(own[:1]))
    if top in ("", "flipkit") or not needed:
        return None
    what = f"flipkit {command}" if command else "this command"
    return (f"{what} needs the '{needed[0]}' extra (no module named {top!r}): "
            f"pip install 'flipkit[{needed[0]}]'")
