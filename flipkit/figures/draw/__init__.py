"""Axes-level drawing for the figure notebooks, by kind of view.

Each function draws into axes it is given and returns what it drew (numbers for captions);
figure size, style and saving stay with the caller (:func:`flipkit.figures.style`,
:func:`flipkit.figures.save`). Colours follow the paper where it names them (Figs. 6–7:
desired red, actual blue) and the Okabe–Ito palette of :data:`flipkit.figures.COLORS`
elsewhere (:mod:`flipkit.figures.style`).
"""

from flipkit.figures.draw.cell import draw_cell, shade_segments
from flipkit.figures.draw.compare import (OUTCOME_LABELS, OUTCOMES, outcome_classes,
                                          plot_joint_path, plot_outcome_maps)
from flipkit.figures.draw.maps import draw_burger, draw_snapshot, plot_grill_map, plot_landings
from flipkit.figures.draw.panels import (plot_cone_regions, plot_defect_zoom, plot_forces,
                                         plot_hermite_simpson, plot_tangential_sections,
                                         plot_tracking, plot_tracking_error, shade_nodes)
from flipkit.figures.draw.scaling import plot_scaling
from flipkit.figures.draw.schedule import plot_deviations, plot_schedule
from flipkit.figures.draw.throughput import PUBLISHED_CLAIMS, plot_lateness, plot_throughput
from flipkit.figures.draw.stats import (plot_sensitivity, plot_solve_times, plot_success,
                                        plot_success_series, wilson_interval)

__all__ = ["OUTCOMES", "OUTCOME_LABELS", "outcome_classes", "plot_joint_path",
           "plot_outcome_maps", "draw_burger", "draw_cell", "draw_snapshot", "plot_cone_regions", "plot_defect_zoom",
           "plot_forces", "plot_grill_map", "plot_hermite_simpson", "plot_landings",
           "PUBLISHED_CLAIMS", "plot_deviations", "plot_lateness", "plot_schedule",
           "plot_throughput", "plot_scaling", "plot_sensitivity", "plot_solve_times", "plot_success", "plot_success_series",
           "plot_tangential_sections", "plot_tracking", "plot_tracking_error", "shade_nodes",
           "shade_segments", "wilson_interval"]
