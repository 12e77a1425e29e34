"""The arm's pause at the sense of sense-plan-act trials: how long the re-plan held it.

In a flip's sense-plan-act trial (:func:`flipkit.experiments.trials.validate` with ``replan``)
the arm stops at rest after the scoop, the burger is measured on the blade, and the rest of the
behaviour is re-planned for it while the arm waits; the executed run includes that pause
(:func:`flipkit.simulation.execute.execute_plan`). With contingency flips
(:mod:`flipkit.experiments.contingent`) most re-plans are handed out ready-made, and the pause
is the hand-out. A serve's burger is measured during the carry, and the arm waits at the
carry's end only for the re-plan's time beyond that lead (the record's ``wait_s``).
:func:`pause_summary` gathers the pauses of every trial of a validation.
"""

from __future__ import annotations

import numpy as np

PAUSE_TARGET_S = 0.15  # s: the sense-plan-act cycle's budget for the pause (design target)


def pause_summary(trials: list, target_s: float = PAUSE_TARGET_S) -> dict | None:
    """The pauses (s) at the sense over the trials of a validation.

    Args:
        trials: One record per trial whose ``replan`` holds the arm's wait ``wait_s`` (a
            record without one: the re-plan's ``time_s``, which a flip's wait equals;
            ``replan`` ``None`` for an open-loop trial): a flip validation's ``landings``,
            a serve validation's ``rests``.
        target_s: The pause budget (s) whose overruns are counted.

    Returns:
        ``{"trials", "median_s", "p90_s", "worst_s", "target_s", "over_target"}``, or ``None``
        when no trial re-planned (open loop, or no plan solved).
    """
    waits = [t["replan"].get("wait_s", t["replan"].get("time_s")) for t in trials
             if t.get("replan") is not None]
    times = np.array([w for w in waits if w is not None], float)
    if times.size == 0:
        return None
    return {"trials": int(times.size), "median_s": float(np.median(times)),
            "p90_s": float(np.quantile(times, 0.9)), "worst_s": float(times.max()),
            "target_s": float(target_s), "over_target": int(np.sum(times > target_s))}


def format_pauses(summary: dict | None) -> str:
    """One line for a report: the pauses' median, 90th percentile, worst and overruns."""
    if summary is None:
        return "no re-plans (open loop)"
    return (f"pause at the sense over {summary['trials']} re-plans: median "
            f"{summary['median_s']:.3f} s, p90 {summary['p90_s']:.3f} s, worst "
            f"{summary['worst_s']:.3f} s; {summary['over_target']} over "
            f"{summary['target_s']:.2f} s")


__all__ = ["PAUSE_TARGET_S", "format_pauses", "pause_summary"]
