"""The cook as a Gantt chart: the arm's motions, when each was planned, and every burger's
cook states against its 90 s and 150 s marks (figure ``schedule``)."""

from __future__ import annotations

from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from flipkit.figures.style import BURGER_COLOR, COLORS

MOTION_COLORS = {"flip": COLORS[0], "serve": COLORS[2]}
SIDE_COLORS = ("#E8C9A8", BURGER_COLOR)  # first side (raw), second side
PLAN_COLOR = "0.55"


def plot_schedule(ax, timeline: dict, title: str = "") -> dict:
    """Draw a timeline (the JSON of ``flipkit schedule``, as a dict) as a Gantt chart.

    Rows, top to bottom: ``planning`` (each motion's planning, on the planning clock), ``arm``
    (the motions, coloured by kind; a failed one as a hatched outline at the time it would
    have started), then one row per burger: first side from the drop to its landing on the
    second side, second side from there to its lift-off for serving (or to the end of the
    chart when it is not served). Ticks on a burger's row mark its 90 s and 150 s marks.
    Time in s on the cook order's clock.

    Returns:
        ``{"n_burgers", "n_motions", "t_end_s"}``.
    """
    burgers, motions = timeline["burgers"], timeline["motions"]
    t_end = max([m["end"] for m in motions] + [b["t_drop"] + 150.0 for b in burgers]) + 5.0
    rows = ["planning", "arm"] + [f"burger {b['burger']}" for b in burgers]
    y = {name: len(rows) - 1 - k for k, name in enumerate(rows)}
    h = 0.6
    for m in motions:
        t1 = m["planned_at"]
        ax.broken_barh([(t1 - m["planning_time_s"], max(m["planning_time_s"], 0.05))],
                       (y["planning"] - h / 2, h), facecolors=PLAN_COLOR, edgecolor="white",
                       linewidth=0.3)
        if m["status"] == "solved":
            ax.broken_barh([(m["start"], m["end"] - m["start"])], (y["arm"] - h / 2, h),
                           facecolors=MOTION_COLORS.get(m["kind"], COLORS[3]),
                           edgecolor="black", linewidth=0.3)
        else:
            ax.broken_barh([(m["start"], 1.0)], (y["arm"] - h / 2, h), facecolors="none",
                           edgecolor=COLORS[1], hatch="////", linewidth=0.6)
    for b in burgers:
        row = y[f"burger {b['burger']}"]
        first_end = b["flip_time"] if b["flip_time"] is not None else t_end
        ax.broken_barh([(b["t_drop"], first_end - b["t_drop"])], (row - h / 2, h),
                       facecolors=SIDE_COLORS[0], edgecolor="none")
        if b["flip_time"] is not None:
            second_end = b["serve_time"] if b["serve_time"] is not None else t_end
            ax.broken_barh([(b["flip_time"], second_end - b["flip_time"])], (row - h / 2, h),
                           facecolors=SIDE_COLORS[1], edgecolor="none",
                           alpha=1.0 if b["serve_time"] is not None else 0.45)
        for mark in (90.0, 150.0):
            ax.plot([b["t_drop"] + mark] * 2, [row - h / 2 - 0.1, row + h / 2 + 0.1],
                    color="black", lw=0.8)
    ax.set_yticks([y[r] for r in rows], rows)
    ax.set_ylim(-0.7, len(rows) - 0.3)
    ax.set_xlim(min([0.0] + [b["t_drop"] for b in burgers]), t_end)
    ax.set_xlabel("time (s)")
    ax.grid(axis="y", visible=False)
    handles = [Patch(color=PLAN_COLOR, label="planning"),
               *[Patch(color=c, label=k) for k, c in MOTION_COLORS.items()
                 if any(m["kind"] == k for m in motions)],
               Patch(color=SIDE_COLORS[0], label="first side"),
               Patch(color=SIDE_COLORS[1], label="second side"),
               *([Patch(color=SIDE_COLORS[1], alpha=0.45, label="second side, not served")]
                 if any(b["flip_time"] is not None and b["serve_time"] is None
                        for b in burgers) else []),
               Line2D([], [], color="black", lw=0.8, label="90 s / 150 s marks")]
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=4)
    if title:
        ax.set_title(title)
    return {"n_burgers": len(burgers), "n_motions": len(motions), "t_end_s": float(t_end)}


__all__ = ["MOTION_COLORS", "plot_schedule"]
