"""Safe file output: checks before any work, and all-or-nothing writes.

* ``check_outputs`` refuses, before anything is computed, an output path that is also an input
  (the same file, through any path or link), two outputs on one path, an unknown extension, an
  empty path, or a folder that cannot be created.
* ``OutputSet`` stages every file of a command next to its target (a hidden temporary file) and
  renames them all into place only when the command has succeeded; on any error, Ctrl-C or SIGTERM
  the temporaries are removed and no output is left half-written. New files get the permissions
  of the umask (as ``open`` would), a replaced file keeps its own, and an output that is a symbolic
  link is written through to the link's target.
"""

from __future__ import annotations

import os
import tempfile
import threading
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path

from shipid.errors import ShipidError


class Interrupted(KeyboardInterrupt):
    """SIGTERM, handled like Ctrl-C: temporaries removed, one line, exit 130."""


# Set by the command line's signal handlers. Their exception can land where Python drops it (a
# finaliser, e.g. of a JIT compile's LLVM objects): the command would then run on and write its
# files. The flag outlives the dropped exception, and no file is committed once it is set.
_stop = threading.Event()


def request_stop() -> None:
    """Record an interrupt (SIGINT/SIGTERM) for ``check_stop``, in case its exception is lost."""
    _stop.set()


def clear_stop() -> None:
    """Forget an earlier interrupt (a new command starts)."""
    _stop.clear()


def stop_requested() -> bool:
    """Whether an interrupt was recorded: an error raised after it (e.g. numba's "no compiled
    object yet" once the interrupt broke its compile) is the interrupt's doing, not a bug."""
    return _stop.is_set()


def check_stop() -> None:
    """Raise ``Interrupted`` if an interrupt was recorded."""
    if stop_requested():
        raise Interrupted()


LOG_EXTENSIONS = (".csv", ".parquet", ".pq")
JSON_EXTENSIONS = (".json",)
FIGURE_EXTENSIONS = (".png", ".svg", ".pdf")
HTML_EXTENSIONS = (".html", ".htm")
KIND_EXTENSIONS = {"log": LOG_EXTENSIONS, "json": JSON_EXTENSIONS, "figure": FIGURE_EXTENSIONS,
                   "html": HTML_EXTENSIONS, "python": (".py",), "dir": None,
                   "yaml or json": (".yml", ".yaml", ".json")}  # fmt: skip


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _target(path: Path) -> Path:
    """Where writing ``path`` lands: a symbolic link is followed to its target."""
    return Path(os.path.realpath(path)) if path.is_symlink() else path


def _same_file(a: Path, b: Path) -> bool:
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def _check_creatable(path: Path, option: str) -> None:
    """The folder of ``path`` exists or can be made: no parent is a regular file."""
    for parent in [path, *path.parents] if path.is_dir() else path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ShipidError(f"{option} {path}: cannot write under {parent}, which is a file")
            if not os.access(parent, os.W_OK):
                raise ShipidError(f"{option} {path}: folder {parent} is not writable")
            return


def check_outputs(
    outputs: Mapping[str, tuple[str | Path | None, str]], inputs: Iterable[str | Path] = ()
) -> None:
    """Refuse unsafe outputs before any work.

    Parameters
    ----------
    outputs : option name (as the user typed it, e.g. ``"-o"``) → (path or None, kind); kind is
        'log', 'json', 'figure', 'html', 'python', 'yaml or json' or 'dir'.
    inputs : the files the command reads.
    """
    inputs = [Path(p) for p in inputs]
    seen: dict[str, str] = {}
    for option, (value, kind) in outputs.items():
        if value is None:
            continue
        if str(value).strip() == "":
            raise ShipidError(f"{option}: empty path")
        path = Path(value)
        if kind == "dir" and path.exists() and not path.is_dir():
            raise ShipidError(f"{option} {path}: exists and is not a folder")
        if kind != "dir" and path.is_dir():
            raise ShipidError(f"{option} {path}: is a folder, not a file")
        for src in inputs:
            if kind == "dir" and src.exists() and Path(os.path.realpath(src)).parent == Path(
                os.path.realpath(path)
            ):
                continue  # reading from a folder we write figures into is fine
            if _same_file(path, src):
                raise ShipidError(f"{option} {path}: is also an input ({src}); writing it would "
                                  "destroy the input, choose another output path")  # fmt: skip
        allowed = KIND_EXTENSIONS[kind]
        if allowed is not None and path.suffix.lower() not in allowed:
            raise ShipidError(f"{option} {path}: unknown extension {path.suffix or '(none)'!r}; "
                              f"use {', '.join(allowed)}")  # fmt: skip
        key = os.path.realpath(path)
        if key in seen:
            raise ShipidError(f"{option} and {seen[key]} both write {path}")
        seen[key] = option
        _check_creatable(path, option)


class OutputSet:
    """Files written together: staged as temporaries, renamed into place on ``commit``.

    Use as a context manager: the set commits when the block ends normally and is discarded on
    any exception (KeyboardInterrupt and SIGTERM included)::

        with OutputSet() as out:
            out.write("model.json", lambda p: p.write_text(text))
            out.write("plots/a.png", lambda p: fig.savefig(p, format="png"))
    """

    def __init__(self) -> None:
        self._staged: list[tuple[Path, Path]] = []
        self._made_dirs: list[Path] = []
        self.written: list[Path] = []

    def _mkdir(self, folder: Path) -> None:
        missing = [p for p in [folder, *folder.parents] if not p.exists()]
        for p in reversed(missing):
            try:
                p.mkdir()
            except FileExistsError:
                continue
            except OSError as exc:
                raise ShipidError(f"cannot create folder {p}: {exc.strerror}") from None
            self._made_dirs.append(p)

    def write(self, path: str | Path, writer: Callable[[Path], None]) -> Path:
        """Stage ``path``: ``writer(tmp)`` writes the content to a temporary beside it."""
        final = _target(Path(path))
        self._mkdir(final.parent)
        try:
            fd, tmp = tempfile.mkstemp(prefix=f".{final.name}.", suffix=".tmp", dir=final.parent)
        except OSError as exc:
            raise ShipidError(f"cannot write {path}: {exc.strerror}") from None
        os.close(fd)
        tmp_path = Path(tmp)
        self._staged.append((tmp_path, final))
        writer(tmp_path)
        return final

    def commit(self) -> list[Path]:
        """Rename every staged file into place (mode of the umask or of the file replaced);
        after an interrupt, nothing (``Interrupted``; the caller discards the set)."""
        check_stop()
        mask = _umask()
        for tmp, final in self._staged:
            try:
                mode = final.stat().st_mode & 0o7777 if final.exists() else 0o666 & ~mask
                os.chmod(tmp, mode)
                os.replace(tmp, final)
            except OSError as exc:
                self.abort()
                done = ", ".join(map(str, self.written)) or "nothing"
                raise ShipidError(f"cannot write {final}: {exc.strerror} (written: {done})") from None
            self.written.append(final)
        self._staged = []
        return self.written

    def abort(self) -> None:
        """Remove the staged temporaries and the folders this set created."""
        for tmp, _ in self._staged:
            tmp.unlink(missing_ok=True)
        self._staged = []
        for folder in reversed(self._made_dirs):
            try:
                folder.rmdir()  # only if we made it and it stayed empty
            except OSError:
                pass
        self._made_dirs = []

    def __enter__(self) -> OutputSet:
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is None:
            try:
                self.commit()
            except BaseException:
                self.abort()
                raise
        else:
            self.abort()
        return False


def atomic_write(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Write one file atomically: ``write(tmp_path)``, then rename over ``path``."""
    with OutputSet() as out:
        final = out.write(path, write)
    return final


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    return atomic_write(path, lambda p: p.write_text(text, encoding="utf-8"))
