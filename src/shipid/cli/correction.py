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
    _beyond_the_logs(reference, fit.vessel)
    atomic_write_text(args.output, _json_text(correction_document(
        fit, args.reference, names, args.filter)))  # fmt: skip
    print(f"corrected ship written to {args.output} (validate, simulate, manoeuvre, criteria, "
          "linearise, autopilot and follow run it)")  # fmt: skip
    return 0


# What the correction does where the logs do not reach: the reference's and the corrected ship's
# held 35° turns and 10°/10° zig-zags to either side, from the reference's own approach.
BEYOND = (("turning", "tactical_diameter"), ("turning", "steady_speed"),
          ("turning", "steady_yaw_rate"), ("zigzag", "first_overshoot_deg"),
          ("zigzag", "second_overshoot_deg"))  # fmt: skip


def _beyond_the_logs(reference, corrected) -> None:
    """Print the standard manoeuvres of both ships side by side, and warn where the corrected
    ship's turn diverges, never settles into one, or turns the other way."""
    from shipid.cli.common import _pd
    from shipid.trials.manoeuvres import turning_circle, zigzag

    rows = []
    for side in ("starboard", "port"):
        runs = {}
        for label, ship in (("reference", reference), ("corrected", corrected)):
            runs[label] = {"turning": turning_circle(ship, 35.0, side=side),
                           "zigzag": zigzag(ship, 10.0, 10.0, first=side)}  # fmt: skip
        turn = runs["corrected"]["turning"]
        if turn.diverged or turn.indices.get("tactical_diameter") is None:
            _warn(f"the corrected ship's 35° turn to {side} "
                  + ("diverges" if turn.diverged else "does not complete 180°")
                  + ": the correction does not hold beyond its logs; a smaller --gamma keeps it "
                  "nearer the reference")  # fmt: skip
        elif turn.indices.get("turn_direction") not in (None, side):
            _warn(f"the corrected ship turns to {turn.indices['turn_direction']} with its 35° "
                  f"rudder to {side}")  # fmt: skip
        for kind, key in BEYOND:
            rows.append({"manoeuvre": f"{'35° turn' if kind == 'turning' else '10°/10°'} "
                                      f"{side}", "index": key,
                         **{label: runs[label][kind].indices.get(key) for label in runs}})
    print("Beyond the logs (the standard manoeuvres from the reference's approach):")
    print(_pd().DataFrame(rows).to_markdown(index=False, floatfmt=".4g"))
