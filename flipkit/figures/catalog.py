"""The figures of the report (paper/main.tex) and the notebooks that make them."""

from __future__ import annotations

from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS_DIR = REPO_ROOT / "notebooks"
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
