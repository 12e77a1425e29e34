"""A planning worker that dies (a broken process pool) costs `plan batch` and the cook's
prefetching a re-plan in the main process, not the command: the plans are those a live
worker would have made, and one line on stderr says what happened."""

from __future__ import annotations

import concurrent.futures as cf
import os
import signal
import subprocess
import sys
import time
from concurrent.futures.process import BrokenProcessPool

import numpy as np
import psutil

from flipkit.config import CellConfig
from flipkit.planning.kitchen.cook import CookBurger
from flipkit.planning.kitchen.motions import MotionJob
from flipkit.planning.kitchen.prefetch import PrefetchPlanners
from flipkit.planning.planners.planner import plan_batch, plan_flip

LOCS = [(0.69, -0.16, 0.072), (0.75, 0.05, 0.072)]


class _DyingPool(cf.Executor):
    """Runs what it is given here; the ``die_at``-th submission's future fails as a killed
    worker's would, and so does every submission after it (the pool is broken for good)."""

    def __init__(self, die_at: int):
        self.die_at, self.submitted = die_at, 0

    def submit(self, fn, /, *args, **kwargs):
        self.submitted += 1
        if self.submitted > self.die_at:
            raise BrokenProcessPool("the pool is broken")
        fut = cf.Future()
        if self.submitted == self.die_at:
            fut.set_exception(BrokenProcessPool("a worker was terminated abruptly"))
        else:
            fut.set_result(fn(*args, **kwargs))
        return fut


def _same(a, b) -> bool:
    return a.status == b.status and all(
        np.array_equal(sa.q, sb.q) for sa, sb in zip(a.segments, b.segments))


def test_plan_batch_plans_a_dead_workers_burger_itself(capsys):
    plans = plan_batch(LOCS, executor=_DyingPool(die_at=2), progress=False)
    assert [p.status for p in plans] == ["solved", "solved"]
    assert _same(plans[1], plan_flip(LOCS[1]))  # what the worker would have made
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["flipkit: the worker planning burger 2 died (BrokenProcessPool); "
                   "planning it in this process"], err


def test_prefetching_goes_on_in_this_process_after_a_worker_died(capsys):
    cell = CellConfig()
    order = [CookBurger(f"b{k}", 5.0 * k, x, y) for k, (x, y, _) in enumerate(LOCS, 1)]
    planners = PrefetchPlanners(order, ("flip",), cell.robot.q_home, {}, _DyingPool(die_at=1),
                                cell)
    for b in order:
        pm = planners["flip"](MotionJob("flip", b.burger, b.location(cell)), cell.robot.q_home)
        assert pm.ok, pm
    assert planners.on_demand == 2 and planners.executor is None
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "a planning worker died" in err[0], err


def test_plan_batch_survives_a_killed_worker(tmp_path):
    """A real SIGKILL of one of `plan batch`'s two workers while they plan: exit 0, both
    burgers solved, one line naming the burger."""
    burgers = tmp_path / "two.csv"
    burgers.write_text("x,y,z\n" + "".join(f"{x},{y},{z}\n" for x, y, z in LOCS))
    proc = subprocess.Popen([sys.executable, "-m", "flipkit", "plan", "batch", "--burgers",
                             str(burgers), "--out", str(tmp_path / "out"), "--workers", "2",
                             "--no-progress"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        me, t0 = psutil.Process(proc.pid), time.monotonic()
        while True:  # the two workers: the forkserver's children
            servers = [p for p in me.children(recursive=True)
                       if "forkserver" in " ".join(p.cmdline())]
            workers = servers[0].children() if servers else []
            if len(workers) >= 2:
                break
            assert proc.poll() is None and time.monotonic() - t0 < 90
            time.sleep(0.1)
        time.sleep(1.0)  # into their first solves (a flip takes seconds)
        os.kill(workers[0].pid, signal.SIGKILL)
        out, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
    err = err.decode()
    assert proc.returncode == 0, err
    assert "Traceback" not in err and "died" in err and "planning it in this process" in err
    assert len(list((tmp_path / "out").glob("*.json"))) == 2
