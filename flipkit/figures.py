"""Figure pipeline: one matplotlib style, reproducible saving, and the notebook runner.

Each figure of DESIGN.md is made by one notebook in ``notebooks/``. A notebook draws with
:mod:`flipkit.plotting` and calls :func:`save`, which writes ``<id>.pdf`` (vector),
``<id>.png`` (300 dpi) and a JSON sidecar ``<id>.json`` (files, caption, numbers).
:func:`run_notebooks` executes the notebooks with papermill and merges the sidecars into
``manifest.json``, the list of every figure, its caption, notebook, parameters and numbers.
"""

from __future__ import annotations

import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from . import __version__
from .errors import FlipkitError, InvalidChoiceError

REPO_ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS_DIR = REPO_ROOT / "notebooks"
FIGURES = {  # figure id -> notebook that makes it (DESIGN.md, "The figures"), in paper order
    "cell": "cell.ipynb", "forces": "forces.ipynb", "subbehaviors": "subbehaviors.ipynb",
    "defects": "defects.ipynb", "translate": "translate.ipynb", "flip": "flip.ipynb",
    "table1": "table1.ipynb", "ik_failure": "ik_failure.ipynb",
    "solve_times": "solve_times.ipynb", "cone_forms": "cone_forms.ipynb",
    "landing": "landing.ipynb", "filmstrip": "landing.ipynb",
    "sensitivity": "sensitivity.ipynb",
}
FIGURE_IDS = tuple(FIGURES)
COLUMN_WIDTH = 3.5  # in, one RA-L column
PAGE_WIDTH = 7.16  # in, both RA-L columns
PNG_DPI = 300
# The kernel's own log (plain-TCP warning, interrupt on shutdown) is noise here; cell errors
# still reach us through the notebook, a dead kernel through nbclient.
KERNEL_QUIET = ["--IPKernelApp.log_level=CRITICAL"]
COLORS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442",
          "#000000")  # Okabe-Ito, colour-blind safe
RC = {
    "font.family": "sans-serif", "font.sans-serif": ["DejaVu Sans"], "font.size": 8,
    "axes.titlesize": 9, "axes.labelsize": 8, "xtick.labelsize": 7, "ytick.labelsize": 7,
    "legend.fontsize": 7, "legend.frameon": False, "lines.linewidth": 1.4,
    "lines.markersize": 4, "axes.grid": True, "grid.color": "0.88", "grid.linewidth": 0.5,
    "axes.spines.top": False, "axes.spines.right": False, "figure.dpi": 100,
    "savefig.dpi": PNG_DPI, "savefig.bbox": "tight", "savefig.pad_inches": 0.02,
    "pdf.fonttype": 42, "ps.fonttype": 42, "svg.hashsalt": "flipkit", "image.cmap": "viridis",
}


class NotebookError(FlipkitError):
    """A figure notebook that failed to execute or did not save its figure."""


class _Style:
    """The flipkit rcParams, applied on creation; as a context manager, restored on exit."""

    def __init__(self):
        import matplotlib as mpl
        from cycler import cycler

        self._saved = {k: mpl.rcParams[k] for k in (*RC, "axes.prop_cycle")}
        mpl.rcParams.update(RC)
        mpl.rcParams["axes.prop_cycle"] = cycler(color=COLORS)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        import matplotlib as mpl

        mpl.rcParams.update(self._saved)
        return False


def style() -> _Style:
    """Apply the flipkit figure style: sans-serif (DejaVu) 7–9 pt text, Okabe-Ito colours,
    light grid, TrueType-embedded PDF fonts, 300 dpi PNG.

    Call it once at the top of a notebook, or use ``with style(): ...`` to restore the
    previous settings afterwards. Figure sizes are in inches: :data:`COLUMN_WIDTH`,
    :data:`PAGE_WIDTH`.
    """
    return _Style()


def _jsonable(value, where: str):
    """``value`` with numpy scalars/arrays turned into Python ones; NaN/inf become None."""
    if isinstance(value, dict):
        return {str(k): _jsonable(v, f"{where}.{k}") for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_jsonable(v, where) for v in (value.tolist() if isinstance(value, np.ndarray)
                                             else value)]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if value is None or isinstance(value, (bool, int, str)):
        return value
    raise FlipkitError(f"figure number {where} is not JSON-serialisable: {type(value).__name__}")


def save(fig, fig_id: str, caption: str, numbers: dict, out_dir="figures") -> list[Path]:
    """Write ``<fig_id>.pdf``, ``<fig_id>.png`` and the sidecar ``<fig_id>.json``.

    The PDF carries fixed metadata (no creation or modification date), so the same figure
    gives byte-identical files; the PNG (``savefig.dpi``, 300) carries no date either.

    Args:
        fig: The matplotlib figure.
        fig_id: One of :data:`FIGURE_IDS`.
        caption: The figure's caption (one or more sentences, units included).
        numbers: The values the figure shows or the caption quotes, by name (SI units,
            named with a unit suffix where not obvious); NaN and inf are stored as null.
        out_dir: Output directory, created if missing.

    Returns:
        The paths of the PDF, the PNG and the sidecar.

    Raises:
        InvalidChoiceError: ``fig_id`` is not a known figure id.
        FlipkitError: Empty caption, or a number that is not JSON-serialisable.
    """
    import matplotlib as mpl

    if fig_id not in FIGURES:
        raise InvalidChoiceError("figure id", fig_id, FIGURE_IDS)
    if not str(caption).strip():
        raise FlipkitError(f"figure {fig_id!r} needs a caption")
    numbers = _jsonable(dict(numbers), "numbers")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    software = f"flipkit {__version__} (matplotlib {mpl.__version__})"
    pdf, png, sidecar = (out / f"{fig_id}.{ext}" for ext in ("pdf", "png", "json"))
    fig.savefig(pdf, format="pdf", metadata={
        "CreationDate": None, "ModDate": None, "Producer": software, "Creator": software,
        "Title": fig_id})
    fig.savefig(png, format="png", dpi=PNG_DPI, metadata={"Software": software})
    entry = {"files": [pdf.name, png.name], "caption": " ".join(str(caption).split()),
             "numbers": numbers}
    sidecar.write_text(json.dumps(entry, indent=2, sort_keys=True) + "\n")
    return [pdf, png, sidecar]


def git_commit(root: Path = REPO_ROOT) -> str | None:
    """The checked-out commit of the repository at ``root``, read from ``.git`` (no git
    process), or None outside a git checkout."""
    gitdir = root / ".git"
    if gitdir.is_file():  # worktree or submodule: "gitdir: <path>"
        gitdir = (root / gitdir.read_text().split(":", 1)[1].strip()).resolve()
    try:
        head = (gitdir / "HEAD").read_text().strip()
        if not head.startswith("ref:"):
            return head or None
        ref = head.split(":", 1)[1].strip()
        common = gitdir / "commondir"
        base = (gitdir / common.read_text().strip()).resolve() if common.is_file() else gitdir
        for where in (gitdir, base):
            if (where / ref).is_file():
                return (where / ref).read_text().strip()
        for line in (base / "packed-refs").read_text().splitlines():
            if line.endswith(" " + ref):
                return line.split()[0]
    except (OSError, IndexError):
        pass
    return None


def kernel_name() -> str:
    """Name of a Jupyter kernelspec that runs this Python (the venv's).

    ``python3`` if it resolves to this interpreter (argv ``python`` is replaced by
    ``sys.executable`` by jupyter_client); otherwise a ``flipkit-python3`` kernelspec, installed
    into ``sys.prefix/share/jupyter/kernels`` on first use.
    """
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
    from ipykernel.kernelspec import install

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
    import papermill
    from papermill.exceptions import PapermillExecutionError

    try:
        papermill.execute_notebook(str(notebook), str(executed), parameters=parameters,
                                   kernel_name=kernel, language="python", cwd=str(REPO_ROOT),
                                   progress_bar=False, extra_arguments=KERNEL_QUIET)
    except PapermillExecutionError as exc:
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


# ------------------------------------------------------------------ LaTeX macros
MACRO_HEADER = r"""% Made by flipkit.figures.write_macros from figures/manifest.json; do not edit.
% \fknum{<figure id>}{<number key>} prints a number of the manifest (nested keys joined by
% ".", list items numbered from 1); \fkmm and \fkpct print metre values in mm and ratios
% in %; \fkmeta{<key>} prints run metadata and the package's configuration (config.*);
% \fkcaption{<figure id>} the figure's caption. An unknown key prints a bold "??" and
% logs "flipkit: undefined number macro <name>".
\providecommand{\fkdef}[3]{\expandafter\def\csname fk@#1@#2\endcsname{#3}}
\providecommand{\fkdefmm}[3]{\expandafter\def\csname fkmm@#1@#2\endcsname{#3}}
\providecommand{\fkdefpct}[3]{\expandafter\def\csname fkpct@#1@#2\endcsname{#3}}
\providecommand{\fkdefmeta}[2]{\expandafter\def\csname fkmeta@#1\endcsname{#2}}
\providecommand{\fkdefcaption}[2]{\expandafter\def\csname fkcaption@#1\endcsname{#2}}
\providecommand{\fklookup}[1]{\ifcsname #1\endcsname\csname #1\endcsname\else
  \textbf{??}\typeout{flipkit: undefined number macro #1}\fi}
\providecommand{\fknum}[2]{\fklookup{fk@#1@#2}}
\providecommand{\fkmm}[2]{\fklookup{fkmm@#1@#2}}
\providecommand{\fkpct}[2]{\fklookup{fkpct@#1@#2}}
\providecommand{\fkmeta}[1]{\fklookup{fkmeta@#1}}
\providecommand{\fkcaption}[1]{\fklookup{fkcaption@#1}}
"""
_TEX_SPECIAL = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
                "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                "^": r"\textasciicircum{}", "<": r"\textless{}", ">": r"\textgreater{}",
                "|": r"\textbar{}", "μ": r"$\mu$", "δ": r"$\delta$", "ξ": r"$\xi$",
                "→": r"$\rightarrow$", "≤": r"$\le$", "≥": r"$\ge$", "°": r"$^\circ$",
                "±": r"$\pm$", "×": r"$\times$", "−": "-", "–": "--", "—": "---", "²": r"$^2$",
                "·": r"$\cdot$", "’": "'", "‘": "`", "ᵀ": r"$^\top$", "√": r"$\surd$"}


def flatten_numbers(numbers, prefix: str = "") -> list[tuple[str, object]]:
    """The scalar leaves of a figure's ``numbers``: (key, value), nested dict keys joined by
    ``.`` and list items numbered from 1 (``segment_max_error_m.3``), in the stored order.
    One leaf is one LaTeX macro of :func:`write_macros`."""
    if isinstance(numbers, dict):
        items = list(numbers.items())
    elif isinstance(numbers, (list, tuple)):
        items = [(str(k), v) for k, v in enumerate(numbers, 1)]
    else:
        return [(prefix, numbers)]
    out = []
    for key, value in items:
        out += flatten_numbers(value, f"{prefix}.{key}" if prefix else str(key))
    return out


def tex_escape(text: str) -> str:
    """``text`` with LaTeX's special characters escaped (for plain-text macro bodies)."""
    return "".join(_TEX_SPECIAL.get(c, c) for c in str(text))


def format_number(value, digits: int = 3) -> str:
    """A manifest value as LaTeX text: floats rounded to ``digits`` significant digits,
    trailing zeros dropped (scientific, ``\\ensuremath{1.2\\times10^{-5}}``, below 1e-3 or
    from 1e5; negative numbers in ``\\ensuremath`` too, so they work in text and in math),
    integers as they are, booleans as yes/no, None as an en dash, strings escaped."""
    if value is None:
        return "--"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return "--"
        if value == 0:
            return "0"
        if abs(value) < 1e-3 or abs(value) >= 1e5:
            mant, exp = f"{value:.{digits - 1}e}".split("e")
            return f"\\ensuremath{{{mant}\\times10^{{{int(exp)}}}}}"
        decimals = max(digits - 1 - int(math.floor(math.log10(abs(value)))), 0)
        text = f"{value:.{decimals}f}"
        if "." in text:  # 2.00 -> 2, 0.500 -> 0.5
            text = text.rstrip("0").rstrip(".")
        return f"\\ensuremath{{{text}}}" if text.startswith("-") else text
    return tex_escape(value)


def config_constants() -> dict:
    """The configuration values the report quotes, read from the package (not typed by
    hand): friction coefficients (burger-blade ``mu``, burger-grill ``grill_mu`` of the
    simulated cell), the scoop's commanded press into the grill and its band (mm), the
    flip's landing radius (mm), release fraction and node and minimum landing tilt (deg), acceleration limit, burger and spatula
    sizes, grill height, nodes per segment, and the duration bounds T_BOUNDS (s) of every
    segment with their sum over pickup-and-flip."""
    from . import targets as tg
    from .behaviors import (FLIGHT_MARGIN, MU_SAFETY, R_LAND, RELEASE_FRACTION, SCOOP_PRESS,
                            SCOOP_TIP_BAND, T_BOUNDS, SegmentOptions)
    from .config import CellConfig
    from .flight import TILT_MIN_DEG

    cell = CellConfig()
    out = {"mu": cell.burger.mu, "grill_mu": cell.physics.mu_grill,
           "scoop_press_mm": 1e3 * SCOOP_PRESS, "scoop_tip_band_mm": 1e3 * SCOOP_TIP_BAND,
           "r_land_mm": 1e3 * R_LAND, "release_fraction": RELEASE_FRACTION,
           "landing_tilt_min_deg": TILT_MIN_DEG, "mu_safety": MU_SAFETY,
           "scoop_start_margin_mm": 1e3 * tg.SCOOP_START_MARGIN,
           "flight_margin_mm": 1e3 * FLIGHT_MARGIN,
           "release_node": SegmentOptions().release_node(),
           "accel_limit_rad_s2": cell.robot.accel_limit, "burger_diameter_m":
               cell.burger.diameter, "burger_thickness_m": cell.burger.thickness,
           "burger_mass_kg": cell.burger.mass,
           "spatula_length_m": cell.spatula.length, "spatula_width_m": cell.spatula.width,
           "grill_height_m": cell.grill.height, "nodes": SegmentOptions().N + 1,
           "segment_intervals": SegmentOptions().N}
    for name, (lo, hi) in T_BOUNDS.items():
        out[f"T_{name}_min_s"], out[f"T_{name}_max_s"] = lo, hi
    out["T_pickup_and_flip_max_s"] = round(sum(T_BOUNDS[n][1] for n in tg.SUBBEHAVIORS), 9)
    return out


def write_macros(manifest, path) -> Path:
    """Write the LaTeX macro file of a figure manifest (``paper/numbers.tex``).

    One ``\\fkdef{<figure>}{<key>}{<value>}`` per scalar leaf of every figure's ``numbers``
    (:func:`flatten_numbers`), read in the report as ``\\fknum{<figure>}{<key>}``; besides,
    keys ending in ``_m`` get a millimetre version (``\\fkmm``) and ratios and fractions
    (keys ending in ``_ratio`` or containing ``fraction``) a percentage (``\\fkpct``), and
    the run metadata (flipkit version, git commit, per-figure quick flag) and
    :func:`config_constants` (``config.<key>``) ``\\fkmeta``, and every caption
    ``\\fkcaption{<figure>}``.

    Args:
        manifest: The manifest as a dict, or the path of ``manifest.json``.
        path: The ``.tex`` file to write (its directory must exist).

    Returns:
        The path written.
    """
    if not isinstance(manifest, dict):
        manifest = json.loads(Path(manifest).read_text())
    lines = [MACRO_HEADER.rstrip("\n"), ""]
    meta = {"flipkit": manifest.get("flipkit"), "git": (manifest.get("git") or "")[:12] or None}
    for fig_id, entry in sorted(manifest.get("figures", {}).items()):
        params = entry.get("parameters") or {}
        meta[f"{fig_id}.quick"] = params.get("quick")
    meta.update({f"config.{k}": v for k, v in config_constants().items()})
    lines += [f"\\fkdefmeta{{{k}}}{{{format_number(v)}}}" for k, v in meta.items()]
    for fig_id, entry in sorted(manifest.get("figures", {}).items()):
        lines.append(f"% {fig_id} ({entry.get('notebook', '')})")
        lines.append(f"\\fkdefcaption{{{fig_id}}}{{{tex_escape(entry.get('caption', ''))}}}")
        for key, value in flatten_numbers(entry.get("numbers", {})):
            lines.append(f"\\fkdef{{{fig_id}}}{{{key}}}{{{format_number(value)}}}")
            numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
            last = key.rsplit(".", 1)[0] if key.rsplit(".", 1)[-1].isdigit() else key
            if numeric and last.endswith("_m"):
                lines.append(f"\\fkdefmm{{{fig_id}}}{{{key}}}{{{format_number(1e3 * value)}}}")
            if numeric and (last.endswith("_ratio") or "fraction" in last):
                lines.append(f"\\fkdefpct{{{fig_id}}}{{{key}}}"
                             f"{{{format_number(100.0 * value, 3)}\\,\\%}}")
    out = Path(path)
    out.write_text("\n".join(lines) + "\n")
    return out
