"""Cross-validation over logs: the folds (leave one log out, K folds of logs, K blocks of every
log), and the free-run score a held-out log gives a model, shared by ``select`` (terms and γ),
``identify --gamma auto``, the prefilter, the cross-validated error band and the kernel
residual's γ and σ."""

from __future__ import annotations

import numpy as np
import pandas as pd

from shipid.data.log import refuse_copies, refuse_other_ships
from shipid.errors import ShipidError

# The choices ``identify`` makes by free-run cross-validation (the structure, select's terms, γ)
# leave each log out in turn from this many logs; fewer are cut into blocks, BLOCKS each. Two
# logs left out in turn are two folds, whose scores choose among close candidates by luck: of
# the Esso Osaka's 36 pairs of zig-zag files, the default's 35° turns came 30 % off in the median
# (mean 56 %, 1.50 of the spread in the random runs' yaw rate) with the two files left out, 26 %
# (mean 40 %, 1.16) with four blocks of each (``benchmarks/study_esso_single_logs.py``); from
# three files leaving each out is as good as blocks (ad hoc, 12 triples).
LOGS_LEFT_OUT = 3
BLOCKS = 4
BLOCK_SAMPLES = 10  # the fewest samples a block may hold (``split_blocks``)


def choice_cv(logs) -> str:
    """The default cross-validation of a choice made on ``logs``: 'logo' from ``LOGS_LEFT_OUT``
    logs, else 'blocks:BLOCKS', but 'logo' for two logs one of which is too short to cut into
    blocks (``split_blocks`` would refuse it; a single log has no other choice)."""
    if len(logs) >= LOGS_LEFT_OUT:
        return "logo"
    if len(logs) == 2 and not all(_blocks_fit(len(log), BLOCKS) for log in logs):
        return "logo"
    return f"blocks:{BLOCKS}"


def _block_edges(n: int, k: int) -> np.ndarray:
    """The sample indices that cut ``n`` samples into ``k`` contiguous blocks."""
    return np.linspace(0, n, k + 1).round().astype(int)


def _blocks_fit(n: int, k: int) -> bool:
    """Whether ``n`` samples cut into ``k`` blocks leave each at least ``BLOCK_SAMPLES``."""
    return bool(np.diff(_block_edges(n, k)).min() >= BLOCK_SAMPLES)


def parse_cv(cv: str, option: str = "--cv", kinds: tuple[str, ...] = ("kfold", "blocks")
             ) -> tuple[str, int]:  # fmt: skip
    """('logo', 0) or (kind, K) of 'kind:K' with K ≥ 2 for a kind of ``kinds``; else a one-line
    error naming ``option``."""
    if cv == "logo":
        return "logo", 0
    for kind in kinds:
        if isinstance(cv, str) and cv.startswith(kind + ":"):
            try:
                k = int(cv.split(":", 1)[1])
            except ValueError:
                k = 0
            if k >= 2:
                return kind, k
    forms = " or ".join(["'logo'", *(f"'{kind}:K'" for kind in kinds)])
    raise ShipidError(f"{option} must be {forms} with K ≥ 2, got {cv!r}")


def split_blocks(logs, names, k: int) -> tuple[list[pd.DataFrame], list[str]]:
    """Every log cut into ``k`` contiguous blocks (each a log of its own, named after it)."""
    out, out_names = [], []
    for log, name in zip(logs, names, strict=True):
        if not _blocks_fit(len(log), k):
            raise ShipidError(f"{name}: too short for --cv blocks:{k} ({len(log)} samples)")
        edges = _block_edges(len(log), k)
        for j, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
            block = log.iloc[a:b].reset_index(drop=True)
            block.attrs = dict(log.attrs)
            out.append(block)
            out_names.append(f"{name} [block {j + 1}/{k}]")
    return out, out_names


def folds(n_logs: int, cv: str) -> list[list[int]]:
    """Held-out log indices of each fold of ``cv`` ('logo', 'kfold:K'; blocks are logs by
    then)."""
    kind, k = parse_cv(cv)
    if kind == "kfold":
        if k > n_logs:
            raise ShipidError(f"--cv kfold:{k} needs at least {k} logs, got {n_logs}")
        return [list(f) for f in np.array_split(np.arange(n_logs), k)]
    return [[i] for i in range(n_logs)]


def normalised_error(measured: np.ndarray, simulated: np.ndarray, penalty: float,
                     scale: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """Per state: RMS of (simulated − measured)/σ(measured) over the whole log, the samples after
    a divergence (simulated is shorter) counting ``penalty`` each. 1 ≈ predicting the mean.
    ``scale``: σ per state to use instead (e.g. the whole log's, for a part of it)."""
    n, m = len(measured), len(simulated)
    sigma = np.maximum(measured.std(axis=0) if scale is None else scale, 1e-9)
    err = (simulated - measured[:m]) / sigma
    return np.sqrt((np.sum(err * err, axis=0) + (n - m) * penalty * penalty) / n)


def held_out_logs(logs, names, cv: str, option: str) -> tuple[list, list[str], str, str]:
    """(logs, names, the ``cv`` resolved, what is held out: 'logs' or 'blocks') for a search
    that leaves each log, or with 'blocks:K' each block of every log, out in turn. ``'auto'``:
    logo from two logs, four blocks of one. Fewer than two to hold out is a one-line error
    naming ``option``."""
    logs, names = list(logs), list(names)
    refuse_other_ships(logs, names)
    refuse_copies(logs, names)
    if cv == "auto":
        cv = "logo" if len(logs) >= 2 else "blocks:4"
    kind, k = parse_cv(cv, option, kinds=("blocks",))
    held_out = "logs"
    if kind == "blocks":
        logs, names = split_blocks(logs, names, k)
        held_out = "blocks"
    if len(logs) < 2:
        raise ShipidError(f"{option} needs two logs to hold one out; give more logs, or "
                          "blocks:K to cut one")  # fmt: skip
    return logs, names, cv, held_out
