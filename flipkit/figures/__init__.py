"""Figure layer: every figure of the report (paper/main.tex) made by a papermill notebook.

* :mod:`~flipkit.figures.catalog`: the figure ids and their notebooks;
* :mod:`~flipkit.figures.style`: one matplotlib style, and :func:`save` (PDF, PNG, sidecar);
* :mod:`~flipkit.figures.draw`: the drawing functions (panels, maps, statistics, the cell);
* :mod:`~flipkit.figures.data` and :mod:`~flipkit.figures.runs`: the numbers a figure shows,
  computed from plans and runs;
* :mod:`~flipkit.figures.inputs`: the hash of what a notebook's figures are made from;
* :mod:`~flipkit.figures.execute`: one notebook through papermill, in the venv's kernel;
* :mod:`~flipkit.figures.pipeline`: the runner (only notebooks whose inputs changed) and
  ``manifest.json``;
* :mod:`~flipkit.figures.macros`: ``paper/numbers.tex`` from the manifest.

A notebook imports ``from flipkit import figures`` and calls ``figures.style()`` and
``figures.save(...)``; the names below are the layer's public interface.
"""

from flipkit.figures.catalog import FIGURE_IDS, FIGURES
from flipkit.figures.macros import flatten_numbers, format_number, tex_escape, write_macros
from flipkit.figures.execute import NotebookError, kernel_name
from flipkit.figures.inputs import Inputs, NotebookInputsError, hash_inputs
from flipkit.figures.pipeline import RunReport, run_notebooks, write_manifest
from flipkit.figures.style import COLORS, COLUMN_WIDTH, PAGE_WIDTH, PNG_DPI, save, style

__all__ = ["COLORS", "COLUMN_WIDTH", "FIGURES", "FIGURE_IDS", "PAGE_WIDTH", "PNG_DPI", "Inputs",
           "NotebookError", "NotebookInputsError", "RunReport", "flatten_numbers",
           "format_number", "hash_inputs", "kernel_name", "run_notebooks", "save",
           "style", "tex_escape", "write_macros", "write_manifest"]
