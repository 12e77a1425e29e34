"""A signal ends everything a run started: a real ``flipkit`` process with two workers gets
SIGTERM, SIGHUP or SIGINT once its pool, forkserver and resource tracker (and the schedule's
CP-SAT child) run; it prints one line and exits 128 + the signal, its pipes close, and no
process of its group survives."""

import os
import shutil
import signal
import subprocess
import sys
import time
from importlib import resources

import psutil
import pytest

from flipkit.cli.signals import farewell, Terminated

START_S = 90  # s allowed for the imports and the pool to start on a loaded machine


def _alive(pgid: int) -> list:
    """The processes of group ``pgid`` still running (zombies are dead: they hold nothing)."""
    out = []
    for proc in psutil.process_iter():
        try:
            if os.getpgid(proc.pid) == pgid and proc.status() != psutil.STATUS_ZOMBIE:
                out.append(proc)
        except (ProcessLookupError, psutil.Error):
            pass
    return out


def _interruptible():
    """In the child before it runs flipkit: SIGINT as a terminal delivers it. A test suite run
    as a background job of a non-interactive shell inherits SIGINT ignored, and Python keeps
    an ignored SIGINT ignored."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _run_and_signal(argv, signum, children: int, cwd):
    """Start ``flipkit argv`` in its own process group, wait for ``children`` descendants,
    send ``signum``; return (exit status, stderr, seconds to exit, survivors)."""
    proc = subprocess.Popen([sys.executable, "-m", "flipkit", *map(str, argv)], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True, preexec_fn=_interruptible)
    try:
        me, t0 = psutil.Process(proc.pid), time.monotonic()
        while len(me.children(recursive=True)) < children:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() - t0 < START_S, "the workers did not start"
            time.sleep(0.1)
        time.sleep(0.5)
        t1 = time.monotonic()
        os.kill(proc.pid, signum)
        _, err = proc.communicate(timeout=30)  # returns once every holder of the pipes ended
        took = time.monotonic() - t1
    finally:
        if proc.poll() is None:
            proc.kill()
    time.sleep(0.2)
    survivors = _alive(proc.pid)
    for p in survivors:  # leave nothing behind even when the test fails
        p.kill()
    return proc.returncode, err.decode(), took, survivors


@pytest.fixture
def batch(tmp_path):
    burgers = tmp_path / "two.csv"
    burgers.write_text("x,y,z\n0.69,-0.16,0.072\n0.75,0.05,0.072\n")
    return ["plan", "batch", "--burgers", burgers, "--out", tmp_path / "out", "--workers", "2",
            "--no-progress"], 4, ["two.csv"]  # tracker, forkserver, two workers


@pytest.fixture
def schedule(tmp_path):
    cook = tmp_path / "c.csv"
    shutil.copy(resources.files("flipkit").joinpath("data", "cook_five.csv"), cook)
    return ["schedule", cook, "--json", tmp_path / "o.json", "--workers", "2",
            "--no-progress"], 5, ["c.csv"]  # and the CP-SAT child


@pytest.mark.parametrize("command", ["batch", "schedule"])
@pytest.mark.parametrize("signum, status, word", [
    (signal.SIGTERM, 143, "terminated"), (signal.SIGHUP, 129, "hung up"),
    (signal.SIGINT, 130, "interrupted")])
def test_a_signal_ends_every_process_of_the_run(request, tmp_path, command, signum, status,
                                                word):
    argv, children, files = request.getfixturevalue(command)
    code, err, took, survivors = _run_and_signal(argv, signum, children, tmp_path)
    assert code == status and err.strip() == f"flipkit: {word}", err
    assert not survivors, [p.cmdline() for p in survivors]
    assert took < 10, took
    assert sorted(os.listdir(tmp_path)) == files  # nothing written


@pytest.mark.parametrize("signum, status, word", [
    (signal.SIGTERM, 143, "terminated"), (signal.SIGHUP, 129, "hung up"),
    (signal.SIGINT, 130, "interrupted")])
def test_validate_with_two_workers_ends_on_a_signal(flip_plan_file, tmp_path, signum, status,
                                                    word):
    argv = ["validate", "--plan", flip_plan_file, "--trials", "20", "--workers", "2",
            "--no-progress", "--json", tmp_path / "v.json"]
    code, err, took, survivors = _run_and_signal(argv, signum, 4, tmp_path)
    lines = err.strip().splitlines()  # the run cache's line, then the farewell
    assert code == status and lines[-1] == f"flipkit: {word}" and len(lines) == 2, err
    assert "run the same command again to resume" in lines[0], err
    assert not survivors and took < 10
    assert os.listdir(tmp_path) == ["v.run-cache"]  # kept for the resume; no result file


def test_farewell_names_the_signal():
    assert farewell(KeyboardInterrupt()) == ("flipkit: interrupted", 130)
    assert farewell(Terminated(signal.SIGTERM)) == ("flipkit: terminated", 143)
    assert farewell(Terminated(signal.SIGHUP)) == ("flipkit: hung up", 129)


def test_a_pool_left_by_an_exception_ends_its_workers():
    """Workers an hour into their work end at once, and no traceback of the pool's manager
    thread is printed for the work the caller cancelled."""
    from flipkit.experiments.sweep import make_executor

    pool = make_executor(workers=2)
    t0 = time.monotonic()
    with pytest.raises(RuntimeError, match="stop"):
        with pool:
            futures = [pool.submit(time.sleep, 3600) for _ in range(4)]
            while not any(f.running() for f in futures):
                time.sleep(0.05)
            for f in futures:
                f.cancel()
            raise RuntimeError("stop")
    assert time.monotonic() - t0 < 60
    assert all(f.done() for f in futures)
