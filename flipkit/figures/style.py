"""One matplotlib style for every figure, and reproducible saving (PDF, PNG, JSON sidecar).

A notebook draws with :mod:`flipkit.figures.draw` and calls :func:`save`, which writes
``<id>.pdf`` (vector), ``<id>.png`` (300 dpi) and a JSON sidecar ``<id>.json`` (files,
caption, numbers) that :mod:`flipkit.figures.pipeline` merges into the manifest.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from flipkit import __version__
from flipkit.errors import FlipkitError, InvalidChoiceError
from flipkit.figures.catalog import FIGURE_IDS, FIGURES

COLUMN_WIDTH = 3.5  # in, one RA-L column
PAGE_WIDTH = 7.16  # in, both RA-L columns
PNG_DPI = 300
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
# Semantic colours: the paper's where it names them (Figs. 6-7: desired red, actual blue).
DESIRED_COLOR, ACTUAL_COLOR = "#D55E00", "#0072B2"  # paper Figs. 6-7: desired red, actual blue
SOLVER_COLORS = {"sqp": "#0072B2", "ipopt": "#E69F00", "ipopt_exact": "#D55E00",
                 "fatrop": "#009E73", "sqpmethod": "#CC79A7"}
SOLVER_LABELS = {"sqp": "SQP (cvxpy/OSQP)", "ipopt": "IPOPT (L-BFGS, MUMPS)",
                 "ipopt_exact": "IPOPT (exact Hessian, MUMPS)", "fatrop": "FATROP",
                 "sqpmethod": "CasADi sqpmethod (HPIPM)"}
BURGER_COLOR = "#8B4513"
# both admit, physical only, paper only, neither
CONE_CLASS_COLORS = ("#CFE8D8", "#0072B2", "#D55E00", "white")


class _Style:
    """The flipkit rcParams, applied on creation; as a context manager, restored on exit."""

    def __init__(self):
        import matplotlib as mpl  # not at the top: `flipkit --help` imports this module

        self._rc = mpl.rcParams
        self._saved = {k: self._rc[k] for k in (*RC, "axes.prop_cycle")}
        self._rc.update(RC)
        self._rc["axes.prop_cycle"] = mpl.cycler(color=COLORS)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._rc.update(self._saved)
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
    import matplotlib as mpl  # not at the top: `flipkit --help` imports this module

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
