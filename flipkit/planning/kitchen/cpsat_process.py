"""CP-SAT in a child process: :func:`solve_schedule` sends a schedule problem to
``python -m flipkit.planning.kitchen.cpsat_process`` as JSON on its standard input and reads
the answer from its standard output; the child solves it with
:func:`~flipkit.planning.kitchen.cpsat.solve_here`.

Why a child: the OR-Tools wheel ships its own ``libhighs.so.1``, older than the one of
``highspy`` (which cvxpy imports), and one process cannot load both — whichever comes
second fails to load with an undefined symbol (google/or-tools issue #5246). The planners
load cvxpy; the child loads only OR-Tools, and no module of the package imports OR-Tools
but this one's ``__main__``. The child costs about 0.6 s of start-up per schedule.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time
from dataclasses import asdict

from flipkit.errors import FlipkitError
from flipkit.planning.kitchen.cpsat import (BurgerJob, CpSatSchedule, MotionTimes,
                                            ScheduleTimeoutError, check_jobs, solve_here)
from flipkit.planning.kitchen.windows import WindowBreak, Windows

# The child's wall-time bound only detects a hung child. Its work is bounded in CP-SAT's
# deterministic time (about seconds on one idle core), and the same work takes several times
# longer on a loaded machine: at load 4-5 on two cores a 10 s limit overran 70 s of wall time.
CHILD_WALL_FACTOR = 30.0  # wall s allowed per deterministic s of the limit
CHILD_MARGIN_S = 60.0  # s beyond that (start-up, building the model)


def wall_bound(time_limit_s: float) -> float:
    """Wall time (s) after which the child counts as hung, for a deterministic-time limit."""
    return CHILD_WALL_FACTOR * time_limit_s + CHILD_MARGIN_S


class CpSatProcessError(FlipkitError):
    """The CP-SAT child process failed (its last error line) or did not answer in time."""


def solve_schedule(jobs, windows: Windows = Windows(), *, dwell_s: float = 0.0,
                   earliest_s: float = -math.inf, time_limit_s: float = 10.0,
                   workers: int = 1, seed: int = 0, relax: str = "max") -> CpSatSchedule:
    """Order and time the motions of ``jobs`` (:class:`~flipkit.planning.kitchen.cpsat.BurgerJob`,
    any order) with CP-SAT in a child process; :func:`~flipkit.planning.kitchen.cpsat.solve_here`
    says how.

    Args:
        windows: Event windows. dwell_s: Table dwell (s). earliest_s: No motion before (s).
        time_limit_s: Limit for all solves together, in CP-SAT's deterministic time (about
            seconds on one idle core); the child is given :func:`wall_bound` of wall time.
        workers: CP-SAT search workers. seed: CP-SAT random seed.
        relax: The first objective when the windows cannot be met: "max" or "count".

    Returns:
        The schedule; ``wall_s`` counts the child process's start too.

    Raises:
        ScheduleTimeoutError: No schedule found within ``time_limit_s``.
        CpSatProcessError: The child process failed or hung.
        InvalidChoiceError: An unknown ``relax``. FlipkitError: No jobs.
    """
    jobs = list(jobs)
    check_jobs(jobs, relax)
    problem = {"jobs": [asdict(j) for j in jobs], "windows": windows.to_dict(),
               "dwell_s": dwell_s, "earliest_s": earliest_s if math.isfinite(earliest_s)
               else None, "time_limit_s": time_limit_s, "workers": workers, "seed": seed,
               "relax": relax}
    t0 = time.perf_counter()
    try:
        run = subprocess.run([sys.executable, "-m", __name__], input=json.dumps(problem),
                             capture_output=True, text=True,
                             timeout=wall_bound(time_limit_s))
    except subprocess.TimeoutExpired:
        raise CpSatProcessError(f"the CP-SAT process did not answer within "
                                f"{wall_bound(time_limit_s):g} s") from None
    if run.returncode != 0:
        last = (run.stderr.strip().splitlines() or ["no message"])[-1]
        raise CpSatProcessError(f"the CP-SAT process failed (exit {run.returncode}): {last}")
    reply = json.loads(run.stdout)
    if "timeout" in reply:
        raise ScheduleTimeoutError(reply["timeout"])
    breach = reply["breach"]
    return CpSatSchedule(
        {(kind, k): start for kind, k, start in reply["starts"]}, reply["status"],
        reply["max_excess_s"], reply["max_deviation_s"], reply["total_deviation_s"],
        None if breach is None else WindowBreak(**{**breach, "window": tuple(breach["window"])}),
        time.perf_counter() - t0, reply["proved_infeasible"], reply["solve_s"])


def answer(problem: dict, cp) -> dict:
    """The child's answer (JSON-ready) to ``problem`` (the JSON :func:`solve_schedule` sends)."""
    jobs = [BurgerJob(j["burger"], j["t_drop"], MotionTimes(**j["flip"]),
                      None if j["serve"] is None else MotionTimes(**j["serve"]), j["previous"])
            for j in problem["jobs"]]
    earliest = problem["earliest_s"]
    try:
        r = solve_here(cp, jobs, Windows(**problem["windows"]), dwell_s=problem["dwell_s"],
                       earliest_s=-math.inf if earliest is None else earliest,
                       time_limit_s=problem["time_limit_s"], workers=problem["workers"],
                       seed=problem["seed"], relax=problem["relax"])
    except ScheduleTimeoutError as exc:
        return {"timeout": str(exc)}
    return {"starts": [[kind, k, v] for (kind, k), v in r.starts.items()],
            "status": r.status, "max_excess_s": r.max_excess_s,
            "max_deviation_s": r.max_deviation_s, "total_deviation_s": r.total_deviation_s,
            "breach": None if r.breach is None else asdict(r.breach), "solve_s": r.wall_s,
            "proved_infeasible": r.proved_infeasible}


__all__ = ["CHILD_MARGIN_S", "CpSatProcessError", "answer", "solve_schedule"]


if __name__ == "__main__":  # the child process: a problem on stdin, the answer on stdout
    from ortools.sat.python import cp_model

    json.dump(answer(json.load(sys.stdin), cp_model), sys.stdout)
