"""A sweep whose worker is killed (SIGKILL, mid-item): the pool is replaced and the results are
those of an undisturbed run; an item that kills its worker on every attempt is named as
``worker died`` once the rest finished; a Dask cluster that loses a worker finishes too."""

import os
import signal
import threading
import time
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np
import pytest

from flipkit.errors import SweepError
from flipkit.experiments.sweep import make_executor, run_sweep

N = 8


def square(x):
    return {"x": x, "y": x * x}


def marked_square(job):
    """``square(x)`` after 0.3 s, leaving ``start-<x>`` (this worker's pid) and one line per
    attempt in ``attempts-<x>`` in the job's folder."""
    x, folder = job
    with open(Path(folder, f"attempts-{x}"), "a") as f:
        f.write(f"{os.getpid()}\n")
    Path(folder, f"start-{x}").write_text(str(os.getpid()))
    time.sleep(0.3)
    return square(x)


def poisoned_square(job):
    """``marked_square``, except that item 3 kills its own worker."""
    x, folder = job
    if x == 3:
        with open(Path(folder, "attempts-3"), "a") as f:
            f.write(f"{os.getpid()}\n")
        os.kill(os.getpid(), signal.SIGKILL)
    return marked_square(job)


def item_key(job):
    return job[0]


def item_label(job):
    return f"item {job[0]}"


def attempts(folder, x) -> int:
    path = Path(folder, f"attempts-{x}")
    return len(path.read_text().splitlines()) if path.exists() else 0


def kill_when_started(folder, rng, killed: list) -> threading.Thread:
    """A thread that SIGKILLs the worker running a random item of 1..N-2, a random moment
    (up to 0.25 s, before it ends) after it started, and records (item, pid) in ``killed``."""
    x, delay = int(rng.integers(1, N - 1)), float(rng.uniform(0.0, 0.25))

    def kill():
        start = Path(folder, f"start-{x}")
        deadline = time.monotonic() + 30
        while not start.exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(delay)
        pid = int(start.read_text())
        os.kill(pid, signal.SIGKILL)
        killed.append((x, pid))

    thread = threading.Thread(target=kill, daemon=True)
    thread.start()
    return thread


def test_a_killed_worker_is_replaced_and_nothing_is_lost(tmp_path, capsys):
    jobs = [(x, str(tmp_path)) for x in range(N)]
    killed = []
    with make_executor(None, 2) as executor:
        thread = kill_when_started(tmp_path, np.random.default_rng(59), killed)
        got = run_sweep(marked_square, jobs, executor, tmp_path / "cache", item_key,
                        progress=False, label_fn=item_label)
        thread.join()
        assert executor.pools == 2  # the broken pool was replaced once
    assert killed and got == [square(x) for x in range(N)]
    assert len(list((tmp_path / "cache").glob("*.json"))) == N
    (note,) = capsys.readouterr().err.splitlines()  # one line on stderr, naming the item
    assert note.startswith("flipkit: a worker died running ") and f"item {killed[0][0]}" in note
    # the killed item ran again; so did at most one other, in flight when the pool broke
    runs = [attempts(tmp_path, x) for x in range(N)]
    assert runs[killed[0][0]] == 2 and max(runs) == 2 and sum(runs) <= N + 2


def test_an_item_that_always_kills_its_worker_is_named_and_the_rest_finishes(tmp_path):
    jobs = [(x, str(tmp_path)) for x in range(N)]
    with make_executor(None, 2) as executor:
        with pytest.raises(SweepError) as err:
            run_sweep(poisoned_square, jobs, executor, tmp_path / "cache", item_key,
                      progress=False, name="sq", desc="squares", label_fn=item_label,
                      retries=2)
    message = str(err.value)
    assert "\n" not in message and err.value.exit_status == 1
    assert message == ("squares: item 3: worker died on each of 3 attempts; the 7 other items "
                       f"finished, kept in {tmp_path / 'cache'} (the same sweep resumes from "
                       f"there)")
    assert attempts(tmp_path, 3) == 3  # 1 + retries
    assert all(attempts(tmp_path, x) <= 2 for x in range(N) if x != 3)
    assert len(list((tmp_path / "cache").glob("*.json"))) == N - 1
    # the run resumes from the cache: only the poisoned item runs again
    resumed = [(x, str(tmp_path)) for x in range(N) if x != 3]
    with make_executor(None, 2) as executor:
        assert run_sweep(marked_square, resumed, executor, tmp_path / "cache", item_key,
                         progress=False, name="sq") == [square(x) for x in range(N) if x != 3]
    assert all(attempts(tmp_path, x) <= 2 for x in range(N) if x != 3)


def test_a_dask_cluster_that_loses_a_worker_finishes_the_sweep(tmp_path):
    from dask.distributed import Client, LocalCluster

    jobs = [(x, str(tmp_path)) for x in range(N)]
    killed = []
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        before = set(client.run(os.getpid).values())
        with make_executor(cluster.scheduler_address) as executor:
            thread = kill_when_started(tmp_path, np.random.default_rng(60), killed)
            got = run_sweep(marked_square, jobs, executor, None, item_key, progress=False)
            thread.join()
    assert killed and killed[0][1] in before  # a Dask worker was killed mid-item
    assert got == [square(x) for x in range(N)]
    assert attempts(tmp_path, killed[0][0]) == 2  # Dask ran the killed item again


@pytest.mark.parametrize("error", [
    SweepError("trials: location (0.750, 0.000, 0.073) trial 3 seed 9: worker died on each of "
               "3 attempts; the 99 other items finished"),
    BrokenProcessPool("A process in the process pool was terminated abruptly"),
])
def test_the_command_line_ends_a_lost_item_with_one_line_and_exit_1(error, monkeypatch, capsys,
                                                                     tmp_path):
    from flipkit.cli import main
    from flipkit.cli.commands import validate

    def run(args):
        raise error

    monkeypatch.setattr(validate, "run", run)
    code = main(["validate", "--locations", "table1", "--trials", "1", "--no-progress",
                 "--json", str(tmp_path / "k.json")])
    (line,) = capsys.readouterr().err.splitlines()
    assert code == 1 and line.startswith("flipkit: error: ") and str(error) in line
