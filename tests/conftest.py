"""Test-session settings shared by every test file."""

import os

# BLAS on one thread, as the commands run it (``shipid.blas``): two test workers on two cores,
# each with OpenBLAS threads spinning between calls, took the cores the compiled simulations
# needed (the suite 88 s against 74 s). Read by OpenBLAS when it loads, in each worker.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

# numba on one thread in each test worker, as ``shipid.parallel`` runs its Dask tasks: two
# workers each spinning two numba threads of the compiled simulations' ``prange`` on two cores
# oversubscribed them (output error's 40 fits took 7.7 s beside another worker, 1.1 s alone; the
# suite 84 s against 56 s). Read when numba loads, before any test imports it; a serial run
# (no worker) keeps numba's default. The suite's subprocesses (the README's commands) inherit it.
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")

# ``make test`` runs two workers with ``--dist loadfile``: whole files go to whichever worker is
# free, in collection order. Collected alphabetically, test_readme.py (a third of the suite's
# time: its blocks run in order on one worker) started late and ran alone at the end; the longest
# files first balance the two workers (by their seconds in a --durations run: with the four
# longest alone first, one worker ran 98 s of tests and the other 90 s).
LONGEST_FIRST = ("test_readme.py", "test_other_rps.py", "test_real_data.py",
                 "test_auto_structure.py", "test_select.py", "test_tanker.py",
                 "test_output_error.py", "test_files.py", "test_cli.py", "test_steady_speed.py",
                 "test_study.py")


def pytest_collection_modifyitems(session, config, items):
    def rank(item):
        name = item.path.name
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)

    items.sort(key=rank)  # stable: the order inside a file, and of the others, is kept
