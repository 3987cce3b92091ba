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

**The propeller reversed.** Logs that never reverse the propeller (n ≥ 0 throughout) cannot
tell its thrust ahead, pos(n)² or |n|·n in the surge, from what it does astern: a selection's
pos(n)² gives nothing there (a crash stop coasts on the hull's resistance), and advance-ratio
similarity's |n|·n mirrors the thrust astern whole. A fixed-pitch propeller turned astern pushes
less than ahead (its sections meet the water trailing edge first, and its race runs along the
hull), so the thrust is written as ``propeller(k)``, n² ahead and −k·n² astern, k the
``ASTERN_THRUST_RATIO`` of ``shipid.dynamics.propeller`` (``--astern-thrust`` to set another).
The same fit wherever n ≥ 0.

Measured on the Esso Osaka (``benchmarks/study_astern_thrust.py``; its four random runs reverse
the propeller for 16–36 % of their samples, and no model here was fitted to them): chosen by
the free runs of three of the runs and judged on the fourth, k is 0.5 or 0.6 in each of the four
folds, and the nine zig-zags' model predicts the held-out run's u, v and r better than with
the thrust as fitted in every fold. k is a prior, not a finding of these logs: logs with the
propeller astern give the ship's own terms (neg(n)²), and are then left as fitted.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shipid.data.log import column_values
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
    return bool(logs) and all(float(np.min(column_values(log, "u", float))) > 0 for log in logs)


# The surge's thrust terms that logs which never reverse the propeller cannot tell apart.
AHEAD_THRUST = frozenset(parse_term(t).text for t in ("pos(n)^2", "|n|*n"))


def thrust_form(dof: str, term: str, ratio: float) -> str:
    """The form ``term`` of equation ``dof`` is written in where the logs never reverse the
    propeller: a thrust term of the surge as ``propeller(ratio)``, else ``term``."""
    text = parse_term(term).text
    if dof == "u" and text in AHEAD_THRUST:
        return parse_term(f"propeller({ratio:.12g})").text
    return text


def logs_never_reverse(logs: Sequence[pd.DataFrame]) -> bool:
    """Whether every log logs the propeller speed and never reverses it (n ≥ 0 throughout)."""
    return bool(logs) and all(
        "n" in log.columns and float(np.nanmin(column_values(log, "n", float))) >= 0
        for log in logs)  # fmt: skip


@dataclass(frozen=True)
class AsternForms:
    """What a model of logs that never go astern is written as: ``hull``, its ``AHEAD_FORMS``
    (the logs never go astern); ``thrust_ratio``, its thrust as ``propeller(k)`` (the logs never
    reverse the propeller; None: as fitted)."""

    hull: bool = False
    thrust_ratio: float | None = None

    def __bool__(self) -> bool:
        return self.hull or self.thrust_ratio is not None

    def form(self, dof: str, term: str) -> str:
        """The form ``term`` of equation ``dof`` is written in."""
        text = astern_form(dof, term) if self.hull else parse_term(term).text
        return text if self.thrust_ratio is None else thrust_form(dof, text, self.thrust_ratio)

    def renaming(self, structure: ModelStructure) -> TermRenaming:
        """The forms of ``structure``'s terms (``shipid.dynamics.renaming``, ratio 1); a term
        whose form the equation already has (u·v beside |u|·v) keeps its fitted one, as the two
        are the fit's separate terms."""
        return TermRenaming(renamed_terms(structure, lambda dof, t: (self.form(dof, t), 1.0)))

    def parts(self, structure: ModelStructure) -> tuple[bool, bool]:
        """Which of these forms change ``structure``: (its hull's and rudder's terms, its
        thrust)."""
        changed = [new for eq in self.renaming(structure).renamed.values()
                   for old, (new, _) in eq.items() if new != old]  # fmt: skip
        thrust = [any(f.propeller for f in parse_term(t).factors) for t in changed]
        return (not all(thrust), any(thrust))

    def for_model(self, model: ManoeuvringModel) -> AsternForms:
        """These forms for ``model``: its thrust written at the ratio only where it pushes ahead
        in one term (its surge's fitted pos(n)² or |n|·n > 0); a negative one is no thrust (the
        fit carried it in another term), and mirrored at a ratio it would push ahead when
        reversed; a surge with both (a ``select --average`` of candidates with either) cannot
        write their sum as one ``propeller(k)`` (the two are one term there) and renaming one
        would brake astern at neither ratio: left as fitted."""
        if self.thrust_ratio is None:
            return self
        coefs = model.coefficients.get("u", {})
        thrust = [float(c) for t, c in coefs.items() if parse_term(t).text in AHEAD_THRUST]
        pushes = len(thrust) == 1 and thrust[0] > 0
        return self if pushes else AsternForms(self.hull, None)

    def written(self, model: ManoeuvringModel) -> ManoeuvringModel:
        """``model`` in these forms (``for_model``): the same accelerations wherever u ≥ 0
        (``hull``) and n ≥ 0 (``thrust_ratio``)."""
        found = self.for_model(model).renaming(model.structure)
        return renamed_model(model, found) if found.changes else model


def ahead_forms(structure: ModelStructure) -> TermRenaming:
    """The ``AHEAD_FORMS`` of ``structure``'s terms (``AsternForms.renaming``, the hull's and
    rudder's alone)."""
    return AsternForms(hull=True).renaming(structure)


def written_ahead(model: ManoeuvringModel) -> ManoeuvringModel:
    """``model`` with its terms in their ``AHEAD_FORMS``: the same accelerations wherever
    u ≥ 0."""
    return AsternForms(hull=True).written(model)
