"""The EE + IK baseline against joint-space collocation (figure ``ik_failure``): grill maps of
each location's outcome class under the one judge, and joint paths of both methods at one
location."""

from __future__ import annotations

import numpy as np

from flipkit.errors import ConfigError
from flipkit.figures.draw.cell import shade_segments
from flipkit.figures.draw.maps import plot_grill_map

# outcome classes of a location, in legend order (flipkit.baseline.classify.FAILURE_CLASSES,
# plus "no_plan": the collocation solver found no plan that passes flipkit verify)
OUTCOMES = ("solved", "time_scalable", "dynamic", "kinematic", "ee", "no_plan")
OUTCOME_LABELS = {"solved": "solved", "time_scalable": "time-scalable (≤ 2× slower passes)",
                  "dynamic": "dynamic (velocity, acceleration, torque)",
                  "kinematic": "kinematic (reach, singularity, limit, jump, grill)",
                  "ee": "EE optimisation infeasible", "no_plan": "no verified plan"}
OUTCOME_STYLES = {"solved": {"marker": "o", "color": "#009E73", "s": 26},
                  "time_scalable": {"marker": "s", "color": "#E69F00", "s": 30},
                  "dynamic": {"marker": "D", "color": "#D55E00", "s": 30},
                  "kinematic": {"marker": "X", "color": "#882255", "s": 38},
                  "ee": {"marker": "v", "color": "#56B4E9", "s": 34},
                  "no_plan": {"marker": "x", "color": "#000000", "s": 34}}


def outcome_classes(entries) -> tuple[list, list]:
    """The outcome class (:data:`OUTCOMES`) of each location for both methods.

    Args:
        entries: ``compare_ik(...)["locations"]`` (or the ``locations`` of its JSON).

    Returns:
        ``(ee_ik, collocation)``: lists of class names, one per entry. A collocation plan that
        was solved and verified takes the judge's class (``solved`` when it passes).
    """
    ee, coll = [], []
    for e in entries:
        b, c = e["ee_ik"], e["collocation"]
        ee.append("solved" if b["status"] == "solved" else (b.get("class") or "ee"))
        if c["status"] != "solved":
            coll.append("no_plan")
        else:
            judge = c.get("judge") or {}
            coll.append("solved" if judge.get("status", "solved") == "solved"
                        else judge.get("class") or "kinematic")
    return ee, coll


def plot_outcome_maps(ax_ee, ax_coll, cell, entries, table_locations=None,
                      notes: bool = True) -> dict:
    """Grill maps of the outcome classes: EE + IK on ``ax_ee``, collocation on ``ax_coll``.

    Args:
        ax_ee, ax_coll: 2D axes.
        cell: The cell (grill area).
        entries: Per-location records of :func:`flipkit.experiments.compare_ik.compare_ik`.
        table_locations: Table I locations, drawn as small crosses.
        notes: Write the initial of the failing subbehaviour beside each EE + IK failure.

    Returns:
        ``{"ee_ik": {class: fraction}, "collocation": {class: fraction}}`` over the entries.
    """
    if not entries:
        raise ConfigError("no locations to draw")
    ee, coll = outcome_classes(entries)
    points = np.array([e["location"] for e in entries], float)
    initials = {"go_to_burger": "G", "scoop": "S", "pickup": "P", "flip": "F", "turn_back": "T"}
    letters = ([initials.get(e["ee_ik"].get("subbehavior"), "") for e in entries]
               if notes else None)
    styles = {OUTCOME_LABELS[k]: v for k, v in OUTCOME_STYLES.items()}
    fractions = {}
    for ax, labels, method, title in ((ax_ee, ee, "ee_ik", "(a) end-effector space + IK"),
                                      (ax_coll, coll, "collocation", "(b) joint-space collocation")):
        frac = {k: labels.count(k) / len(labels) for k in OUTCOMES}
        fractions[method] = frac
        plot_grill_map(ax, cell, points, [OUTCOME_LABELS[k] for k in labels], styles,
                       title=f"{title}: {frac['solved']:.0%} solved",
                       table_locations=table_locations,
                       notes=letters if method == "ee_ik" else None)
    return fractions


def plot_joint_path(ax, path: dict, title: str = "", limits=None) -> None:
    """Joint angles of one method along pickup-and-flip, the failing subbehaviour shaded.

    Args:
        ax: 2D axes (x: time, s; y: rad).
        path: ``{"t": (n,) s, "q": (n, 6) rad, "boundaries": (K + 1,) s, "names": (K,),
            "failed": name of the failing subbehaviour or None, "label": one line}`` as
            :func:`flipkit.figures.runs.ik_example` gives.
        title: Axes title.
        limits: Optional (q_min, q_max) (rad, 6 each), drawn as thin dotted lines for the
            joints that come within 0.3 rad of them.
    """
    t, q = np.asarray(path["t"], float), np.asarray(path["q"], float)
    if t.ndim != 1 or q.shape != (len(t), 6):
        raise ConfigError(f"joint path needs t (n,) and q (n, 6), got {t.shape}, {q.shape}")
    shade_segments(ax, path["boundaries"], [n.replace("_", " ") for n in path["names"]],
                   label_y=1.01)
    failed = path.get("failed")
    if failed in path["names"]:
        k = list(path["names"]).index(failed)
        ax.axvspan(path["boundaries"][k], path["boundaries"][k + 1], color="#D55E00",
                   alpha=0.15, lw=0, zorder=0)
    for j in range(6):
        ax.plot(t, q[:, j], lw=1.0, label=f"joint {j + 1}")
        if limits is not None:
            for bound in (limits[0][j], limits[1][j]):
                if np.min(np.abs(q[:, j] - bound)) < 0.3:
                    ax.axhline(bound, color=ax.lines[-1].get_color(), lw=0.6, ls=":")
    ax.set_xlim(t[0], t[-1])
    lo, hi = ax.get_ylim()  # room below the curves for the label, none of them hidden by it
    ax.set_ylim(lo - 0.18 * (hi - lo), hi)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("joint angle (rad)")
    if title:
        ax.set_title(title, fontsize=8, pad=12)
    if path.get("label"):
        ax.text(0.01, 0.02, path["label"], transform=ax.transAxes, fontsize=5.5, va="bottom",
                bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8, "pad": 1.0})


__all__ = ["OUTCOMES", "OUTCOME_LABELS", "OUTCOME_STYLES", "outcome_classes",
           "plot_outcome_maps", "plot_joint_path"]
