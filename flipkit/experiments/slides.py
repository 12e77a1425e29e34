"""How far flipped burgers slide on the grill after they touch down, and how flat they land.

A flip's ballistic flight is planned to the touchdown, and ``flipkit verify`` recomputes it;
what the burger does after it (slapping down, sliding, bouncing) is the simulated patty's
alone. Each trial of :func:`flipkit.experiments.trials.validate` records the burger's centre at
its first contact with the grill after the flip starts (``touchdown_xy``) and at rest
(``xy``), and the burger's tilt from flat at the touchdown (``touchdown_tilt_deg``);
:func:`slide_summary` gathers them over a validation, so that a report can tell a miss in the
air from a miss on the grill. A burger that lands tilted slaps down and slides; the flip
plans a flat landing (``docs/robust-flips.md`` §2).
"""

from __future__ import annotations

import numpy as np


def slide_summary(landings: list) -> dict | None:
    """The slides (m) after the touchdown over the trials of a validation.

    Args:
        landings: One record per trial with ``xy`` (the burger at rest, m) and
            ``touchdown_xy`` (at its first contact with the grill after the flip's start, m;
            ``None`` when it never touched, or absent in records made before it was kept).

    Returns:
        ``{"trials", "median_m", "p90_m", "max_m", "over_2cm", "tilt_median_deg",
        "tilt_max_deg"}`` (the tilts ``None`` when no record has ``touchdown_tilt_deg``), or
        ``None`` when no trial recorded a touchdown.
    """
    d = np.array([np.hypot(*np.subtract(t["xy"], t["touchdown_xy"])) for t in landings
                  if t.get("touchdown_xy") is not None and t.get("xy") is not None], float)
    if d.size == 0:
        return None
    tilt = np.array([t["touchdown_tilt_deg"] for t in landings
                     if t.get("touchdown_tilt_deg") is not None], float)
    return {"trials": int(d.size), "median_m": float(np.median(d)),
            "p90_m": float(np.quantile(d, 0.9)), "max_m": float(d.max()),
            "over_2cm": int(np.sum(d > 0.02)),
            "tilt_median_deg": float(np.median(tilt)) if tilt.size else None,
            "tilt_max_deg": float(tilt.max()) if tilt.size else None}


def format_slides(summary: dict | None) -> str:
    """One line of text for :func:`slide_summary` (empty for ``None``)."""
    if summary is None:
        return ""
    line = (f"slide after the touchdown over {summary['trials']} trials: median "
            f"{100 * summary['median_m']:.1f} cm, p90 {100 * summary['p90_m']:.1f} cm, max "
            f"{100 * summary['max_m']:.1f} cm; {summary['over_2cm']} over 2 cm")
    if summary.get("tilt_median_deg") is not None:
        line += (f"; touched down {summary['tilt_median_deg']:.1f}° from flat (median), "
                 f"{summary['tilt_max_deg']:.1f}° at most")
    return line


__all__ = ["format_slides", "slide_summary"]
