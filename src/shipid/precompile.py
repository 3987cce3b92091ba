"""Compile the numba kernels once, into their on-disk cache, so that no command pays for it.

``make install`` runs ``python -m shipid.precompile``. Each kernel is compiled the first time it
is called with a new combination of argument types, and the cache keeps the machine code beside
the source (``__pycache__``). A cold cache costs the first command that needs a kernel its
compilation (about 9 s of the demo's 13 s on a fresh install) and each of two test workers its
own copy; so every compiled path is exercised here once, with the argument types the commands
use: the term model's open and closed runs, its accelerations and path following, the kernel
residual (hybrid), the reference ships (and each corrected), the zero-phase filter, the
track smoother and the LS-SVM's blocked leave-one-out. Python's bytecode of the package is written too.
"""

from __future__ import annotations

import compileall
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np


def precompile(part: str | None = None) -> list[str]:
    """Run every compiled path once (``part`` "models": the identified models' paths; "ships":
    the reference ships', each corrected; None: both, in one process); the names of the paths
    run, in order."""
    done = []
    if part in (None, "models"):
        done += _models()
    if part in (None, "ships"):
        done += _ships()
    return done


def _models() -> list[str]:
    """The term model's open and closed runs (identify, validate), its accelerations and path
    following, the kernel residual, the zero-phase filter, the blocked leave-one-out."""
    from shipid.control.autopilot import PID, follow_path
    from shipid.data.preprocess import lowpass
    from shipid.demo import TRAINING, synthesise_trials
    from shipid.dynamics.hybrid import HybridModel
    from shipid.dynamics.simulate import simulate_log
    from shipid.evaluation.validate import validate
    from shipid.identification.identify import identify
    from shipid.identification.residual import fit_residual
    from shipid.lssvm.loo import PrimalLOOPath
    from shipid.trials.manoeuvres import zigzag

    done = []
    logs = synthesise_trials(seed=0)
    train, held = logs[TRAINING], [log for name, log in logs.items() if name != TRAINING]
    fit = identify(train)  # prefilter, open runs, closed-loop plausibility checks
    done.append("identify")
    lowpass(train, 1.0)
    validate(fit.model, held)  # replays, closed-loop replicas, the track smoother
    done.append("validate")
    model, speed = fit.model, float(train["u"].iloc[0])
    model.compiled_accelerations(np.zeros((2, 3)), np.zeros((2, 5)))
    follow_path(model, PID(1.0, 0.0, 10.0), [(0.0, 0.0), (20.0, 0.0), (40.0, 10.0)],
                lookahead=5.0, duration=5.0, speed=speed)  # fmt: skip
    done.append("term model")
    hybrid = HybridModel(model, fit_residual(model, [train], 1.0, 2.0))
    simulate_log(hybrid, held[0])
    zigzag(hybrid, 20, 20, duration=5.0, speed=speed)
    done.append("hybrid")
    rng = np.random.default_rng(0)
    PrimalLOOPath(rng.normal(size=(64, 3)), rng.normal(size=(64, 3)), np.ones(64)).mse_grid([1.0, 10.0])
    done.append("blocked leave-one-out")
    return done


def _ships() -> list[str]:
    """The reference ships' compiled physics, and each with a correction (shipid correct): its
    formula plus a term model."""
    from shipid.dynamics.simulate import simulate
    from shipid.identification.correction import identify_correction
    from shipid.trials.manoeuvres import turning_circle, zigzag
    from shipid.vessels import cybership2, kvlcc2, mariner, tanker

    done = []
    for ship in (mariner(), kvlcc2(), cybership2(), tanker()):
        run = zigzag(ship, 10, 10, duration=5.0)
        simulate(ship.dynamics, run.log["t"], run.log["delta"], np.r_[ship.approach_speed, np.zeros(5)])
        ship.dynamics.derivatives(np.array([[ship.approach_speed, 0.0, 0.0]]), np.zeros(1))
        done.append(ship.name)
    turning_circle(mariner(), 35, duration=5.0)
    for ship in (kvlcc2(), tanker(), mariner(), cybership2()):
        own = zigzag(ship, 10, 10, duration=20.0).log
        corrected = identify_correction(own, ship)
        simulate(corrected.vessel.dynamics, own["t"], own["delta"],
                 np.r_[ship.approach_speed, np.zeros(5)])  # fmt: skip
        zigzag(corrected.vessel, 10, 10, duration=5.0)
        done.append(f"corrected {ship.name}")
    return done


def _part(part: str) -> list[str]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the short runs' extrapolation notes are not the point
        return precompile(part)


def drop_uncached_entries() -> list[Path]:
    """Delete numba's files of the kernel's functions that are no longer cached on their own
    (``kernel.open_run``, ``closed_run``: an older install's, one entry a process, never read
    again); the files deleted."""
    from numba.core.caching import NullCache

    from shipid.dynamics import kernel

    folder = Path(kernel.__file__).parent / "__pycache__"
    dropped = []
    for name, obj in vars(kernel).items():
        if isinstance(getattr(obj, "_cache", None), NullCache):
            for stale in folder.glob(f"kernel.{name}-*.nb[ic]"):
                try:
                    stale.unlink()
                    dropped.append(stale)
                except OSError:
                    pass  # a read-only install: nothing of it is read either
    return dropped


def main() -> int:
    """``python -m shipid.precompile``: compile, then say what and how long."""
    start = time.perf_counter()
    drop_uncached_entries()
    # Python's own bytecode too: an editable install writes none, and where
    # PYTHONDONTWRITEBYTECODE is set no command ever would (0.13 s of every start).
    compileall.compile_dir(Path(__file__).parent, quiet=1)
    # The two halves in two processes where there are two cores: from a cold cache 45 s
    # against 98 s one after the other (2026-11-29). Numba writes each cache file whole (a
    # temporary file renamed), and the halves' few shared kernels are compiled alike: the
    # cache holds the same 90 overloads either way.
    if (os.cpu_count() or 1) > 1:
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(2) as pool:
            done = [name for names in pool.map(_part, ("models", "ships")) for name in names]
    else:
        done = _part("models") + _part("ships")
    print(f"shipid: compiled kernels ({', '.join(done)}) in {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
