"""How many threads BLAS runs on in shipid's commands.

The commands alternate small BLAS calls (the LS-SVM's p × p systems, a trust-region step's SVD)
with compiled simulation kernels that run their batches on every core. OpenBLAS's threads keep
spinning for a while after each call, and on the 2-core machines this project targets they then
hold the cores the simulation needs: `select` on the Esso Osaka recipe took 3.82 s (5.7 s of
CPU) with them and 3.50 s (4.3 s) without, the test suite 88 s and 74 s. So the commands run BLAS
on one thread, and the dense LS-SVM solves large enough to gain from more ask for every core
(``threads_for``; a Cholesky of 1000 equations runs 1.17–1.39 times as fast on two, of 4000
1.47 times).
"""

from __future__ import annotations

import contextlib
import os
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
    from threadpoolctl import threadpool_limits

    os.environ[THREADS_VARIABLE] = "1"
    try:
        with threadpool_limits(limits=1, user_api="blas"):
            yield
    finally:
        os.environ.pop(THREADS_VARIABLE, None)


def threads_for(n: int) -> int | None:
    """BLAS threads for a dense solve of ``n`` equations: every core from
    ``MULTITHREADED_FROM`` on, else None (as set around it)."""
    return (os.cpu_count() or 1) if n >= MULTITHREADED_FROM else None
