"""Methods × held-out logs: the paper's future-work comparison as one call.

Every method is cross-validated the same way (leave one log out, or k-fold by log): fitted on the
other logs, run free over the held-out one from its measured initial state with its measured
inputs, scored by the normalised error of ``shipid.identification.cross_validation.normalised_error``
(per state, error RMS over the state's spread in the held-out log; samples after a divergence
count ``divergence_penalty``).

Methods: the semiphysical estimators of ``shipid.identification.estimators`` on a given
structure ('lssvm', 'ols', 'ridge', 'lasso', 'svr'), and black-box dynamics ('elm', 'lssvm-rbf')
on u, v, r and the structure's inputs; ``select:LIBRARY`` runs the structure search inside each
fold (nested CV: the held-out log is never seen by the search).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from shipid.data.log import column_array, column_values, common_rudder_convention
from shipid.dynamics.model import DOFS, ModelStructure, get_structure
from shipid.dynamics.simulate import simulate_log
from shipid.errors import ShipidError
from shipid.identification.cross_validation import normalised_error
from shipid.identification.estimators import (
    BLACK_BOX_ESTIMATORS,
    ESTIMATORS,
    RegressorDynamics,
    make_black_box,
)
from shipid.identification.select import STATES, cross_validate

DEFAULT_METHODS = ("lssvm", "ols", "ridge", "lasso", "svr", "elm")


def _black_box_fold(method: str, train: list[pd.DataFrame], test: pd.DataFrame, inputs,
                    gamma: float, sim_method: str, penalty: float
                    ) -> tuple[np.ndarray, bool]:  # fmt: skip
    dt = float(np.median(np.diff(train[0]["t"])))
    features, targets = [], []
    for log in train:
        X = np.column_stack([column_values(log, c) for c in ("u", "v", "r", *inputs)])
        features.append(X[:-1])
        targets.append(np.column_stack([np.diff(column_values(log, d)) / dt for d in DOFS]))
    X, Y = np.vstack(features), np.vstack(targets)
    estimators = [make_black_box(method, gamma).fit(X, Y[:, i]) for i in range(3)]
    dyn = RegressorDynamics(estimators, inputs, name=method)
    sim = simulate_log(dyn, test, method=sim_method)
    measured = column_array(test, STATES)
    simulated = column_array(sim.log, STATES)
    return normalised_error(measured, simulated, penalty), sim.diverged


def compare(
    logs: Sequence[pd.DataFrame],
    structure: str | ModelStructure = "blanke",
    methods: Sequence[str] = DEFAULT_METHODS,
    names: Sequence[str] | None = None,
    gamma: float = 1e4,
    cv: str = "logo",
    method: str = "euler",
    divergence_penalty: float = 2.0,
    progress: bool = False,
) -> pd.DataFrame:
    """One row per (method, held-out log): normalised error per state, score, diverged."""
    logs, _ = common_rudder_convention(list(logs))  # one rudder convention for all folds
    names = list(names or [log.attrs.get("name", f"log {i}") for i, log in enumerate(logs)])
    if len(logs) < 2:
        raise ShipidError("compare needs at least 2 logs (each is held out in turn)")
    if cv != "logo" and any(not m.startswith("select:") and m in BLACK_BOX_ESTIMATORS
                            for m in methods):  # fmt: skip
        raise ShipidError("black-box methods are compared leave-one-log-out only (--cv logo)")
    structure = get_structure(structure) if isinstance(structure, str) else structure
    inputs = ("delta", *structure.inputs)
    rows = []
    from shipid.progress import progress as counted

    for m in counted(methods, "methods", shown=bool(progress)):
        if m.startswith("select:"):
            rows += _nested_select(logs, names, m.split(":", 1)[1], gamma, method,
                                   divergence_penalty)  # fmt: skip
        elif m in BLACK_BOX_ESTIMATORS:
            for h, (test, name) in enumerate(zip(logs, names, strict=True)):
                train = [log for j, log in enumerate(logs) if j != h]
                e, div = _black_box_fold(m, train, test, inputs, gamma, method,
                                         divergence_penalty)  # fmt: skip
                rows.append({"method": m, "held_out": name, "diverged": bool(div),
                             **dict(zip(STATES, e.tolist(), strict=True)),
                             "score": float(e.mean())})  # fmt: skip
        elif m in ESTIMATORS:
            df = cross_validate(logs, structure, (gamma,), names, cv, m, method,
                                divergence_penalty)  # fmt: skip
            rows += [{"method": m, **r} for r in df.drop(columns="gamma").to_dict("records")]
        else:
            raise ShipidError(f"unknown method {m!r}; use {', '.join(ESTIMATORS)} or "
                              "select:LIBRARY")  # fmt: skip
    return pd.DataFrame(rows)


def _nested_select(logs, names, library, gamma, method, penalty) -> list[dict]:
    from shipid.identification.select import select

    rows = []
    for h, (test, name) in enumerate(zip(logs, names, strict=True)):
        train = [log for j, log in enumerate(logs) if j != h]
        train_names = [n for j, n in enumerate(names) if j != h]
        if len(train) < 2:
            raise ShipidError("select:LIBRARY in compare needs at least 3 logs (nested CV)")
        sel = select(train, library=library, names=train_names, method=method,
                     divergence_penalty=penalty)  # fmt: skip
        sim = simulate_log(sel.model, test, method=method)
        e = normalised_error(column_array(test, STATES),
                             column_array(sim.log, STATES), penalty)  # fmt: skip
        rows.append({"method": f"select:{library}", "held_out": name, "diverged": sim.diverged,
                     **dict(zip(STATES, e.tolist(), strict=True)), "score": float(e.mean())})
    return rows


def summary(table: pd.DataFrame) -> pd.DataFrame:
    """Methods × held-out logs of the score, with the mean and the number of diverged folds."""
    wide = table.pivot_table(index="method", columns="held_out", values="score", sort=False)
    wide["mean"] = wide.mean(axis=1)
    wide["diverged"] = table.groupby("method", sort=False)["diverged"].sum()
    return wide.sort_values("mean")
