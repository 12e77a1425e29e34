"""The sweep executor: cache and resume, input order, local processes vs Dask, the grill grid."""

import json
import time

import numpy as np
import pytest

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.experiments.sweep import grill_grid, make_executor, run_sweep, stable_hash

ITEMS = list(range(6))


def square(x):
    return {"x": x, "y": x * x}


def square_unless_small(x):
    """Raises for the items a first, interrupted sweep already did (x < 3)."""
    if x < 3:
        raise RuntimeError(f"item {x} recomputed")
    return square(x)


def refuse(x):
    raise RuntimeError(f"item {x} recomputed")


def slow_first(x):
    """Early items finish last, so completion order is the reverse of input order."""
    time.sleep(0.1 * (3 - x) if x < 3 else 0.0)
    return [x, 10 * x]


@pytest.fixture(scope="module")
def local():
    with make_executor(None, 2) as executor:
        yield executor


def test_cache_resumes_without_recomputation(local, tmp_path):
    first = run_sweep(square, ITEMS[:3], local, tmp_path, None, progress=False, name="sq")
    assert first == [square(x) for x in ITEMS[:3]]
    assert len(list(tmp_path.glob("sq-*.json"))) == 3
    # the interrupted sweep resumes: only items 3.. are computed
    full = run_sweep(square_unless_small, ITEMS, local, tmp_path, None, progress=False,
                     name="sq")
    assert full == [square(x) for x in ITEMS]
    # a third run computes nothing at all
    assert run_sweep(refuse, ITEMS, local, tmp_path, None, progress=False, name="sq") == full
    # another function name or another key is another cache entry
    with pytest.raises(RuntimeError, match="recomputed"):
        run_sweep(refuse, ITEMS[:1], local, tmp_path, None, progress=False, name="other")
    with pytest.raises(RuntimeError, match="recomputed"):
        run_sweep(refuse, ITEMS[:1], None, tmp_path, lambda x: [x, "v2"], progress=False,
                  name="sq")


def test_corrupt_cache_entry_is_recomputed(tmp_path):
    run_sweep(square, [4], None, tmp_path, progress=False, name="sq")
    (entry,) = tmp_path.glob("sq-*.json")
    entry.write_text("{not json")
    assert run_sweep(square, [4], None, tmp_path, progress=False, name="sq") == [square(4)]
    assert json.loads(entry.read_text())["result"] == square(4)


def test_results_in_input_order(local):
    assert run_sweep(slow_first, ITEMS, local, None, progress=False) == [
        [x, 10 * x] for x in ITEMS]


def test_worker_error_propagates(local, tmp_path):
    with pytest.raises(RuntimeError, match="recomputed"):
        run_sweep(square_unless_small, ITEMS, local, tmp_path, progress=False)


def test_dask_executor_matches_local_processes(local):
    from dask.distributed import LocalCluster

    want = run_sweep(square, ITEMS, local, None, progress=False)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        with make_executor(cluster.scheduler_address, None) as dask_executor:
            got = run_sweep(square, ITEMS, dask_executor, None, progress=False)
    assert got == want == [square(x) for x in ITEMS]


def test_bad_executor_arguments():
    for workers in (0, -1, 1.5, True):
        with pytest.raises(ConfigError, match="workers"):
            make_executor(None, workers)


def test_stable_hash_is_canonical():
    a = stable_hash({"location": (0.75, 0.0, 0.073), "solver": "ipopt"})
    b = stable_hash({"solver": "ipopt", "location": np.array([0.75, 0.0, 0.073])})
    assert a == b != stable_hash({"solver": "sqp", "location": [0.75, 0.0, 0.073]})
    with pytest.raises(TypeError):
        stable_hash(object())


def test_grill_grid_covers_the_grill_at_grill_height():
    cell = CellConfig()
    pts = grill_grid(cell, 3, 2)
    assert len(pts) == 6 and len(set(pts)) == 6
    assert all(cell.grill.contains(p[:2], tol=0.0) and p[2] == cell.grill.height for p in pts)
    assert pts[0][1] == pts[1][1] == pts[2][1] < pts[3][1]  # x varies fastest
    assert grill_grid(cell, 1, 1) == [(0.74, -0.17, cell.grill.height)]
    for bad in ((0, 2), (2, -1), (1.5, 2)):
        with pytest.raises(ConfigError, match="grid"):
            grill_grid(cell, *bad)
