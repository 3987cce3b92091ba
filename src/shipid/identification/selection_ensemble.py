"""Uncertainty of a selected model that includes the choice of its terms.

A bootstrap of the selected structure (``shipid.identification.uncertainty.bootstrap``) holds the
terms and γ at the selection's: its intervals say what the equation error leaves uncertain in
*those* coefficients, not that other structures fitted the held-out logs almost as well and
predict differently beyond them. Here each replicate first draws a candidate of the search (its
terms and γ) with the probability ``select`` chose it on resampled held-out logs
(``Candidate.share``, ``shipid.identification.select.selection_shares``), then refits it on a
moving-block resample of the equations (or a resample of whole logs), as ``bootstrap`` does. A
member's coefficient of a term its candidate lacks is 0, so every member is a model of the union
of the drawn structures.

When one candidate is always chosen, the ensemble is ``bootstrap`` of it, replicate for
replicate (the block resamples come from the same random stream).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from shipid.dynamics.model import DOFS, ModelStructure
from shipid.errors import ShipidError
from shipid.identification.uncertainty import (
    SELECTION_LOG_METHOD,
    SELECTION_METHOD,
    WHOLE_LOGS,
    Ensemble,
    _bar,
    resampler,
)


def selection_ensemble(
    logs: Sequence[pd.DataFrame],
    selection,
    replicates: int = 200,
    block_s: float | str = "auto",
    seed: int = 0,
    names: Sequence[str] | None = None,
    progress: bool = False,
) -> Ensemble:
    """Ensemble of ``selection`` (a ``Selection``) over the choice of terms and the equations.

    Parameters
    ----------
    logs : the logs ``select`` was given (the same ones, in the same rudder convention).
    selection : what ``select`` returned; its ``shares`` say how often each candidate is chosen.
    replicates, block_s, seed : as ``bootstrap``.
    names : log names for messages.
    """
    from shipid.identification.identify import weighted_refit

    logs = [logs] if isinstance(logs, pd.DataFrame) else list(logs)
    draw, block_s = resampler(logs, replicates, block_s)
    cands = list(selection.shares)
    if not cands:
        raise ShipidError("the selection has no candidate chosen on resampled held-out logs "
                          "(no plausible candidate); no ensemble over its terms")  # fmt: skip
    p = np.array([c.share for c in cands], dtype=float)
    p /= p.sum()
    point = selection.model
    structure = point.structure.union(*(c.terms for c in cands),
                                      name=f"{point.structure.name} (ensemble)")
    columns = {t: j for j, t in enumerate(structure.all_terms)}
    options = selection.options
    rng = np.random.default_rng(seed)  # the block resamples: bootstrap's stream
    draws = np.random.default_rng([seed, 1]).choice(len(cands), size=replicates, p=p)
    refits: dict[int, object] = {}
    thetas = np.zeros((replicates, 3, len(columns)))
    bar = _bar(progress, replicates)
    for k, i in enumerate(draws):
        if i not in refits:
            refits[i] = weighted_refit(logs, model=ModelStructure("candidate", cands[i].terms),
                                       gamma=cands[i].gamma, names=names,
                                       estimator=options.estimator, physics=options.physics)  # fmt: skip
        member = refits[i](draw(rng))
        for dof, coefs in member.coefficients.items():
            for t, value in coefs.items():
                thetas[k, DOFS.index(dof), columns[t]] = value
        bar.update()
    bar.close()
    return Ensemble(point, thetas, block_s, int(seed),
                    SELECTION_LOG_METHOD if block_s == WHOLE_LOGS else SELECTION_METHOD, structure)

