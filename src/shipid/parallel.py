"""Independent tasks run serially or fanned out on Dask (a local cluster or a scheduler).

Used by the studies: Monte Carlo trials (``shipid.evaluation.study``) and the identification
of many log sets (``shipid.identification.batch``). Each task is a pure function of its item
and returns a dict; results come back in the items' order, wherever they ran. Every task runs
with one BLAS and one numba thread: parallelism comes from tasks side by side (two workers each
spinning two numba threads on two cores ran slower than one worker).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

from shipid.errors import ShipidError


def single_threaded(fn: Callable[[object], dict], item) -> dict:
    """``fn(item)`` with one BLAS and one numba thread (restored afterwards)."""
    import numba
    from threadpoolctl import threadpool_limits

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        with threadpool_limits(limits=1):
            return fn(item)
    finally:
        numba.set_num_threads(threads)


def run_tasks(fn: Callable[[object], dict], items: Sequence, scheduler: str | None = None,
              workers: int | None = None, progress: bool = True,
              unit: str = "task") -> list[dict]:  # fmt: skip
    """``[fn(item) for item in items]``, in order.

    Parameters
    ----------
    fn : a module-level function (Dask pickles it by reference), returning a dict.
    scheduler : None (a ``LocalCluster`` of ``workers`` processes), 'serial' (this process, no
        Dask) or the address of a running Dask scheduler (``tcp://host:8786``), whose workers
        must have shipid installed.
    workers : worker processes of the local cluster (default: the machine's cores).
    progress : a progress bar on standard error, counting ``unit``.
    """
    if workers is not None and (scheduler is not None or workers < 1):
        raise ShipidError("workers: a count ≥ 1, for the local cluster only (not with a scheduler)")
    if scheduler == "serial":
        rows = []
        with _bar(len(items), progress, unit) as bar:
            for item in items:
                rows.append(fn(item))
                bar.update()
        return rows
    return _run_on_dask(fn, items, scheduler, workers, progress, unit)


def _bar(total: int, progress: bool, unit: str):
    from shipid.progress import progress_bar

    return progress_bar(total, f"{unit}s", unit, shown=bool(progress), leave=False)


def _run_on_dask(fn, items, scheduler, workers, progress, unit) -> list[dict]:
    import logging

    import dask
    from dask.distributed import Client, LocalCluster, as_completed

    # The workers' statistical profiler samples every thread's stack each 10 ms under the GIL;
    # the tasks time themselves.
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = None
        try:
            if scheduler is None:
                cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1,
                                       threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
                client = Client(cluster)
            else:
                client = Client(scheduler, timeout=10)
        except (OSError, RuntimeError, TimeoutError) as exc:
            what = f"reach the Dask scheduler {scheduler}" if scheduler else "start a local Dask cluster"
            raise ShipidError(f"cannot {what}: {exc}") from None
        try:
            futures = client.map(fn, items, pure=False)
            order = {f.key: i for i, f in enumerate(futures)}
            rows: list = [None] * len(items)
            with _bar(len(items), progress, unit) as bar:
                for future in as_completed(futures):
                    rows[order[future.key]] = future.result()
                    bar.update()
            return rows
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
