"""``shipid correct``: a reference ship's model kept whole, an LS-SVM correction fitted to logs
of the same ship; the corrected ship written to a file the commands run as a reference ship."""

from __future__ import annotations

from shipid.cli.common import _json_text, _read_files, _training_logs, _warn


def cmd_correct(args) -> int:
    """``shipid correct VESSEL LOG... -o SHIP.json``."""
    from shipid.cli.evaluation import _reference_speed_notes
    from shipid.identification.correction import correction_document, identify_correction
    from shipid.outputs import atomic_write_text, check_outputs
    from shipid.vessels import get_vessel

    check_outputs({"-o": (args.output, "json")}, [*args.logs, *_read_files(args)])
    reference = get_vessel(args.reference)
    logs = _training_logs(args)
    names = [str(p) for p in args.logs]
    for note in _reference_speed_notes(reference, logs, names):
        _warn(note)
    fit = identify_correction(logs, reference, args.model, args.gamma, args.filter, names)
    if fit.gamma_scores:
        print("γ by the free runs of held-out logs: " + ", ".join(
            f"{g:g} {s:.4g}" for g, s in fit.gamma_scores.items()) + f" → {fit.gamma:g}")
    print(f"{args.reference} kept whole, corrected by an LS-SVM fit (γ {fit.gamma:g}) to what "
          f"it misses of {len(logs)} log(s):")  # fmt: skip
    print(fit.correction.equations())
    shares = ", ".join(f"{d}̇ {100 * x:.0f} %" for d, x in fit.explained.items())
    print(f"the reference's share of the increments' variance on the logs: {shares}")
    atomic_write_text(args.output, _json_text(correction_document(
        fit, args.reference, names, args.filter)))  # fmt: skip
    print(f"corrected ship written to {args.output} (validate, simulate, manoeuvre, criteria, "
          "linearise, autopilot and follow run it)")  # fmt: skip
    return 0
