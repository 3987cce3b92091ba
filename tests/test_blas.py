"""BLAS threads in the commands (``shipid.blas``): one thread around a command, the user's
setting left alone, every core for the dense solves that gain from it."""

import os

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from shipid import blas


def _blas_threads() -> set[int]:
    return {lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"}


def test_a_command_runs_blas_on_one_thread_and_restores_it(monkeypatch):
    np.ones((2, 2)) @ np.ones((2, 2))  # BLAS loaded
    monkeypatch.delenv(blas.THREADS_VARIABLE, raising=False)
    with threadpool_limits(limits=2, user_api="blas"):
        with blas.one_thread():
            assert os.environ[blas.THREADS_VARIABLE] == "1"
            assert _blas_threads() == {1}
        assert blas.THREADS_VARIABLE not in os.environ
        assert _blas_threads() == {2}


def test_the_users_setting_holds(monkeypatch):
    monkeypatch.setenv(blas.THREADS_VARIABLE, "2")
    with threadpool_limits(limits=2, user_api="blas"), blas.one_thread():
        assert os.environ[blas.THREADS_VARIABLE] == "2" and _blas_threads() == {2}


@pytest.mark.parametrize("n, expected", [(999, None), (1000, os.cpu_count())])
def test_threads_for_a_dense_solve(n, expected):
    assert blas.threads_for(n) == expected


def test_a_command_that_loads_numpy_inside_gets_one_thread():
    """The installed command's path: NumPy is first loaded inside the command, where only the
    variable OpenBLAS reads at load can hold it (threadpoolctl is not imported for it)."""
    import subprocess
    import sys

    code = ("import sys\nfrom shipid.blas import one_thread\nwith one_thread():\n"
            "    loaded = 'threadpoolctl' in sys.modules\n    import numpy\n"
            "from threadpoolctl import threadpool_info\n"
            "print(loaded, sorted({l['num_threads'] for l in threadpool_info()"
            " if l['user_api'] == 'blas'}))")  # fmt: skip
    env = {k: v for k, v in os.environ.items() if k != blas.THREADS_VARIABLE}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout.strip()  # fmt: skip
    assert out == "False [1]"


def test_a_dense_solves_limit_holds_every_blas_and_none_costs_nothing():
    """``blas_threads``: the libraries found once, every BLAS (NumPy's and SciPy's) set inside
    and restored after; None touches nothing (the small solves, most of them)."""
    import scipy.linalg  # noqa: F401

    with threadpool_limits(limits=1, user_api="blas"):
        with blas.blas_threads(2):
            assert _blas_threads() == {2}
        assert _blas_threads() == {1}
        with blas.blas_threads(None):
            assert _blas_threads() == {1}
        with blas.blas_threads(2):  # the found libraries reused
            assert _blas_threads() == {2}
        assert _blas_threads() == {1}
