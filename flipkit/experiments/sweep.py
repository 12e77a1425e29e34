"""Sweeps: one picklable function mapped over many items on an Executor, cached and resumable.

The project's Executor is a :class:`concurrent.futures.Executor`: local worker processes by
default (:class:`~concurrent.futures.ProcessPoolExecutor`, forkserver start method, so no
worker inherits a half-initialised solver by forking), or a Dask cluster when a scheduler
address is given (``dask.distributed.Client(address)``'s executor). :func:`run_sweep` caches
every result as one JSON file under ``cache_dir`` as soon as it arrives, keyed by a stable
hash of the item, the function's name and the flipkit version, so a sweep interrupted
half-way recomputes only what is missing when it is run again.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import hashlib
import json
import multiprocessing
import os
import re
import sys
from pathlib import Path

import numpy as np
from tqdm import tqdm

from flipkit import __version__
from flipkit.config import CellConfig
from flipkit.errors import ConfigError, FlipkitError
from flipkit.experiments.worker_pool import WorkerPool

SINGLE_THREAD_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _single_threaded() -> None:
    """Worker initializer: one BLAS/OpenMP thread per worker process (unless set)."""
    for name in SINGLE_THREAD_ENV:
        os.environ.setdefault(name, "1")


def _dask_executor(scheduler: str) -> cf.Executor:
    """The executor of a Dask client connected to ``scheduler``; it closes the client when
    shut down."""
    import distributed.cfexecutor  # Dask is slow to import; only --scheduler needs it

    try:
        client = distributed.Client(scheduler, timeout="10s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FlipkitError(f"cannot connect to the Dask scheduler at {scheduler}: "
                           f"{msg}") from None

    class DaskExecutor(distributed.cfexecutor.ClientExecutor):
        """A Dask client's executor that also closes the client when shut down."""

        def shutdown(self, wait: bool = True) -> None:
            try:
                super().shutdown(wait=wait)
            finally:
                self._client.close()

    return DaskExecutor(client, pure=False)


def make_executor(scheduler: str | None = None, workers: int | None = None) -> cf.Executor:
    """The executor of a sweep.

    Args:
        scheduler: Address of a Dask scheduler (e.g. ``tcp://host:8786``); ``None`` for
            local worker processes.
        workers: Number of local worker processes (default: the CPU count). Ignored with a
            scheduler: the cluster decides.

    Returns:
        An executor; call ``shutdown()`` (or use it in a ``with`` block) when done. A Dask
        executor closes its client on shutdown.

    Raises:
        ConfigError: ``workers`` is not a positive integer.
        FlipkitError: The scheduler cannot be reached (10 s timeout).
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise ConfigError(f"workers must be a positive integer, got {workers!r}")
    if scheduler:
        return _dask_executor(scheduler)
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    return WorkerPool(max_workers=workers or os.cpu_count() or 1, mp_context=ctx,
                      initializer=_single_threaded)


def jsonable(obj):
    """``obj`` as plain JSON values: dataclasses → dicts, tuples and arrays → lists,
    numpy scalars → Python numbers, paths → strings.

    Raises:
        TypeError: A value with no JSON form.
    """
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    if obj is None or isinstance(obj, (bool, int, float, str)):
        return obj
    raise TypeError(f"no JSON form for {type(obj).__name__}: {obj!r}")


def stable_hash(obj) -> str:
    """SHA-256 hex digest of the canonical JSON of ``obj`` (sorted keys, see :func:`jsonable`);
    the same on every machine and Python run."""
    text = json.dumps(jsonable(obj), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def _cache_path(cache_dir: Path, name: str, key) -> Path:
    digest = stable_hash({"function": name, "flipkit": __version__, "key": key})
    return cache_dir / f"{re.sub(r'[^A-Za-z0-9_.-]', '_', name)}-{digest[:24]}.json"


def _read_cache(path: Path):
    """(True, result) of a readable cache file, else (False, None)."""
    try:
        return True, json.loads(path.read_text())["result"]
    except (OSError, ValueError, KeyError, TypeError):
        return False, None


def _write_cache(path: Path, name: str, key, result) -> None:
    tmp = path.with_name(path.name + f".{os.getpid()}.tmp")
    doc = {"function": name, "flipkit": __version__, "key": jsonable(key), "result": result}
    try:
        tmp.write_text(json.dumps(doc))
        os.replace(tmp, path)
    except OSError as exc:
        raise FlipkitError(f"cannot write the sweep cache {path}: {exc.strerror or exc}") from None


def run_sweep(fn, items, executor: cf.Executor | None = None, cache_dir=None, key_fn=None,
              progress: bool = True, *, name: str | None = None, desc: str = "sweep",
              dedupe: bool = False) -> list:
    """``[fn(item) for item in items]``, in input order, run on ``executor`` and cached.

    Each result is stored as JSON as soon as it arrives, so the function must return JSON
    values (dicts, lists, numbers, strings, ``None``); every result, computed or read back,
    is returned as its JSON round trip (tuples come back as lists).

    Args:
        fn: A picklable top-level function of one argument.
        items: The arguments; each must be picklable.
        executor: Where to run; ``None`` runs in this process, one item after the other.
        cache_dir: Directory of the cache (created if missing); ``None`` disables caching.
        key_fn: ``item -> key`` with a JSON form (:func:`jsonable`) identifying the work;
            default the item itself.
        progress: Show a tqdm progress bar on stderr.
        name: Cache namespace of ``fn``; default ``"<module>.<qualname>"``.
        desc: Progress-bar label.
        dedupe: Compute items of equal keys once and give each the same result (the
            function must be deterministic in its key, as the cache assumes).

    Returns:
        The results, one per item, in input order.

    Raises:
        Whatever ``fn`` raises for an item (pending work is cancelled; results that already
        arrived stay cached). FlipkitError: The cache cannot be written.
    """
    items = list(items)
    name = name or f"{fn.__module__}.{fn.__qualname__}"
    keys = [item if key_fn is None else key_fn(item) for item in items]
    results, pending, paths = [None] * len(items), [], [None] * len(items)
    if cache_dir is not None:
        cache_dir = Path(cache_dir)
        cache_dir.mkdir(parents=True, exist_ok=True)
    for i, key in enumerate(keys):
        if cache_dir is not None:
            paths[i] = _cache_path(cache_dir, name, key)
            found, results[i] = _read_cache(paths[i])
            if found:
                continue
        pending.append(i)
    cached = len(items) - len(pending)
    copies = {}  # item computed -> the later items of equal key that take its result
    if dedupe:
        first, unique = {}, []
        for i in pending:
            digest = stable_hash(keys[i])
            if digest in first:
                copies.setdefault(first[digest], []).append(i)
            else:
                first[digest] = i
                unique.append(i)
        pending = unique

    def store(i, result):
        results[i] = json.loads(json.dumps(result))
        if paths[i] is not None:
            _write_cache(paths[i], name, keys[i], results[i])
        for j in copies.get(i, ()):
            results[j] = json.loads(json.dumps(results[i]))
            bar.update()

    with tqdm(total=len(items), initial=cached, desc=desc, unit="item",
              disable=not progress, file=sys.stderr) as bar:
        if executor is None:
            for i in pending:
                store(i, fn(items[i]))
                bar.update()
            return results
        futures = {executor.submit(fn, items[i]): i for i in pending}
        try:
            for future in cf.as_completed(futures):
                store(futures[future], future.result())
                bar.update()
        except BaseException:
            for future in futures:
                future.cancel()
            raise
    return results


def grill_grid(cell: CellConfig | None = None, nx: int = 5, ny: int = 5) -> list[tuple]:
    """Burger locations on an nx × ny grid over the grill area, at the grill height h_g.

    The points are the centres of nx × ny equal cells of the area (rounded to 1 µm), so
    every one lies strictly inside it; they are ordered with x varying fastest.

    Returns:
        [(x, y, h_g), ...] (m), nx·ny tuples.

    Raises:
        ConfigError: ``nx`` or ``ny`` is not a positive integer.
    """
    cell = cell or CellConfig()
    for label, n in (("nx", nx), ("ny", ny)):
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ConfigError(f"grid {label} must be a positive integer, got {n!r}")
    g = cell.grill
    xs = g.x_range[0] + (np.arange(nx) + 0.5) * (g.x_range[1] - g.x_range[0]) / nx
    ys = g.y_range[0] + (np.arange(ny) + 0.5) * (g.y_range[1] - g.y_range[0]) / ny
    return [(round(float(x), 6), round(float(y), 6), float(g.height)) for y in ys for x in xs]


__all__ = ["WorkerPool", "make_executor", "run_sweep", "grill_grid", "stable_hash", "jsonable"]
