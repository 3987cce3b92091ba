"""``python -m shipid.cli``: the ``shipid`` command."""

from shipid.cli import run

if __name__ == "__main__":
    run()
