"""How many threads BLAS runs on in shipid's commands.

The commands alternate small BLAS calls (the LS-SVM's p × p systems, a trust-region step's SVD)
with compiled simulation kernels that run their batches on every core. OpenBLAS's threads keep
spinning for a while after each call, and on the 2-core machines this project targets they then
hold the cores the simulation needs: `select` on the Esso Osaka recipe took 3.82 s (5.7 s of
CPU) with them and 3.50 s (4.3 s) without, the test suite 88 s and 74 s. So the commands run BLAS
on one thread, and the dense LS-SVM solves large enough to gain from more ask for every core
(``threads_for``; a Cholesky solve of 500 equations gains nothing from a second thread, of 1000
1.29–1.36 times, of 4000 1.42–1.48 times: ``benchmarks/bench_blas_threads.py``).
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator

# The variable OpenBLAS (NumPy's and SciPy's wheels) reads when it loads.
THREADS_VARIABLE = "OPENBLAS_NUM_THREADS"
# Dense systems from this many equations on gain from every core.
MULTITHREADED_FROM = 1000


@contextlib.contextmanager
def one_thread() -> Iterator[None]:
    """BLAS on one thread: the libraries loaded now (``threadpoolctl``) and those loaded inside
    (the variable OpenBLAS reads when it loads); both restored after, but a library first loaded
    inside keeps the one thread it started with (a process that runs ``shipid.cli.main`` before
    importing NumPy itself). Where the user has set the variable, their setting holds."""
    if THREADS_VARIABLE in os.environ:
        yield
        return
    os.environ[THREADS_VARIABLE] = "1"
    try:
        if "numpy" not in sys.modules:
            # No BLAS is loaded yet (the installed command's case): the variable is enough, and
            # importing threadpoolctl would cost every command 20 ms.
            yield
            return
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            yield
    finally:
        os.environ.pop(THREADS_VARIABLE, None)


def threads_for(n: int) -> int | None:
    """BLAS threads for a dense solve of ``n`` equations: every core from
    ``MULTITHREADED_FROM`` on, else None (as set around it)."""
    return (os.cpu_count() or 1) if n >= MULTITHREADED_FROM else None


_CONTROLLER = None


def blas_threads(threads: int | None) -> contextlib.AbstractContextManager:
    """BLAS on ``threads`` threads inside the ``with`` block (None: as it is, at no cost).

    ``threadpoolctl.threadpool_limits`` finds the loaded libraries anew on every call: 0.7 ms,
    1.4 % of the test suite's CPU in the LS-SVM's dense solves, most of which asked for no
    limit at all. The libraries are found once here, at the first call: BLAS is NumPy's and
    SciPy's OpenBLAS, loaded with ``scipy.linalg`` (the solvers' import) and never after."""
    global _CONTROLLER
    if threads is None:
        return contextlib.nullcontext()
    if _CONTROLLER is None:
        import scipy.linalg  # noqa: F401  (SciPy's BLAS loaded before the libraries are found)
        from threadpoolctl import ThreadpoolController

        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER.limit(limits=threads, user_api="blas")
