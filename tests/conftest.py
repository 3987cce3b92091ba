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
# free, in collection order. Collected alphabetically, test_readme.py (a fifth of the suite's
# time: its blocks run in order on one worker) started late and ran alone at the end; the longest
# files first balance the two workers (by their seconds in a --durations run), the short ones
# fill in at the end. pytest-xdist reorders the files by their number of tests unless told not
# to (``--no-loadscope-reorder``, which make test passes): with its order, test_readme.py started
# at 72 % of the run, and the two workers ran 80.7 s and 75.0 s of tests.
LONGEST_FIRST = ("test_readme.py", "test_auto_structure.py", "test_other_rps.py",
                 "test_real_data.py", "test_cli.py", "test_select.py", "test_output_error.py",
                 "test_files.py", "test_correction.py", "test_steady_speed.py", "test_tanker.py",
                 "test_gear_limit.py", "test_control.py", "test_similarity.py", "test_tutorial.py",
                 "test_study.py", "test_identify.py", "test_selection_ensemble.py",
                 "test_precompile.py", "test_astern_thrust.py", "test_lssvm.py", "test_fuzz.py")


def pytest_collection_modifyitems(session, config, items):
    def rank(item):
        name = item.path.name
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)

    items.sort(key=rank)  # stable: the order inside a file, and of the others, is kept
