"""The model as ``identify`` and ``select`` write it: carried to every propeller speed from the
one its logs run at, in the forms that carry it astern, its prime coefficients printed, and its
bootstrap replicates checked in that form."""

from __future__ import annotations

import json

from shipid.cli.printing import _json_text, _pd, _term_display


def _replicates_checked(ensemble, report: dict, model, as_written, speed, rps, curvature,
                        given: tuple = (None, None)) -> dict:  # fmt: skip
    """``members_plausibility`` of the bootstrap ``ensemble``: each replicate, as the model file
    will have it, through the checks that rule a model out (from the approach ``model``'s were:
    ``speed``, ``rps``, or the ``given`` speed and rps), counting those it fails where ``model``
    (its check ``report``) does not, by reason."""
    from shipid.identification.plausibility import disqualifying_checks, plausibility_at_approach
    from shipid.identification.uncertainty import members_plausibility

    passed = disqualifying_checks(report, model)

    def reasons(member) -> list[str]:
        written = as_written(member)
        found = disqualifying_checks(plausibility_at_approach(
            written, speed, rps, *given, curvature=curvature)[0], written)  # fmt: skip
        return [note for check, (severity, note) in found.items()
                if severity > passed.get(check, (0, ""))[0]]  # fmt: skip

    return members_plausibility(ensemble, reasons)


def _report_replicates(ensemble, record: dict, ident) -> None:
    """Keep ``record`` (``_replicates_checked``) with ``ensemble``, print it, and warn where
    many replicates fail the checks."""
    from shipid.identification.uncertainty import implausible_members_note

    ensemble.plausibility = record
    print(f"plausibility of {record['checked']} of the {ensemble.replicates} replicates: "
          f"{record['implausible']} fail checks the model passes" + "".join(
              f"; {why}: {count}" for why, count in list(record["reasons"].items())[:3]))
    weak = implausible_members_note(record, ensemble.members_label)
    if weak:
        ident.warnings.append(f"bootstrap: {weak}")


def _as_written(model, rps: float | None, ahead=None):
    """``model`` as the model file will have it: carried to every propeller speed from ``rps``
    (None: as it is), then in the forms ``ahead`` (``shipid.dynamics.astern.AsternForms``;
    None: none); ``model`` itself where nothing changes."""
    from shipid.dynamics.similarity import rps_similar, similarity_map

    if rps is not None and similarity_map(model.structure, rps).changes:
        model = rps_similar(model, rps)
    return ahead.written(model) if ahead else model


def _written_text(text: str, rps: float | None, ahead, path) -> tuple[str, dict | None]:
    """The model file ``text`` as it is written (``_rps_similar``, then ``_ahead_forms``), and
    its prime record where either changed it (else None)."""
    prime = None
    for step in (lambda t: _rps_similar(t, rps, path), lambda t: _ahead_forms(t, ahead, path)):
        doc = step(text)
        if doc is not None:
            text, prime = _json_text(doc), doc.get("prime")
    return text, prime


def _ahead_forms(text: str, ahead, path) -> dict | None:
    """The model file ``text`` with its terms in the forms ``ahead``
    (``shipid.dynamics.astern.AsternForms``), said on the command line; None where there are
    none, or no term changes."""
    from shipid.reporting.modelfile import ahead_forms_document, model_from_document

    if not ahead:
        return None
    fitted = json.loads(text)
    doc = ahead_forms_document(fitted, path, ahead)
    if doc is not None:
        record = doc["identification"]["ahead_forms"]
        ratio = record.get("astern_thrust_ratio")
        model = model_from_document(fitted, path)
        hull = ahead.for_model(model).parts(model.structure)[0]
        pushes = (f"its propeller pushes astern {ratio:g} times what it pushes ahead"
                  if ratio is not None else "")  # fmt: skip
        if hull:
            never = "the logs never do" + (", nor reverse the propeller," if pushes else ",")
            does = ("its damping damps, its rudder reverses astern and " + pushes if pushes
                    else "its damping damps and its rudder reverses astern")  # fmt: skip
            keeps = ("--no-ahead-forms keeps the fit's hull and rudder terms, --astern-thrust "
                     "none its thrust" if pushes else "--no-ahead-forms keeps the fit's")
        else:
            never, does, keeps = ("the logs never reverse the propeller,", pushes,
                                  "--astern-thrust RATIO|none to set or keep it")  # fmt: skip
        print(f"going astern: {never} and cannot tell these forms from the fitted ones; "
              f"written as the physics carries them astern ({record['terms']}): the same fit "
              f"ahead, {does} ({keeps})")  # fmt: skip
    return doc


def _rps_similar(text: str, rps: float | None, path) -> dict | None:
    """The model file ``text`` with its model carried to every propeller speed from the one its
    logs run at (``_one_rps``), said on the command line; None where there is none, or no term
    changes. The Esso Osaka's one-file models predicted the held-out logs at another rps with a
    yaw rate error of 0.37 of their spread instead of 0.48 (median of 70;
    ``benchmarks/study_esso_single_logs.py``)."""
    from shipid.reporting.modelfile import rps_similar_document

    if rps is None:
        return None
    doc = rps_similar_document(json.loads(text), rps, path)
    if doc is not None:
        print(f"propeller speed: the logs run at one {rps:.4g} rps, which cannot show how the "
              f"forces depend on it; each term written to scale with it as advance-ratio "
              f"similarity has it ({doc['identification']['rps_similarity']['terms']}): at "
              f"{rps:.4g} rps the model is the fit, at other rps its forces scale with n² and "
              "its manoeuvres start from the logs' approach speed times n/n₀, where it holds "
              "that speed (--no-rps-similarity keeps the fit's terms)")  # fmt: skip
    return doc


def _print_prime(record: dict | None) -> None:
    """The prime (non-dimensional) coefficients next to the dimensional ones."""
    if not record:
        return
    print(f"\nPrime form (L = {record['length']:g} m, U = {record['speed']:.4g} m/s, the "
          f"{record['speed_basis']}; ρ = {record['rho']:g} kg/m³; u̇′ = u̇ L/U², ṙ′ = ṙ L²/U²):")
    rows = [{"equation": f"{dof}̇′", "term": _term_display(t), "prime": c}
            for dof, terms in record["coefficients"].items() for t, c in terms.items()]
    print(_pd().DataFrame(rows).to_markdown(index=False, floatfmt=".5g"))
