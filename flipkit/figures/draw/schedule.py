"""The cook as a Gantt chart: the arm's motions, when each was planned, and every burger's
cook states against its 90 s and 150 s marks; and each event's deviation from its mark
under two schedules of the same cook, against its window (figure ``schedule``)."""

from __future__ import annotations

from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from flipkit.figures.style import BURGER_COLOR, COLORS

MOTION_COLORS = {"flip": COLORS[0], "serve": COLORS[2]}
SIDE_COLORS = ("#E8C9A8", BURGER_COLOR)  # first side (raw), second side
PLAN_COLOR = "0.55"
WINDOW_COLOR = "0.82"  # an event's window, behind its deviations


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


def plot_deviations(ax, timelines: dict) -> dict:
    """Each event's deviation from its mark (s) under several schedules of one cook.

    Args:
        timelines: Label → timeline JSON (``flipkit schedule --json``, as a dict), the same
            burgers in each; the first's ``windows`` are drawn as grey bands.

    Returns:
        ``{"max_deviation_s": {label: s}, "n_outside": {label: events beyond their
        windows}}`` (2 ms tolerance, the optimiser's rounding).
    """
    labels = list(timelines)
    first = timelines[labels[0]]
    windows = first["windows"]
    events = [(b["burger"], e) for b in first["burgers"] for e in ("flip", "serve")
              if b["deviation_s"][e] is not None]
    x = list(range(len(events)))
    width = 0.8 / len(labels)
    for k, (burger, event) in enumerate(events):
        early, late = windows[event]
        ax.add_patch(Rectangle((k - 0.45, -early), 0.9, early + late, facecolor=WINDOW_COLOR,
                               lw=0, zorder=0))
    out = {"max_deviation_s": {}, "n_outside": {}}
    for j, label in enumerate(labels):
        dev = {b["burger"]: b["deviation_s"] for b in timelines[label]["burgers"]}
        ys = [dev[burger][event] for burger, event in events]
        ax.bar([k - 0.4 + width * (j + 0.5) for k in x], ys, width, label=label,
               color=COLORS[j % len(COLORS)], zorder=2)
        out["max_deviation_s"][label] = max(abs(v) for v in ys)
        out["n_outside"][label] = sum(v > windows[e][1] + 2e-3 or v < -windows[e][0] - 2e-3
                                      for v, (_, e) in zip(ys, events))
    ax.axhline(0, color="black", lw=0.6)
    ax.set_xticks(x, [f"{b}\n{e}" for b, e in events])
    ax.set_xlim(-0.6, len(events) - 0.4)
    low = min([0.0] + [-windows[e][0] for e in ("flip", "serve")]
              + [min(0.0, *(d for b in t["burgers"] for d in b["deviation_s"].values()
                            if d is not None)) for t in timelines.values()])
    high = max([windows[e][1] for e in ("flip", "serve")] + list(out["max_deviation_s"].values()))
    ax.set_ylim(low - 0.1 * (high - low), high + 0.45 * (high - low))  # room for the legend
    ax.set_ylabel("deviation from mark (s)")
    handles, names = ax.get_legend_handles_labels()
    ax.legend(handles + [Patch(facecolor=WINDOW_COLOR, label="window")], names + ["window"],
              loc="upper left", ncol=len(labels) + 1)
    return out


__all__ = ["MOTION_COLORS", "plot_deviations", "plot_schedule"]
