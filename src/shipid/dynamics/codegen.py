"""Simulation kernels generated per term set: the state derivative written out as straight-line
code and compiled by numba, run by the same integrators and closed-loop logic as the interpreter
(``shipid.dynamics.kernel``).

The interpreter evaluates any term set from its factor table: per term a loop over its factors,
a branch on each factor's operation and a check for all-zero coefficients. That generality costs
about 3× against a loop with the terms typed in (``benchmarks/bench_simulate.py``). A generated
kernel is that typed-in loop: the source of ``rhs(ctx, u, v, r, ψ)`` for one term set is written
to a module in the cache folder, imported, and compiled with numba's on-disk cache, so each term
set is compiled once per machine (about 2–4 s) and then loads in a fraction of a second. Only
the (equation, term) coefficients that are non-zero in the run's coefficient sets are compiled
into the sums: the equations of most structures have different terms, and the products by zero
cost 10–20 % of the speed (benchmarks/README.md). Its arithmetic is otherwise the
interpreter's, in the same order, so the two agree to the last bit or two.

``engine="auto"`` (the default; ``with codegen.use("generated"):`` sets another) uses a
generated kernel for runs long enough to repay the compilation (``GENERATED_MIN_STEPS``
state-steps), or when this process has already compiled or loaded that term set with those
non-zero coefficients; short runs
(selection's thousands of candidate structures, each run once) stay on the interpreter. The
cache folder is ``$SHIPID_CACHE_DIR``, else ``$XDG_CACHE_HOME/shipid/kernels`` or
``~/.cache/shipid/kernels``; where it cannot be written, the interpreter runs.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import sys
import threading
from pathlib import Path
from types import ModuleType

import numpy as np

from shipid import __version__
from shipid.dynamics.terms import CROSSFLOW, CROSSFLOW_SLOTS, RUDDER, RUDDER_SLOT, SIGNALS, TermCode

ENGINES = ("auto", "generated", "interpreted")
# Below this many state-steps a run takes well under a second on the interpreter: not worth
# a first compilation (2–4 s), which later runs of the same term set would reuse.
GENERATED_MIN_STEPS = 2_000_000

_engine: contextvars.ContextVar[str] = contextvars.ContextVar("shipid_engine", default="auto")
# By term set and non-zero (equation, term) pairs: the integrators cannot change.
_loaded: dict[tuple[tuple[str, ...], bytes], ModuleType] = {}

_lock = threading.Lock()
_unwritable = False


def cache_dir() -> Path:
    """The folder of the generated modules (and numba's cache of them)."""
    if os.environ.get("SHIPID_CACHE_DIR"):
        return Path(os.environ["SHIPID_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "shipid" / "kernels"


def _factor_expr(signal: int, op: int, k: float, power: int, name: str) -> list[str]:
    """Lines assigning factor ``name``: op(k·s)^power, as ``kernel._factor`` computes it."""
    s = f"s{signal}"
    base = {0: s, 1: f"abs({s})", 2: f"({s} if {s} > 0.0 else 0.0)",
            3: f"(-{s} if {s} < 0.0 else 0.0)", 4: f"math.sin({k!r} * {s})",
            5: f"math.cos({k!r} * {s})",
            9: f"({s} * {s} if {s} >= 0.0 else {-k!r} * {s} * {s})"}[op]  # fmt: skip
    if power <= 1:
        return [f"{name} = {base}"]
    return [f"{name}_b = {base}", f"{name} = " + " * ".join([f"{name}_b"] * power)]


def _signal_name(index: int) -> str:
    return SIGNALS[index] if index < len(SIGNALS) else (*CROSSFLOW, RUDDER)[index - len(SIGNALS)]


def source(code: TermCode, pairs: np.ndarray | None = None) -> str:
    """The generated module's source for the term set ``code``; ``pairs`` (3, T) bool: the
    (equation, term) coefficients that can be non-zero (None: all). The others are left out of
    the sums, which is what brings a structure whose equations have different terms (most of
    them) to a loop with its terms typed in."""
    used = set(int(s) for s in code.signal)
    body = ["th, inp, wind_true, vw, dw = ctx", "c = math.cos(psi)", "sn = math.sin(psi)",
            "xd = u * c - v * sn", "yd = u * sn + v * c", "s0, s1, s2 = u, v, r"]  # fmt: skip
    if 3 in used:
        body.append("s3 = math.sqrt(u * u + v * v)")
    if 4 in used:
        body.append("s4 = math.atan2(-v, u)")
    if used & set(CROSSFLOW_SLOTS):  # the hull's cross-flow drag, its length the factors' k
        length = next(float(code.k[f]) for f in range(len(code.signal))
                      if code.signal[f] in CROSSFLOW_SLOTS)  # fmt: skip
        sway, yaw = CROSSFLOW_SLOTS
        body.append(f"s{sway}, s{yaw} = _kernel.crossflow(v, r, {length!r})")
    if RUDDER_SLOT in used:  # the rudder's normal force, its inflow's parameters the table's
        a, c, g, x = (float(p) for p in code.rudder)
        body.append(f"s{RUDDER_SLOT} = _kernel.rudder_normal(u, v, r, inp[0], inp[1], {a!r}, "
                    f"{c!r}, {g!r}, {x!r})")
    for i in (5, 6, 7):
        if i in used:
            body.append(f"s{i} = inp[{i - 5}]")
    if used & {8, 9}:
        # Air velocity relative to the ship, earth frame, then body frame; the angle it comes from.
        body += ["if wind_true:",
                 "    ax = -vw * math.cos(dw) - xd", "    ay = -vw * math.sin(dw) - yd",
                 "    bx = ax * c + ay * sn", "    by = -ax * sn + ay * c",
                 "    s8 = math.sqrt(bx * bx + by * by)", "    s9 = math.atan2(-by, -bx)",
                 "else:", "    s8 = inp[3]", "    s9 = inp[4]"]  # fmt: skip
    for j in range(code.n_terms):
        names = []
        for f in range(int(code.start[j]), int(code.start[j + 1])):
            name = f"f{j}_{f}"
            body += _factor_expr(int(code.signal[f]), int(code.op[f]), float(code.k[f]),
                                 int(code.power[f]), name)  # fmt: skip
            names.append(name)
        body.append(f"phi{j} = " + (" * ".join(names) if names else "1.0"))
    for i in range(3):
        js = [j for j in range(code.n_terms) if pairs is None or pairs[i, j]]
        terms = " + ".join(f"th[{i}, {j}] * phi{j}" for j in js) or "0.0"
        body.append(f"a{i} = {terms}")
    body.append("return a0, a1, a2, r, xd, yd")
    rhs = "\n".join("    " + line for line in body)
    return f'''"""Generated by shipid {__version__} (shipid.dynamics.codegen) for the term set
{list(code.texts)!r}; signals {[_signal_name(s) for s in sorted(used)]!r}. Do not edit."""

import math
import sys

import numba
import numpy as np

from shipid.dynamics import kernel as _kernel

_self = sys.modules[__name__]


@numba.njit(cache=True, inline="always")
def rhs(ctx, u, v, r, psi):
{rhs}


@numba.njit(cache=True, parallel=True)
def integrate_open(theta, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
    for b in numba.prange(theta.shape[0]):
        inp = np.zeros(_kernel.N_INPUTS)
        ctx = (theta[b], inp, False, 0.0, 0.0)
        n_valid[b] = _kernel.open_run(_self.rhs, ctx, inp, t, inputs[b], n_steps[b], s0[b], rk4,
                                      speed_lim[b], yaw_lim[b], out[b])


@numba.njit(cache=True, parallel=True)
def integrate_closed(theta, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder,
                     n_valid):
    for b in numba.prange(theta.shape[0]):
        p = params[b]
        inp = np.zeros(_kernel.N_INPUTS)
        ctx = (theta[b], inp, True, p[_kernel.P_WIND_SPEED], p[_kernel.P_WIND_DIR])
        n_valid[b] = _kernel.closed_run(_self.rhs, ctx, inp, p, dt, n_steps, s0[b], rk4,
                                        speed_lim[b], yaw_lim[b], states[b], rudder[b])
'''


def _key(text: str) -> str:
    """The generated module's name suffix: a hash of its source, the integrators it compiles in
    (numba does not track a cached function's callees) and shipid's version."""
    import hashlib  # 3 ms: on first use, not on every command's start-up

    from shipid.dynamics import kernel

    h = hashlib.sha256(text.encode() + kernel.source_digest().encode() + __version__.encode())
    return h.hexdigest()[:20]


def nonzero_pairs(code: TermCode, theta: np.ndarray) -> np.ndarray:
    """(3, T) bool: the (equation, term) pairs non-zero in any of the coefficient sets ``theta``
    ((3, T) or (B, 3, T))."""
    return np.any(np.asarray(theta).reshape(-1, 3, code.n_terms) != 0.0, axis=0)


def _loaded_key(code: TermCode, pairs: np.ndarray | None) -> tuple[tuple[str, ...], bytes]:
    return code.texts, b"" if pairs is None else np.packbits(pairs).tobytes()


def load(code: TermCode, pairs: np.ndarray | None = None) -> ModuleType | None:
    """The generated kernels of ``code`` with the non-zero coefficient ``pairs`` (None: all)
    (written and imported on first use), or None where the cache folder cannot be written."""
    global _unwritable
    key = _loaded_key(code, pairs)
    with _lock:
        if key in _loaded:
            return _loaded[key]
        if _unwritable:
            return None
        text = source(code, pairs)
        name = f"shipid_terms_{_key(text)}"
        folder = cache_dir()
        path = folder / f"{name}.py"
        try:
            folder.mkdir(parents=True, exist_ok=True)
            if not path.exists():
                tmp = folder / f".{name}.{os.getpid()}.tmp"
                tmp.write_text(text, encoding="utf-8")
                os.replace(tmp, path)  # atomic: concurrent processes write the same text
        except OSError:
            _unwritable = True
            return None
        import importlib.util

        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        _loaded[key] = module
        return module


def _check(engine: str) -> str:
    if engine not in ENGINES:
        from shipid.errors import ShipidError

        raise ShipidError(f"engine must be one of {ENGINES}, got {engine!r}")
    return engine


@contextlib.contextmanager
def use(engine: str):
    """Run the simulations inside the ``with`` block on ``engine`` ('auto', 'generated',
    'interpreted'), e.g. to compare the two or to force the generated kernels."""
    token = _engine.set(_check(engine))
    try:
        yield
    finally:
        _engine.reset(token)


def choose(code: TermCode, steps: int, engine: str | None = None,
           theta: np.ndarray | None = None) -> ModuleType | None:  # fmt: skip
    """The generated kernels to run ``steps`` state-steps of ``code`` with the coefficient sets
    ``theta`` (their non-zero pairs are compiled in; None: every pair), or None for the
    interpreter; ``engine`` None is the one ``use`` set ('auto' by default)."""
    engine = _check(_engine.get() if engine is None else engine)
    if engine == "interpreted":
        return None
    pairs = None if theta is None else nonzero_pairs(code, theta)
    if engine == "auto" and steps < GENERATED_MIN_STEPS and _loaded_key(code, pairs) not in _loaded:
        return None
    return load(code, pairs)
