"""The throughput figure's streams, one drop rate per worker process.

:func:`flipkit.planning.kitchen.throughput.sweep_rates` schedules the streams of every rate
one after the other. Each rate's streams depend only on the rate, the model and the seed,
and CP-SAT stops at a limit of deterministic time with one worker and a fixed seed
(:mod:`flipkit.planning.kitchen.cpsat`), so the schedules do not depend on the process or
the machine's load: :func:`throughput_sweep` hands the rates to an executor and returns
the rows ``sweep_rates`` returns, in its order.
"""

from __future__ import annotations

from flipkit.experiments.sweep import make_executor
from flipkit.planning.kitchen.throughput import POLICIES, sweep_rates


def stream_rows(job: tuple) -> list[dict]:
    """``sweep_rates([rate], minutes, model, policies, **kw)`` of ``job = (rate, minutes,
    model, policies, kw)`` (a worker)."""
    rate, minutes, model, policies, kw = job
    return sweep_rates([rate], minutes, model, policies, **kw)


def throughput_sweep(rates, minutes: float, model, policies=POLICIES, *,
                     scheduler: str | None = None, workers: int | None = None,
                     **kw) -> list[dict]:
    """The rows of ``sweep_rates(rates, minutes, model, policies, **kw)``, the rates spread
    over local worker processes (``workers``, default one per CPU; ``0``: in this process)
    or a Dask ``scheduler``; the slowest (highest) rates are handed out first."""
    rates = list(rates)
    jobs = [(rate, minutes, model, tuple(policies), dict(kw)) for rate in rates]
    if not scheduler and workers == 0:
        return [row for job in jobs for row in stream_rows(job)]
    order = sorted(range(len(jobs)), key=lambda i: -float(rates[i]))
    executor = make_executor(scheduler, workers=workers or None)
    try:
        futures = {i: executor.submit(stream_rows, jobs[i]) for i in order}
        return [row for i in range(len(jobs)) for row in futures[i].result()]
    finally:
        executor.shutdown(cancel_futures=True)


__all__ = ["stream_rows", "throughput_sweep"]
