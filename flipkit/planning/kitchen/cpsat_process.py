"""CP-SAT in a child process: :func:`solve_schedule` sends a schedule problem to
``python -m flipkit.planning.kitchen.cpsat_process`` as JSON on its standard input and reads
the answer from its standard output; the child solves it with
:func:`~flipkit.planning.kitchen.cpsat.solve_here`.

Why a child: the OR-Tools wheel ships its own ``libhighs.so.1``, older than the one of
``highspy`` (which cvxpy imports), and one process cannot load both — whichever comes
second fails to load with an undefined symbol (google/or-tools issue #5246). The planners
load cvxpy; the child loads only OR-Tools, and no module of the package imports OR-Tools
but this one's ``__main__``.

A :class:`Child` reads one problem per line and answers each with one line, so it can serve
many schedules: whoever schedules many times (a cook's clearance rounds, a stream) makes one,
passes it to each schedule and closes it at the end (``with Child() as child:``), and only the
first schedule pays its start (importing OR-Tools); :meth:`Child.warm` starts it ahead,
while the motions are being planned. A schedule given no child starts one for itself and
stops it. A child that fails or does not answer in time is killed, and the next schedule
asked of the same :class:`Child` starts a new one.
"""

from __future__ import annotations

import json
import math
import select
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import asdict

from flipkit.errors import FlipkitError
from flipkit.planning.kitchen.cpsat import (BurgerJob, CpSatSchedule, MotionTimes,
                                            ScheduleTimeoutError, check_jobs, solve_here)
from flipkit.planning.kitchen.windows import WindowBreak, Windows

# The child's wall-time bound only detects a hung child. Its work is bounded in CP-SAT's
# deterministic time (close to seconds on one idle core), and the same work takes several
# times longer in wall time on a loaded machine (docs/history.md).
CHILD_WALL_FACTOR = 30.0  # wall s allowed per deterministic s of the limit
CHILD_MARGIN_S = 60.0  # s beyond that (start-up, building the model)


def wall_bound(time_limit_s: float) -> float:
    """Wall time (s) after which the child counts as hung, for a deterministic-time limit."""
    return CHILD_WALL_FACTOR * time_limit_s + CHILD_MARGIN_S


class CpSatProcessError(FlipkitError):
    """The CP-SAT child process failed (its last error line) or did not answer in time."""


def _readable(stream, timeout: float) -> bool:
    """Whether ``stream`` has something to read within ``timeout`` (s)."""
    return bool(select.select([stream], [], [], timeout)[0])


class Child:
    """A CP-SAT child process (module docstring), started on demand and stopped by
    :meth:`close` or at the end of a ``with`` block."""

    def __init__(self):
        self._proc: subprocess.Popen | None = None
        self._err = None  # the child's stderr: a file, so that it can never fill a pipe
        self._lock = threading.Lock()

    def warm(self) -> None:
        """Start the child unless it runs; it imports OR-Tools while the caller goes on."""
        with self._lock:
            self._start()

    def _start(self) -> None:
        if self._proc is None or self._proc.poll() is not None:
            self._err = tempfile.TemporaryFile("w+")
            self._proc = subprocess.Popen([sys.executable, "-m", __name__], text=True,
                                          stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                          stderr=self._err)

    def ask(self, problem: dict, timeout: float) -> dict:
        """The child's answer to ``problem``, within ``timeout`` s of wall time.

        Raises:
            CpSatProcessError: The child died (its last error line) or did not answer.
        """
        with self._lock:
            self._start()
            proc = self._proc
            try:
                proc.stdin.write(json.dumps(problem) + "\n")
                proc.stdin.flush()
            except OSError:
                pass  # it died: said below
            if not _readable(proc.stdout, timeout):
                self.close()
                raise CpSatProcessError(f"the CP-SAT process did not answer within "
                                        f"{timeout:g} s")
            line = proc.stdout.readline()
            if not line:
                code = proc.wait()
                self._err.seek(0)
                last = (self._err.read().strip().splitlines() or ["no message"])[-1]
                self.close()
                raise CpSatProcessError(f"the CP-SAT process failed (exit {code}): {last}")
            return json.loads(line)

    def __enter__(self) -> "Child":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close()

    def close(self) -> None:
        """Stop the child (the next :meth:`ask` starts another)."""
        proc, self._proc = self._proc, None
        if proc is not None and proc.poll() is None:
            proc.kill()
            proc.wait()
        if self._err is not None:
            self._err.close()
            self._err = None


def solve_schedule(jobs, windows: Windows = Windows(), *, dwell_s: float = 0.0,
                   earliest_s: float = -math.inf, time_limit_s: float = 10.0,
                   workers: int = 1, seed: int = 0, relax: str = "max",
                   child: Child | None = None) -> CpSatSchedule:
    """Order and time the motions of ``jobs`` (:class:`~flipkit.planning.kitchen.cpsat.BurgerJob`,
    any order) with CP-SAT in a child process; :func:`~flipkit.planning.kitchen.cpsat.solve_here`
    says how.

    Args:
        windows: Event windows. dwell_s: Table dwell (s). earliest_s: No motion before (s).
        time_limit_s: Limit for all solves together, in CP-SAT's deterministic time (about
            seconds on one idle core); the child is given :func:`wall_bound` of wall time.
        workers: CP-SAT search workers. seed: CP-SAT random seed.
        relax: The first objective when the windows cannot be met: "max" or "count".
        child: The :class:`Child` to ask (started if it is not running); default: one
            started for this schedule and stopped after it.

    Returns:
        The schedule; ``wall_s`` is the round trip to the child (its start too, if this
        schedule started it).

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
    if child is None:
        with Child() as own:
            reply = own.ask(problem, wall_bound(time_limit_s))
    else:
        reply = child.ask(problem, wall_bound(time_limit_s))
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


__all__ = ["CHILD_MARGIN_S", "Child", "CpSatProcessError", "answer", "solve_schedule"]


if __name__ == "__main__":  # the child: a problem per line on stdin, an answer per line out
    from ortools.sat.python import cp_model

    for request in sys.stdin:
        print(json.dumps(answer(json.loads(request), cp_model)), flush=True)
