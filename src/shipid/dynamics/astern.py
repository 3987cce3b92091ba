"""Terms fitted on logs that never go astern, written in the form that carries them astern.

On logs where the ship always runs ahead (u > 0) some terms cannot be told from another form:
u·v is |u|·v there, u²·δ is |u|·u·δ. The fit is the same either way, but astern (u < 0) the two
forms part, and only one is the physics:

====  ===========  ==============  ======================================================
 eq   fitted       written         why
====  ===========  ==============  ======================================================
 v̇   u·v          |u|·v           the hull's sway damping damps going astern too
 ṙ   u·r          |u|·r           the hull's yaw damping damps going astern too
 any  u²·δ         |u|·u·δ         the rudder's lift reverses with the flow over it
 any  u²·δ²        |u|·u·δ²        the rudder's drag opposes the motion
====  ===========  ==============  ======================================================

(Fossen 2011, *Handbook of Marine Craft Hydrodynamics and Motion Control*, §7: the modulus
forms of Blanke's model are the ones written for both directions of motion.) The other terms
keep their form: u·r in v̇ and u·v in ṙ are mostly the rigid body's centripetal force and the
Munk moment, which change sign with u, and v·r, r² in u̇ are kinematic.

Measured on the Esso Osaka (``benchmarks/study_ahead_forms.py``): the default model of one
zig-zag file, run over the four random runs (a third of their time astern), diverged in 12 of
36 runs with the fitted forms, with these in none; the zig-zags and turns (ahead) are predicted
as before, bit for bit. A log that goes astern settles the form itself: the forms are then left
as fitted.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.dynamics.renaming import TermRenaming, renamed_model, renamed_terms
from shipid.dynamics.terms import parse_term

# (equation or None for any, the fitted term) → the form written, in canonical texts.
AHEAD_FORMS: Mapping[tuple[str | None, str], str] = {
    (dof, parse_term(fitted).text): parse_term(written).text
    for dof, fitted, written in (("v", "u*v", "|u|*v"), ("r", "u*r", "|u|*r"),
                                 (None, "u^2*delta", "|u|*u*delta"),
                                 (None, "u^2*delta^2", "|u|*u*delta^2"))
}  # fmt: skip


def astern_form(dof: str, term: str) -> str:
    """The form ``term`` of equation ``dof`` is written in (``AHEAD_FORMS``), or ``term``."""
    text = parse_term(term).text
    return AHEAD_FORMS.get((dof, text)) or AHEAD_FORMS.get((None, text)) or text


def logs_ahead(logs: Sequence[pd.DataFrame]) -> bool:
    """Whether every log runs ahead throughout (u > 0 in every sample)."""
    return bool(logs) and all(float(np.min(log["u"].to_numpy(dtype=float))) > 0 for log in logs)


def ahead_forms(structure: ModelStructure) -> TermRenaming:
    """The ``AHEAD_FORMS`` of ``structure``'s terms (``shipid.dynamics.renaming``, ratio 1); a
    term whose form the equation already has (u·v beside |u|·v) keeps its fitted one, as the
    two are the fit's separate terms."""
    return TermRenaming(renamed_terms(structure, lambda dof, t: (astern_form(dof, t), 1.0)))


def written_ahead(model: ManoeuvringModel) -> ManoeuvringModel:
    """``model`` with its terms in their ``AHEAD_FORMS``: the same accelerations wherever
    u ≥ 0."""
    found = ahead_forms(model.structure)
    return renamed_model(model, found) if found.changes else model
