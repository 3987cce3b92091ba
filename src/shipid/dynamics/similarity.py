"""A model fitted at one propeller speed, carried to every other by advance-ratio similarity.

A ship driven by its propeller at n rps runs at a speed about proportional to n: the advance
ratio J = u/(nD) of a straight run is nearly the same at every n (the Esso Osaka's 3 m model:
0.35 m/s at 10 rps, 0.58 m/s at 16.7). If every speed (u, v, the derived U) and rate (r, n)
of a manoeuvre scales with n and time with 1/n, the hull's, rudder's and propeller's forces
all scale with n², the path is the same, and the accelerations of each equation are sums of
terms of degree 2 in those signals (the thrust counts 2, being a force ∝ n²).

Logs at a constant n cannot show how a term depends on n: at n₀ a constant is a constant, the
rudder's force in δ alone is as good as in n²δ. A model fitted there without n answers any
other propeller speed as at n₀; the paper's ``blanke`` gives a rudder force and a thrust that
do not change with n, so a model of the Esso's 16.7 rps zig-zag turned at 10 rps with the
thrust of 16.7. ``rps_similar`` writes each term of degree d < 2 with the factor (n/n₀)^(2−d)
it needs to scale as the rest: the constant c as c·n|n|/n₀² (thrust and side force reverse
astern), δ as δ·n⁺²/n₀², u·δ as u·δ·n⁺/n₀ (n⁺ = max(n, 0): a rudder term that does not fall
with the ship's speed is the propeller's race over it, which an astern propeller does not throw
there; as n² the rudder kept its full force at −10 rps with the ship at rest, and the Esso's
one-file models' random runs went 1.47 of their spread off instead of 1.18;
``benchmarks/study_ahead_forms.py``), v as v·|n|/n₀. At n₀ the model is the fit itself, bit
for bit up to rounding. Terms of degree above 2 (Abkowitz's u³, v³) cannot be so written (n⁻¹
is no factor of the term algebra) and terms of the wind (an external speed) keep their form.

Measured on the Esso Osaka (``benchmarks/study_esso_single_logs.py``): the default model of one
zig-zag file predicts the held-out logs at another propeller speed with a yaw rate error of
0.37 of their spread against 0.48 (median of 70 logs × models, better in 49 of them).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from shipid.dynamics.model import DOFS, ManoeuvringModel, ModelStructure
from shipid.dynamics.renaming import TermRenaming, renamed_model, renamed_terms
from shipid.dynamics.terms import Term, parse_term

# Signals that scale with the propeller speed under advance-ratio similarity (each degree 1);
# the thrust is a force (degree 2); the relative wind is outside the ship and does not scale.
SCALING = ("u", "v", "r", "U", "n")
EXTERNAL = ("wind_speed", "wind_angle")


def speed_degree(term: Term | str) -> int | None:
    """The term's degree in the signals that scale with n (the thrust counts 2 per power);
    None for a term of the wind, which keeps its form."""
    term = parse_term(term) if isinstance(term, str) else term
    if any(s in term.signals for s in EXTERNAL):
        return None
    return sum(term.degree_in(s) for s in SCALING) + 2 * term.degree_in("thrust")


def similar_term(term: str) -> tuple[str, int]:
    """(the term written to scale as degree 2, the power k of n it gained); (term, 0) for a
    term left as it is."""
    text = parse_term(term).text
    degree = speed_degree(text)
    if degree is None or degree >= 2:
        return text, 0
    k = 2 - degree
    if text == "1":
        return parse_term("n*|n|").text, 2
    if "delta" in parse_term(text).signals:  # the rudder's force: in the race of n ahead only
        return parse_term(f"{text}*{'pos(n)' if k == 1 else 'pos(n)^2'}").text, k
    return parse_term(f"{text}*{'|n|' if k == 1 else 'n^2'}").text, k


@dataclass(frozen=True)
class SimilarityMap(TermRenaming):
    """The terms of a structure carried to advance-ratio similarity at ``rps``
    (``TermRenaming``: a term's ratio is n₀ to the power it gained, negated), ``kept`` the terms
    of degree above 2 left as fitted, {dof: [term]}."""

    rps: float = 0.0
    kept: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    def structure(self, structure: ModelStructure, name: str | None = None) -> ModelStructure:
        """The structure with its terms renamed, named for the similarity."""
        return super().structure(structure, name or
                                 f"{structure.name} (rps-similar at {self.rps:.4g})")  # fmt: skip

    def describe(self) -> str:
        """Which terms gained which factor, in words."""
        out = super().describe()
        kept = sorted({parse_term(t).display() for ts in self.kept.values() for t in ts})
        if kept:
            out += f"; kept as fitted (degree above 2, no factor of n makes them scale): " \
                   f"{', '.join(kept)}"
        return out


def similarity_map(structure: ModelStructure, rps: float) -> SimilarityMap:
    """The ``SimilarityMap`` of ``structure`` at ``rps`` (> 0). A term whose similar form the
    equation already has (its constant beside ``|n|*n``, ``delta`` beside ``pos(n)^2*delta``)
    keeps its fitted form (``shipid.dynamics.renaming.renamed_terms``)."""
    if not (np.isfinite(rps) and rps > 0):
        raise ValueError(f"the propeller speed must be positive, got {rps!r}")

    def similar(dof: str, term: str) -> tuple[str, float]:
        new, k = similar_term(term)
        return new, float(rps) ** -k

    kept = {dof: tuple(t for t in terms if (speed_degree(t) or 0) > 2)
            for dof, terms in structure.terms.items()}  # fmt: skip
    return SimilarityMap(renamed_terms(structure, similar), rps=float(rps), kept=kept)


def rps_similar(model: ManoeuvringModel, rps: float) -> ManoeuvringModel:
    """``model``, fitted on logs at the one propeller speed ``rps``, with each term written to
    scale with the propeller speed as advance-ratio similarity has it (see the module): equal to
    ``model`` at ``rps``, and anchored there (``similar_at_rps``): its manoeuvres start from the
    training logs' approach speed times n/``rps``."""
    found = similarity_map(model.structure, rps)
    return renamed_model(model, found, similar_at_rps=found.rps)


# The equations of the side force: its constant written n|n| alone (``similar_library``; in a
# library with n⁺² and n⁻², by them), the surge keeping its own. A single screw's side force goes
# with n²; a side force the same at every rps, at rest and astern too, held by the Esso Osaka's
# nine zig-zag files turned their model's 10° turn to starboard at 6 rps 12 times as wide in
# lengths as at 16.7, and its yaw missed the random runs (1–5 rps) by 0.79 of their rms against
# 0.65 with the constant so written (``benchmarks/study_esso_side_constant.py``).
SIDE_FORCE = ("v", "r")

# |n|n = n⁺² − n⁻²: an equation that holds both has the constant's similar form in its span.
_SIGNED_THRUST = ("pos(n)^2", "neg(n)^2")


def similar_library(library: ModelStructure, dofs: Sequence[str] = DOFS
                    ) -> tuple[ModelStructure, tuple[str, ...]]:  # fmt: skip
    """A candidate library for logs with a propeller speed, written as advance-ratio similarity
    has a ship's forces: each term of degree below 2 (the constant, δ²) of the equations
    ``dofs`` replaced by its similar form (``similar_term``: n|n|, n⁺²δ²), left out where the
    equation already holds that form; and the terms so replaced. A library without n is
    returned as it is. ``dofs=("v", "r")`` writes the side force's constant alone
    (``SIDE_FORCE``).

    Fitted at several propeller speeds, a constant force stays the same at every rps while the
    thrust and the rudder's race go as n²: the Esso Osaka's pairs of zig-zag files at 10–16.7 rps
    kept a constant in every candidate, and 8 of their 28 models at two rps went astern, the
    other way or diverged with the rudder held at 8–16.7 rps (``benchmarks/study_esso_rps_range.py``).
    """
    if "n" not in library.inputs:
        return library, ()
    terms: dict[str, tuple[str, ...]] = {}
    replaced: set[str] = set()
    for dof, names in library.terms.items():
        out: list[str] = []
        for term in names:
            new, k = similar_term(term)
            if k == 0 or dof not in dofs:
                out.append(term)
                continue
            replaced.add(term)
            spanned = new == parse_term("|n|*n").text and all(t in names for t in _SIGNED_THRUST)
            if new not in names and new not in out and not spanned:
                out.append(new)
        terms[dof] = tuple(out)
    return ModelStructure(library.name, terms), tuple(sorted(replaced))
