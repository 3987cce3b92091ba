"""A model's terms written in other forms, as one: each term of each equation to its new form
and its coefficient times a ratio. What advance-ratio similarity (``shipid.dynamics.similarity``:
δ → n⁺²δ, the coefficient over n₀²) and the ahead forms (``shipid.dynamics.astern``: u·v →
|u|·v, ratio 1) write; ``shipid.reporting.modelfile`` renames a model file's every record so."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.dynamics.terms import parse_term


@dataclass(frozen=True)
class TermRenaming:
    """``renamed``: {dof: {fitted term: (new term, ratio of coefficients)}}, a term left as it is
    mapped to itself with ratio 1."""

    renamed: Mapping[str, Mapping[str, tuple[str, float]]]

    @property
    def changes(self) -> bool:
        """Whether any term is written in another form."""
        return any(new != old for eq in self.renamed.values() for old, (new, _) in eq.items())

    def structure(self, structure: ModelStructure, name: str | None = None) -> ModelStructure:
        """The structure with its terms renamed (named ``name``, by default as it was)."""
        terms = {d: tuple(self.renamed[d][t][0] for t in ts) for d, ts in structure.terms.items()}
        return ModelStructure(structure.name if name is None else name, terms)

    def coefficients(self, coefficients: Mapping[str, Mapping[str, float]]) -> dict:
        """{dof: {new term: coefficient}} of fitted ones."""
        return {d: {self.renamed[d][t][0]: float(c) * self.renamed[d][t][1]
                    for t, c in values.items()} for d, values in coefficients.items()}  # fmt: skip

    def term(self, dof: str, term: str) -> tuple[str, float]:
        """(new term, ratio) of a fitted term of equation ``dof``."""
        return self.renamed[dof][parse_term(term).text]

    def describe(self) -> str:
        """Which terms were written in which form, in words."""
        return ", ".join(sorted({f"{parse_term(old).display() or '1'} → "
                                 f"{parse_term(new).display()}"
                                 for eq in self.renamed.values()
                                 for old, (new, _) in eq.items() if new != old}))  # fmt: skip


def renamed_terms(structure: ModelStructure, rename: Callable[[str, str], tuple[str, float]]
                  ) -> dict[str, dict[str, tuple[str, float]]]:  # fmt: skip
    """{dof: {term: (new term, ratio)}} of ``structure`` by ``rename(dof, term)``. A term whose
    new form its equation already has (or an earlier term took) keeps its own, ratio 1: the
    structure's own term carries that form, and two terms made one would lose the fit's
    standard errors and replicates."""
    out: dict[str, dict[str, tuple[str, float]]] = {}
    for dof, terms in structure.terms.items():
        taken = set(terms)
        eq: dict[str, tuple[str, float]] = {}
        for t in terms:
            new, ratio = rename(dof, t)
            if new != t and new in taken:
                new, ratio = t, 1.0
            taken.add(new)
            eq[t] = (new, float(ratio))
        out[dof] = eq
    return out


def renamed_model(model: ManoeuvringModel, found: TermRenaming, name: str | None = None,
                  similar_at_rps: float | None = None) -> ManoeuvringModel:  # fmt: skip
    """``model`` with its terms and coefficients renamed by ``found`` (the structure named
    ``name``, by default as it was; anchored at ``similar_at_rps``, by default where ``model``
    was)."""
    return ManoeuvringModel(found.structure(model.structure, name),
                            found.coefficients(model.coefficients), name=model.name,
                            similar_at_rps=model.similar_at_rps if similar_at_rps is None
                            else similar_at_rps)  # fmt: skip
