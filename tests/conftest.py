"""Test-session settings shared by every test file."""

# ``make test`` runs two workers with ``--dist loadfile``: whole files go to whichever worker is
# free, in collection order. Collected alphabetically, test_readme.py (a third of the suite's
# time: its blocks run in order on one worker) started late and ran alone at the end; the longest
# files first balance the two workers.
LONGEST_FIRST = ("test_readme.py", "test_cli.py", "test_select.py", "test_files.py")


def pytest_collection_modifyitems(session, config, items):
    def rank(item):
        name = item.path.name
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)

    items.sort(key=rank)  # stable: the order inside a file, and of the others, is kept
