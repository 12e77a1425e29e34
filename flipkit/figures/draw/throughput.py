"""Throughput against drop rate (figure ``throughput``): burgers per hour served within their
windows and the largest lateness, per scheduling policy, with the published claims of
commercial burger robots marked (:data:`PUBLISHED_CLAIMS`, each with the page it is from).
"""

from __future__ import annotations

from flipkit.figures.style import COLORS

# Published throughput claims of commercial burger robots (burgers per hour), each with the
# page that states it (the claim paraphrased). They are whole-kitchen figures (Creator's and
# Momentum Machines' machines grind, cook and assemble; Flippy's depend on the staff placing
# patties), not one arm flipping and serving: marks for scale, not a like-for-like comparison.
PUBLISHED_CLAIMS = (
    {"label": "Flippy (Miso Robotics)", "per_hour": 150.0,
     "claim": "Flippy is reported to grill 150 burgers an hour (The Robot Report, on its "
              "first day at CaliBurger, Pasadena)",
     "source": "https://www.therobotreport.com/flippy-robot-gets-to-work-at-caliburger/"},
    {"label": "Flippy, upper claim", "per_hour": 300.0,
     "claim": "Miso Robotics puts Flippy at 150 to 300 burgers an hour, depending on the "
              "kitchen staff (NY Tech Media)",
     "source": "https://nytech.media/?p=4697"},
    {"label": "Creator", "per_hour": 130.0,
     "claim": "Creator's machine cooks about 130 cheeseburgers an hour (InsideHook)",
     "source": "https://insidehook-com-develop.go-vip.net/culture-san-francisco/"
               "worlds-first-robot-chef-burger-joint"},
    # Creator was formerly Momentum Machines: San Francisco Chronicle, 2018-06-23,
    # http://www.pressreader.com/usa/san-francisco-chronicle-late-edition/20180623/282222306485098
    {"label": "Momentum Machines (Creator's former name)", "per_hour": 360.0,
     "claim": "the company's release gives its alpha machine about 360 hamburgers an hour "
              "(Vice)",
     "source": "https://www.vice.com/en/article/mgggkv/meet-the-robot-that-makes-360-"
               "gourmet-burgers-per-hour"},
)
POLICY_STYLE = {"cpsat": (COLORS[0], "o", "CP-SAT"), "greedy": (COLORS[1], "s", "greedy")}


def _by_policy(rows) -> dict:
    out: dict[str, list] = {}
    for row in rows:
        out.setdefault(row["policy"], []).append(row)
    return out


def plot_throughput(ax, rows, claims=PUBLISHED_CLAIMS) -> dict:
    """Burgers per hour within their windows against the drop rate, per policy.

    Args:
        rows: :func:`~flipkit.planning.kitchen.throughput.sweep_rates` rows; a refused rate
            (a full grill) is drawn as a cross on the axis.
        claims: Published claims (``label``, ``per_hour``), drawn as numbered dotted lines.

    Returns:
        ``{"max_rate_all_within_per_h": {policy: the highest rate, every burger within its
        windows and none blocked}, "rates_all_within": {policy: how many rates keep every
        burger within}, "first_break_per_h": {policy: the lowest rate that breaks them},
        "n_within": {policy: burgers within their windows and not blocked, all rates},
        "n_burgers": {policy: burgers}, "n_blocked": {policy: burgers blocked at every
        scoop heading, all rates, or None: not checked}, "grill_full_per_h": the lowest
        refused rate or None}``. Rows whose sweeps were checked (``n_blocked``) also draw
        the same schedules' count on timing alone, dashed.
    """
    out = {"max_rate_all_within_per_h": {}, "rates_all_within": {}, "first_break_per_h": {},
           "n_within": {}, "n_burgers": {}, "n_blocked": {}, "grill_full_per_h": None}
    rates = sorted({r["rate_per_h"] for r in rows})
    ax.plot([0, max(rates)], [0, max(rates)], color="0.6", lw=0.8, ls="--",
            label="every burger within its windows")
    for policy, pr in _by_policy(rows).items():
        color, marker, name = POLICY_STYLE.get(policy, (COLORS[3], "^", policy))
        done = [r for r in pr if "refused" not in r]
        ax.plot([r["rate_per_h"] for r in done], [r["per_hour_within"] for r in done],
                color=color, marker=marker, ms=3.5, lw=1.0, label=name)
        timing = [r for r in done if r.get("n_blocked") is not None]
        if timing:  # the same schedules, their motions' sweeps not checked
            ax.plot([r["rate_per_h"] for r in timing],
                    [r["rate_per_h"] * r["n_within_timing"] / max(r["n_burgers"], 1)
                     for r in timing], color=color, lw=0.8, ls=(0, (4, 2)), alpha=0.6,
                    label=f"{name}, timing only")
        ok = [r["rate_per_h"] for r in done if r["windows_met"] and not r.get("n_blocked")]
        broken = [r["rate_per_h"] for r in done
                  if not r["windows_met"] or r.get("n_blocked")]
        out["max_rate_all_within_per_h"][policy] = max(ok) if ok else None
        out["rates_all_within"][policy] = len(ok)
        out["n_within"][policy] = sum(r["n_within"] for r in done)
        out["n_burgers"][policy] = sum(r["n_burgers"] for r in done)
        out["n_blocked"][policy] = (sum(r["n_blocked"] for r in timing) if timing else None)
        out["first_break_per_h"][policy] = min(broken) if broken else None
        refused = [r["rate_per_h"] for r in pr if "refused" in r]
        if refused:
            ax.plot(refused, [0] * len(refused), ls="none", marker="x", color="black",
                    clip_on=False)
            full = min(refused)
            out["grill_full_per_h"] = (full if out["grill_full_per_h"] is None
                                       else min(full, out["grill_full_per_h"]))
    rank = {k: n for n, k in enumerate(sorted(range(len(claims)),
                                              key=lambda k: claims[k]["per_hour"]))}
    for k, c in enumerate(claims, 1):  # labels by value, alternately left and right
        ax.axhline(c["per_hour"], color="0.35", lw=0.7, ls=":")
        left = rank[k - 1] % 2 == 0
        ax.annotate(f"[{k}] {c['label']}", (0.01 if left else 0.99, c["per_hour"]),
                    xycoords=("axes fraction", "data"), fontsize=6, va="bottom",
                    ha="left" if left else "right", color="0.25")
    ax.set_xlabel("drop rate (burgers per hour)")
    ax.set_ylabel("served within windows (per hour)")
    ax.set_xlim(0, max(rates) * 1.02)
    ax.set_ylim(0, max([max(rates)] + [c["per_hour"] for c in claims]) * 1.08)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2, fontsize=6)
    return out


def plot_lateness(ax, rows, late_s: float | None = None) -> dict:
    """The largest lateness (s; linear to 1 s, logarithmic above) against the drop rate, per
    policy; ``late_s``:
    the windows' late bound, drawn as a line.

    Returns:
        ``{"max_lateness_s": {policy: {rate: s}}}``.
    """
    out = {"max_lateness_s": {}}
    for policy, pr in _by_policy(rows).items():
        color, marker, name = POLICY_STYLE.get(policy, (COLORS[3], "^", policy))
        done = [r for r in pr if "refused" not in r]
        ys = [r["max_lateness_s"] for r in done]
        ax.plot([r["rate_per_h"] for r in done], ys, color=color, marker=marker, ms=3.5,
                lw=1.0, label=name)
        out["max_lateness_s"][policy] = {r["rate_per_h"]: r["max_lateness_s"] for r in done}
    if late_s is not None:
        ax.axhline(late_s, color="0.35", lw=0.8, ls="--", label="window's late bound")
    ax.set_yscale("symlog", linthresh=1.0)  # linear below 1 s, logarithmic above
    ax.set_ylim(bottom=0)
    ax.set_xlabel("drop rate (burgers per hour)")
    ax.set_ylabel("largest lateness (s)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3)
    return out


__all__ = ["POLICY_STYLE", "PUBLISHED_CLAIMS", "plot_lateness", "plot_throughput"]
