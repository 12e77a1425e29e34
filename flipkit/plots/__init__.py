"""Figure helpers beyond the cell drawing of :mod:`flipkit.plotting`.

* :mod:`.data` — what a figure shows, computed from the package's objects (plan time
  series, contact forces and cone margins, Hermite–Simpson interpolants and defects, cone
  regions); no drawing.
* :mod:`.draw` — axes-level drawing of those (tracking, forces, defects, cone regions,
  snapshots, success ratios, solve times, grill maps).
* :mod:`.runs` — the computations behind the figures that need a plan, a simulation or a
  sweep (tracking a plan, solve-time sweeps), so the notebooks stay thin.
"""

from . import data, draw, runs

__all__ = ["data", "draw", "runs"]
