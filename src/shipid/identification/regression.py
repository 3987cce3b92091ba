"""From a model structure and trial logs to one regression problem per degree of freedom (paper
eqs. 11–12).

* ``form="paper"``: y_k = ξ(k+1) on x_k = [ξ(k), terms(k)...] (eq. 12), the ξ(k) coefficient
  estimated.
* ``form="increment"``: y_k = (ξ(k+1) − ξ(k))/Δk on the terms alone, i.e. the ξ(k) coefficient fixed
  to 1. The regressors of the paper's form contain ξ(k) itself, which with noisy measurements makes
  the estimated ξ(k) coefficient absorb the noise and the collinearity with the other terms.

The constant term "1" is not a column: the LS-SVM bias b plays its part (and Σα = 0 would make
its weight zero anyway). Samples pair k with k+1 of the same log only, never across two logs.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np
import pandas as pd

from shipid.data.log import column_values, input_columns
from shipid.data.preprocess import gap_text, time_gaps
from shipid.dynamics.model import ModelStructure
from shipid.dynamics.terms import parse_term, required_inputs, term_matrix
from shipid.errors import ShipidError

FORMS = ("increment", "paper")
# Sampling is uniform when every interval is within this fraction of the median: printed times
# (6–9 digits) jitter by far less, and a 0.1 % error in one interval is far below the noise.
DT_RTOL = 1e-3
T = TypeVar("T")


@dataclass
class RegressionProblem:
    dof: str
    form: str
    dt: float
    names: list[str]  # columns of X
    X: np.ndarray
    y: np.ndarray
    has_constant: bool  # "1" is a term: the bias b is its coefficient
    fixed: dict[str, float] = field(default_factory=dict)


def sampling_time(log: pd.DataFrame, name: str = "log") -> float:
    """Δk of a log, which must be uniform (resample it otherwise)."""
    return per_log(log, "sampling_time", lambda: _sampling_time(log, name))


def _sampling_time(log: pd.DataFrame, name: str) -> float:
    t = column_values(log, "t")
    if len(t) < 3:
        raise ShipidError(f"{name}: {len(t)} samples, too short for identification")
    dts = np.diff(t)
    dt = float(np.median(dts))
    if np.max(np.abs(dts - dt)) > DT_RTOL * dt:
        gaps = time_gaps(t)
        if gaps:
            raise ShipidError(f"{name}: {gap_text(t, gaps)}: a one-step regression needs "
                              "consecutive samples; cut the log there (--start/--end) or split "
                              "it into two logs (--dt with --fill-gaps interpolates it)")  # fmt: skip
        k = int(np.argmax(np.abs(dts - dt)))
        raise ShipidError(f"{name}: sampling is not uniform (Δt = {dts[k]:.6g} s at data row "
                          f"{k + 2}, median {dt:.6g} s); resample it with --dt {dt:.6g}")  # fmt: skip
    return dt


def common_sampling_time(logs: Sequence[pd.DataFrame], names: Sequence[str]) -> float:
    """The one uniform Δk of several logs (each uniform, all equal)."""
    dts = [sampling_time(log, n) for log, n in zip(logs, names, strict=True)]
    for d, n in zip(dts[1:], names[1:], strict=True):
        if abs(d - dts[0]) > DT_RTOL * dts[0]:
            raise ShipidError(f"{n}: sampling time {d:.6g} s differs from {dts[0]:.6g} s of "
                              f"{names[0]}; resample the logs to one Δk with --dt")  # fmt: skip
    return dts[0]


# Inside ``shared_term_columns``: id(log) → (the log, {term: its values along the log, and
# ("fact", name): a fact of it, ``per_log``}).
_SHARED: ContextVar[dict[int, tuple[pd.DataFrame, dict]] | None] = \
    ContextVar("shared_term_columns", default=None)  # fmt: skip


@contextmanager
def shared_term_columns() -> Iterator[None]:
    """Within it, a term's values along a log are computed once and shared by every fit of that
    log: the candidates of an average share most of their terms, and each fit built every
    column anew (5–9 % of ``identify``'s time on nine Esso zig-zag files, 6–15 % on a pair of
    them; benchmarks/README.md, *Start-up and end to end*). The logs must not
    change in place inside it; each cached log is held, so its id names it alone. Nested uses
    share the outermost cache."""
    if _SHARED.get() is not None:
        yield
        return
    token = _SHARED.set({})
    try:
        yield
    finally:
        _SHARED.reset(token)


def per_log(log: pd.DataFrame, fact: str, compute: Callable[[], T]) -> T:
    """``compute()``, a fact of ``log`` (its Δk, its envelope), once per log inside
    ``shared_term_columns``, where a search fits the same logs hundreds of times (4000 Δk and
    150 envelopes of nine Esso zig-zags in one ``identify``); outside it, every time. A
    ``compute`` that raises leaves nothing behind."""
    shared = _SHARED.get()
    if shared is None:
        return compute()
    held, columns = shared.setdefault(id(log), (log, {}))
    if held is not log:  # pragma: no cover - an id is unique while its log is held
        return compute()
    key = ("fact", fact)  # not a term's name: a term is a string
    if key not in columns:
        columns[key] = compute()
    return columns[key]


def log_terms(log: pd.DataFrame, names: Sequence[str], name: str = "log") -> np.ndarray:
    """(N, len(names)) values of the terms ``names`` along a log."""
    shared = _SHARED.get()
    if shared is None or not names:
        return _log_terms(log, names, name)
    held, columns = shared.setdefault(id(log), (log, {}))
    if held is not log:  # pragma: no cover - an id is unique while its log is held
        return _log_terms(log, names, name)
    missing = [n for n in dict.fromkeys(names) if n not in columns]
    if missing:
        columns.update(zip(missing, _log_terms(log, missing, name).T, strict=True))
    return np.column_stack([columns[n] for n in names])


def _log_terms(log: pd.DataFrame, names: Sequence[str], name: str) -> np.ndarray:
    inputs = input_columns(log, required_inputs(names), name)
    inputs["delta"] = column_values(log, "delta")
    return term_matrix(list(names), column_values(log, "u"), column_values(log, "v"),
                       column_values(log, "r"), inputs)  # fmt: skip


def regression_problem(
    logs: Sequence[pd.DataFrame],
    structure: ModelStructure,
    dof: str,
    form: str = "increment",
    fixed: Mapping[str, float] | None = None,
    names: Sequence[str] | None = None,
    known: Callable[[pd.DataFrame], np.ndarray] | None = None,
) -> RegressionProblem:
    """Stack the regression of one degree of freedom over several logs.

    ``fixed`` terms (name → continuous-time coefficient) are moved to the target side, and so
    is ``known(log)``: an acceleration of this DOF already known at each sample but the last (a
    reference ship's, ``shipid.identification.correction``; increment form).
    """
    if form not in FORMS:
        raise ShipidError(f"unknown form {form!r}; use one of {', '.join(FORMS)}")
    if dof not in structure.terms:
        raise ShipidError(f"{structure.name} has no {dof} equation")
    fixed = {parse_term(k).text: float(v) for k, v in (fixed or {}).items()}
    unknown = set(fixed) - set(structure.terms[dof])
    if unknown:
        raise ShipidError(f"fixed terms {sorted(unknown)} are not in the {dof} equation "
                          f"({list(structure.terms[dof])})")  # fmt: skip
    free = [n for n in structure.terms[dof] if n not in fixed and n != "1"]
    if form == "paper" and dof in free:
        free.remove(dof)  # ξ(k) is already the first regressor
    has_constant = "1" in structure.terms[dof] and "1" not in fixed
    names = names or [f"log {i}" for i in range(len(logs))]
    dt = common_sampling_time(logs, names)
    Xs, ys = [], []
    for log, name in zip(logs, names, strict=True):
        xi = column_values(log, dof)
        F = log_terms(log, free, name)[:-1]
        target = (xi[1:] - xi[:-1]) / dt
        if fixed:
            Ffix = log_terms(log, list(fixed), name)[:-1]
            target = target - Ffix @ np.fromiter(fixed.values(), float)
        if known is not None:
            target = target - known(log)
        if form == "paper":
            # Eq. (12) as printed: raw terms, so Γ = [ξ(k) coefficient, Δk·θ...] is what the
            # LS-SVM regularises, exactly as in the paper.
            Xs.append(np.column_stack([xi[:-1], F]))
            ys.append(xi[:-1] + dt * target)
        else:
            Xs.append(F)
            ys.append(target)
    cols = ([dof] if form == "paper" else []) + free
    return RegressionProblem(dof, form, dt, cols, np.vstack(Xs), np.concatenate(ys), has_constant,
                             fixed)  # fmt: skip
