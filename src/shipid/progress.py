"""Progress bars on standard error where someone watches it, and none at all elsewhere.

A bar is drawn on a terminal or in a notebook, not into a file or a pipe: ``shipid validate
... 2> log.txt`` wrote the bar's every redraw, carriage returns and all, into the file beside
the warnings. A bar that is not shown costs nothing: tqdm (with ``tqdm.auto``'s notebook
detection, which imports asyncio) is imported only for a bar that is drawn. The searches of
every ``identify`` and ``select`` opened a disabled bar and paid 0.03-0.07 s of imports for it.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator


class _Hidden:
    """A bar that is not shown: the calls the commands make on one, doing nothing."""

    def update(self, n: int = 1) -> None:
        """Nothing to count."""

    def close(self) -> None:
        """Nothing to close."""

    def __enter__(self) -> _Hidden:
        return self

    def __exit__(self, *exc) -> None:
        return None


def watched() -> bool:
    """Whether standard error is seen as it is written: a terminal, or a notebook's kernel
    (whose stream is no terminal, and where ``tqdm.auto`` draws a widget)."""
    isatty = getattr(sys.stderr, "isatty", None)
    try:
        return bool(isatty and isatty()) or "ipykernel" in sys.modules
    except (OSError, ValueError):  # a closed stream
        return False


def progress_bar(total: int | None, desc: str, unit: str = "it", shown: bool = True,
                 leave: bool = True):  # fmt: skip
    """A bar counting to ``total`` (None: open-ended): ``shown``, where standard error is
    watched (``watched``); not shown, none (a ``_Hidden`` bar)."""
    if not shown or not watched():
        return _Hidden()
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit=unit, leave=leave)


def progress(items: Iterable, desc: str, unit: str = "it", shown: bool = True) -> Iterator:
    """``items`` with a bar counting them as they are taken (``progress_bar``'s ``shown``)."""
    items = list(items)
    with progress_bar(len(items), desc, unit, shown) as bar:
        for item in items:
            yield item
            bar.update()
