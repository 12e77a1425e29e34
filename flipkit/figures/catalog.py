"""The figures of the report (paper/main.tex) and the notebooks that make them.

The notebooks are files of the repository, not of the package: the caller says where they
are (``flipkit figures --notebooks DIR``, :func:`flipkit.figures.run_notebooks`).
"""

from __future__ import annotations

FIGURES = {  # figure id -> notebook that makes it, in the report's order
    "cell": "cell.ipynb", "forces": "forces.ipynb", "subbehaviors": "subbehaviors.ipynb",
    "defects": "defects.ipynb", "translate": "translate.ipynb", "flip": "flip.ipynb",
    "table1": "table1.ipynb", "ik_failure": "ik_failure.ipynb",
    "solve_times": "solve_times.ipynb", "solve_scaling": "solve_scaling.ipynb",
    "cone_forms": "cone_forms.ipynb",
    "landing": "landing.ipynb", "filmstrip": "landing.ipynb",
    "sensitivity": "sensitivity.ipynb", "schedule": "schedule.ipynb",
    "throughput": "throughput.ipynb", "kitchen": "kitchen.ipynb",
}
FIGURE_IDS = tuple(FIGURES)
