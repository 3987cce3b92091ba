"""The ``shipid`` command line.

Exit 0 on success, 1 on a user error (one-line message, no traceback, no output file), 2 on a usage
error, 130 when interrupted (Ctrl-C or SIGTERM: temporaries removed, one line). Option values are
checked before any work, and so are output paths: an output that is also an input, an unknown
extension or an unwritable folder is refused before anything is computed. A command's output files
are written together at its end (``shipid.outputs.OutputSet``). Warnings print as ``warning:``
lines on stderr and go into the JSON outputs.

One module per concern: ``parser`` (every command's options); what the commands share:
``reading`` (the logs they read), ``physics_options`` (a fit's structure, prior, constraints and
bounds), ``targets`` (the model or reference ship a command runs on, its approach and steering),
``notes`` (where what a command is asked differs from what the model was identified from) and
``printing``; and the commands by what they do: ``identify``, ``selection`` (select, compare),
``rescale``, ``evaluation``, ``trials``, ``control``, ``data``, ``experiments`` (demo, study).
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import signal
import sys
import warnings
from pathlib import Path

from shipid.blas import one_thread
from shipid.cli.parser import FORMATS, build_parser, shared_parser
from shipid.errors import ShipidError, ShipidWarning
from shipid.outputs import Interrupted, check_stop, clear_stop, request_stop, stop_requested

__all__ = ["FORMATS", "build_parser", "main", "run"]


# Range checks of numeric options: dest → (rule, option as typed). Rules: '>0', '>=0', 'finite',
# 'int>=N'. Checked before any work; a bad value is a user error (exit 1), not a usage error.
OPTION_RULES = {
    "gamma": (">0", "--gamma"), "dt": (">0", "--dt"), "lead": (">=0", "--lead"),
    "filter": (">0", "--filter"), "segment": (">0", "--segment"),
    "refine_evals": ("int>=1", "--refine-evals"), "rudder_deg": (">0", "--rudder"),
    "heading": (">0", "--heading"), "duration": (">0", "--duration"), "step": (">0", "--dt"),
    "speed": (">0", "--speed"), "rps": ("finite", "--rps"), "smooth": (">=0", "--smooth"),
    "length": (">0", "--length"), "rudder_rate": (">0", "--rudder-rate"),
    "astern_rps": ("finite", "--astern-rps"),
    "scale": (">0", "--scale"), "start": ("finite", "--start"), "end": ("finite", "--end"),
    "wind_speed": (">=0", "--wind-speed"), "wind_from": ("finite", "--wind-from"),
    "max_evaluations": ("int>=1", "--max-evaluations"), "show": ("int>=1", "--show"),
    "max_lag": ("int>=1", "--max-lag"), "omega": (">0", "--omega"),
    "lookahead": (">0", "--lookahead"), "bootstrap": ("int>=10", "--bootstrap"),
    "block": (">0", "--block"), "workers": ("int>=1", "--workers"), "factor": (">0", "--factor"),
    "rho": (">0", "--rho"),
}  # fmt: skip


def _on_sigterm(signum, frame) -> None:
    request_stop()
    raise Interrupted()


def _on_sigint(signum, frame) -> None:
    request_stop()
    raise KeyboardInterrupt()


def _ignore_unraisable(unraisable) -> None:
    """``sys.unraisablehook`` while an interrupt unwinds: finaliser errors are not the user's."""


def _quiet_lost_interrupts(hook):
    """``sys.unraisablehook`` while a command runs: an interrupt raised inside a finaliser is
    dropped by Python; it is recorded (``request_stop``) and acted on, so it is not printed."""

    def unraisable(info) -> None:
        if not isinstance(info.exc_value, KeyboardInterrupt):
            hook(info)

    return unraisable


# Options that act only beside another: dest → (whether the other is given, option, the
# other, default). Given alone they changed nothing without a word (`identify --segment 20`
# without --refine).
OPTION_NEEDS = {
    "segment": (lambda a: a.refine, "--segment", "--refine", None),
    "block": (lambda a: a.bootstrap, "--block", "--bootstrap", "auto"),
    "plot_format": (lambda a: a.plots, "--plot-format", "--plots", "png"),
    "wind_from": (lambda a: a.wind_speed, "--wind-from", "--wind-speed", None),
    "max_lag": (lambda a: a.resid, "--max-lag", "--resid", 50),
    # select's plausibility condition (the other commands' --speed has no such partner)
    "speed": (lambda a: not getattr(a, "no_plausibility", False), "--speed",
              "the plausibility checks (--no-plausibility leaves them out)", None),
    "rps": (lambda a: not getattr(a, "no_plausibility", False), "--rps",
            "the plausibility checks (--no-plausibility leaves them out)", None),
}


def check_options(args) -> None:
    """Range checks of the numeric options (``OPTION_RULES``) before any work, and a warning
    for an option given without the one it acts beside (``OPTION_NEEDS``)."""
    for dest, (given, option, needed, default) in OPTION_NEEDS.items():
        value = getattr(args, dest, None)
        if value is not None and value != default and not given(args):
            shown = f"{value:g}" if isinstance(value, float) else value
            warnings.warn(f"{option} {shown} changes nothing without {needed}", ShipidWarning,
                          stacklevel=2)  # fmt: skip
    for dest, (rule, option) in OPTION_RULES.items():
        value = getattr(args, dest, None)
        if value is None or isinstance(value, str):
            continue
        if rule.startswith("int>="):
            least = int(rule[5:])
            if not value >= least:
                raise ShipidError(f"{option} must be a whole number ≥ {least}, got {value}")
            continue
        if not math.isfinite(value):
            raise ShipidError(f"{option} must be a finite number, got {value}")
        if rule == ">0" and not value > 0:
            raise ShipidError(f"{option} must be > 0, got {value:g}")
        if rule == ">=0" and not value >= 0:
            raise ShipidError(f"{option} must be ≥ 0, got {value:g}")


class _ClosableStdout:
    """stdout that goes quiet once its reader has gone (``shipid identify ... | head``): the
    command still finishes and writes its files instead of failing on a broken pipe."""

    def __init__(self, stream):
        self._stream = stream
        self._closed = False

    def write(self, text: str) -> int:
        if not self._closed:
            try:
                return self._stream.write(text)
            except BrokenPipeError:
                self._close()
        return len(text)

    def flush(self) -> None:
        if not self._closed:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self._close()

    def _close(self) -> None:
        import os

        self._closed = True
        try:  # what is still buffered goes nowhere, not into an error at exit
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, self._stream.fileno())
            os.close(null)
        except (OSError, ValueError, AttributeError):
            pass

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (0, 1, 2 usage, 130 interrupted)."""
    args = shared_parser().parse_args(argv)
    import threading

    # Only the main thread may handle signals; a Dask worker runs jobs in its own threads.
    in_main = threading.current_thread() is threading.main_thread()
    if in_main:
        clear_stop()
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
        previous_int = signal.signal(signal.SIGINT, _on_sigint)
    unraisablehook = sys.unraisablehook
    if in_main:
        sys.unraisablehook = _quiet_lost_interrupts(unraisablehook)
    caught: list[warnings.WarningMessage] = []
    stdout = sys.stdout
    sys.stdout = _ClosableStdout(stdout)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ShipidWarning)
            check_options(args)
            try:
                with one_thread():  # BLAS: see shipid.blas
                    # In a copy of the caller's context: what a command sets there (the gear's
                    # largest rudder its checks hold, from its logs' particulars) ends with it.
                    code = contextvars.copy_context().run(args.func, args)
            except Exception:
                # An error after an interrupt is the interrupt's doing (it broke a JIT compile,
                # which then fails with its own RuntimeError), not a bug: exit 130 all the same.
                if in_main and stop_requested():
                    raise Interrupted() from None
                raise
            if in_main:
                check_stop()  # an interrupt whose exception a finaliser dropped
    except ShipidError as exc:
        print(f"shipid: error: {_one_line(exc)}", file=sys.stderr)
        code = 1
    except KeyboardInterrupt:
        print("shipid: interrupted", file=sys.stderr)
        code = 130
        # What the interrupted work leaves half-built (a JIT compile's LLVM objects) may fail in
        # its finaliser when the traceback is dropped at the end of this clause: stay one line.
        sys.unraisablehook = _ignore_unraisable
    except MemoryError:
        print("shipid: error: out of memory (ask for fewer samples: a shorter run, a larger "
              "step or --dt)", file=sys.stderr)  # fmt: skip
        code = 1
    except (ValueError, OSError) as exc:
        print(f"shipid: error: {_one_line(exc)}", file=sys.stderr)
        code = 1
    except Exception as exc:  # a bug: still one line, no traceback (SHIPID_DEBUG=1 shows it)
        import os

        if os.environ.get("SHIPID_DEBUG"):
            raise
        print(f"shipid: error: internal error ({type(exc).__name__}: {_one_line(exc)}); please "
              "report it with the command line (SHIPID_DEBUG=1 shows the traceback)",
              file=sys.stderr)  # fmt: skip
        code = 1
    finally:
        if in_main:
            signal.signal(signal.SIGTERM, previous)
            signal.signal(signal.SIGINT, previous_int)
        sys.stdout = stdout
        if sys.unraisablehook is _ignore_unraisable:
            import gc

            gc.collect()  # the finalisers of cycles, while they are still ignored
        sys.unraisablehook = unraisablehook
    texts = [_one_line(w.message) for w in caught if issubclass(w.category, ShipidWarning)]
    for text in _grouped(texts, [str(p) for p in getattr(args, "logs", None) or []]):
        print(f"warning: {text}", file=sys.stderr)
    return code


def _grouped(texts: list[str], paths: list[str]) -> list[str]:
    """The warnings once each, in order; those that say the same of several of the command's
    logs ('PATH: text') as one line naming the logs (nine zig-zag files read without --format
    gave nine lines of the same sentence)."""
    known = set(paths)
    by_text: dict[str, list[str]] = {}
    for text in dict.fromkeys(texts):
        path, sep, rest = text.partition(": ")
        if sep and path in known:
            by_text.setdefault(rest, []).append(path)
    out, done = [], set()
    for text in dict.fromkeys(texts):
        path, sep, rest = text.partition(": ")
        logs = by_text.get(rest) if sep and path in known else None
        if not logs or len(logs) == 1:
            out.append(text)
        elif rest not in done:
            done.add(rest)
            names = [Path(p).name for p in logs]
            out.append(f"{len(logs)} logs ({', '.join(names[:3])}{', …' if len(names) > 3 else ''})"
                       f": {rest}")
    return out


def _one_line(exc) -> str:
    text = str(exc)
    if isinstance(exc, OSError) and exc.strerror:
        text = f"{exc.filename}: {exc.strerror}" if exc.filename else exc.strerror
    return text.splitlines()[0] if text else type(exc).__name__


def run() -> None:
    """Console entry point: :func:`main`, then exit with its code.

    The process ends with ``os._exit`` once the streams are flushed and the ``atexit`` handlers
    have run (Dask's clusters closed, multiprocessing's children joined, logging flushed), where
    no other thread is left: the interpreter's own teardown of the modules loaded (numba's LLVM,
    pandas, SciPy) took 0.4–0.5 s of a 1.7 s ``identify`` and nothing needs it, every file being
    closed where it is written. With a thread still running, a normal exit joins it.
    After an interrupt the process ends at once: the temporaries are already removed while
    unwinding, and an interrupted JIT compile leaves objects whose finalisers would print
    tracebacks during interpreter teardown.
    """
    import os
    import threading

    code = main()
    if code != 130 and threading.active_count() > 1:
        sys.exit(code)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except BrokenPipeError:
            pass  # the reader has gone (| head): what it read, it wanted
        except (OSError, ValueError) as exc:
            if stream is sys.stdout and code == 0:  # the output's end is lost (a full disk)
                code = 1
                with contextlib.suppress(OSError, ValueError):
                    print(f"shipid: error: standard output: {_one_line(exc)}", file=sys.stderr,
                          flush=True)  # fmt: skip
    if code != 130:
        import atexit

        atexit._run_exitfuncs()
    os._exit(code)
