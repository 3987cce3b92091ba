"""Progress bars on standard error, and none at all where they are not shown.

A bar that is not shown costs nothing: tqdm (with ``tqdm.auto``'s notebook detection, which
imports asyncio) is imported only for a bar that may be drawn. The searches of every
``identify`` and ``select`` opened a disabled bar and paid 0.03-0.07 s of imports for it.
"""

from __future__ import annotations

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


def progress_bar(total: int | None, desc: str, unit: str = "it", shown: bool | None = True,
                 leave: bool = True):  # fmt: skip
    """A bar counting to ``total`` (None: open-ended): ``shown`` True, always; None, where
    standard error is a terminal (tqdm's rule); False, none (a ``_Hidden`` bar)."""
    if shown is False:
        return _Hidden()
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit=unit, disable=shown, leave=leave) \
        if shown is None else tqdm(total=total, desc=desc, unit=unit, leave=leave)  # fmt: skip


def progress(items: Iterable, desc: str, unit: str = "it", shown: bool | None = True
             ) -> Iterator:  # fmt: skip
    """``items`` with a bar counting them as they are taken (``progress_bar``'s ``shown``)."""
    items = list(items)
    with progress_bar(len(items), desc, unit, shown) as bar:
        for item in items:
            yield item
            bar.update()
