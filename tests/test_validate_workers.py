"""``flipkit validate`` with one worker killed (SIGKILL) at a random moment of its trials:
locally without and with ``--cache``, and on a local Dask cluster of two workers. Each run
exits 0 without a traceback and writes the result file of an undisturbed run."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil
import pytest

TRIALS = 4
ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}


def command(plan_file, out, *extra):
    return [sys.executable, "-m", "flipkit", "validate", "--plan", str(plan_file), "--trials",
            str(TRIALS), "--seed", "9", "--no-progress", "--json", str(out), *extra]


def pool_workers(pid) -> list[int]:
    """The pids of a command's local pool workers: the children of its forkserver."""
    servers = [p for p in psutil.Process(pid).children(recursive=True)
               if "forkserver" in " ".join(p.cmdline())]
    return [c.pid for s in servers for c in s.children()]


def started(argv, cache: Path, rng) -> subprocess.Popen:
    """``argv`` running, a random moment (up to 0.5 s) after its first trial is in ``cache``."""
    proc = subprocess.Popen(argv, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    deadline = time.monotonic() + 60
    while not list(cache.glob("*.json")) and time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()[1]
        time.sleep(0.02)
    time.sleep(float(rng.uniform(0.0, 0.5)))
    return proc


def run_killing(argv, cache: Path, rng, workers) -> tuple[subprocess.CompletedProcess, int]:
    """Run ``argv``; a random moment after its first trial is in ``cache``, SIGKILL one of
    ``workers(pid)``. Returns the finished run and the pid killed."""
    proc = started(argv, cache, rng)
    victim = workers(proc.pid)[0]
    os.kill(victim, signal.SIGKILL)
    out, err = proc.communicate(timeout=120)
    return subprocess.CompletedProcess(argv, proc.returncode, out, err), victim


@pytest.fixture(scope="module")
def undisturbed(flip_plan_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("undisturbed") / "k.json"
    done = subprocess.run(command(flip_plan_file, out, "--workers", "2"), env=ENV,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return out.read_text()


def check(done, out: Path, undisturbed: str) -> None:
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    assert out.read_text() == undisturbed


def test_a_killed_local_worker_without_cache(flip_plan_file, undisturbed, tmp_path):
    out = tmp_path / "k.json"
    done, _ = run_killing(command(flip_plan_file, out, "--workers", "2"),
                          tmp_path / "k.run-cache", np.random.default_rng(1), pool_workers)
    check(done, out, undisturbed)
    lines = done.stderr.splitlines()
    assert lines[0] == (f"flipkit validate: keeping finished items in the run cache "
                        f"{tmp_path / 'k.run-cache'}/ (removed when the command succeeds; if "
                        f"it stops, run the same command again to resume)")
    assert any(line.startswith("flipkit: a worker died running location (0.690, -0.160, "
                               "0.072) trial ") for line in lines)
    assert not (tmp_path / "k.run-cache").exists()  # removed once the command succeeded


def test_a_stopped_command_resumes_from_its_run_cache(flip_plan_file, undisturbed, tmp_path):
    out, run_cache = tmp_path / "k.json", tmp_path / "k.run-cache"
    argv = command(flip_plan_file, out, "--workers", "2")
    proc = started(argv, run_cache, np.random.default_rng(4))
    os.killpg(proc.pid, signal.SIGKILL)  # the command and its workers, as a reboot would
    proc.communicate(timeout=60)
    kept = len(list(run_cache.glob("*.json")))
    assert 1 <= kept < TRIALS and not out.exists()
    again = subprocess.run(argv, env=ENV, capture_output=True, text=True, timeout=120)
    check(again, out, undisturbed)
    assert again.stderr.startswith(f"flipkit validate: resuming from the run cache {run_cache}/")
    assert not run_cache.exists()


def test_a_killed_local_worker_with_cache(flip_plan_file, undisturbed, tmp_path):
    out, cache = tmp_path / "k.json", tmp_path / "cache"
    done, _ = run_killing(command(flip_plan_file, out, "--workers", "2", "--cache", str(cache)),
                          cache, np.random.default_rng(2), pool_workers)
    check(done, out, undisturbed)
    assert "a worker died running location" in done.stderr
    assert "run cache" not in done.stderr and not (tmp_path / "k.run-cache").exists()
    assert len(list(cache.glob("*.json"))) == TRIALS  # the cache keeps every trial


def test_a_killed_dask_worker(flip_plan_file, undisturbed, tmp_path):
    from dask.distributed import Client, LocalCluster

    out = tmp_path / "k.json"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        def dask_workers(_):
            return list(client.run(os.getpid).values())

        before = dask_workers(None)
        done, victim = run_killing(
            command(flip_plan_file, out, "--scheduler", cluster.scheduler_address),
            tmp_path / "k.run-cache", np.random.default_rng(3), dask_workers)
    assert victim in before
    check(done, out, undisturbed)
