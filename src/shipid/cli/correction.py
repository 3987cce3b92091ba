"""``shipid correct``: a reference ship's model kept whole, an LS-SVM correction fitted to logs
of the same ship; the corrected ship written to a file the commands run as a reference ship."""

from __future__ import annotations

from shipid.cli.notes import _reference_speed_notes
from shipid.cli.printing import _json_text, _warn
from shipid.cli.reading import _read_files, _training_logs
from shipid.cli.targets import VESSEL_NAMES


def cmd_correct(args) -> int:
    """``shipid correct VESSEL LOG... -o SHIP.json``."""
    from shipid.errors import ShipidError
    from shipid.identification.correction import correction_document, identify_correction
    from shipid.outputs import atomic_write_text, check_outputs
    from shipid.vessels import get_vessel
    from shipid.vessels.mmg_file import FORMAT as MMG_FORMAT
    from shipid.vessels.mmg_file import mmg_vessel, read_document

    given = [] if args.reference in VESSEL_NAMES else [args.reference]
    check_outputs({"-o": (args.output, "json")}, [*given, *args.logs, *_read_files(args)])
    if not given:
        reference, stored = get_vessel(args.reference), args.reference
    else:
        from pathlib import Path

        mmg = read_document(args.reference) if Path(args.reference).is_file() else None
        if not (isinstance(mmg, dict) and mmg.get("format") == MMG_FORMAT):
            raise ShipidError(f"{args.reference}: neither a reference ship "
                              f"({', '.join(VESSEL_NAMES)}) nor an MMG model file "
                              "(format: shipid-mmg, shipid.vessels.mmg_file)")  # fmt: skip
        # Kept whole in the corrected ship's file: it needs no other to load.
        reference, stored = mmg_vessel(mmg, args.reference), {"mmg": mmg}
    logs = _training_logs(args)
    names = [str(p) for p in args.logs]
    for note in _reference_speed_notes(reference, logs, names):
        _warn(note)
    model = args.model
    if model is None:
        from shipid.identification.correction import default_structure

        model = default_structure(logs, reference)
        print(f"correction's structure: {model}" + (" (the logs measure the relative wind, which "
              "the reference does not model)" if model.endswith("+wind") else ""))  # fmt: skip
    fit = identify_correction(logs, reference, model, args.gamma, args.filter, names,
                              args.bootstrap, args.seed)  # fmt: skip
    if fit.gamma_scores:
        print("γ by the free runs of held-out logs: " + ", ".join(
            f"{g:g} {s:.4g}" for g, s in fit.gamma_scores.items()) + f" → {fit.gamma:g}")
    print(f"{reference.name} kept whole, corrected by an LS-SVM fit (γ {fit.gamma:g}) to what "
          f"it misses of {len(logs)} log(s):")  # fmt: skip
    print(fit.correction.equations())
    shares = ", ".join(f"{d}̇ {100 * x:.0f} %" for d, x in fit.explained.items())
    print(f"the reference's share of the increments' variance on the logs: {shares}")
    beyond = _beyond_the_logs(reference, fit.vessel, fit.replicate_vessels())
    doc = correction_document(fit, stored, names, args.filter)
    doc["beyond_the_logs"] = beyond
    atomic_write_text(args.output, _json_text(doc))
    print(f"corrected ship written to {args.output} (validate, simulate, manoeuvre, criteria, "
          "linearise, autopilot and follow run it)")  # fmt: skip
    return 0


# What the correction does where the logs do not reach: the reference's and the corrected ship's
# held 35° turns and 10°/10° zig-zags to either side, from the reference's own approach (at
# the largest rudder its gear allows where that is less: the tanker's is 10°).
BEYOND = (("turning", "tactical_diameter"), ("turning", "steady_speed"),
          ("turning", "steady_yaw_rate"), ("zigzag", "first_overshoot_deg"),
          ("zigzag", "second_overshoot_deg"))  # fmt: skip


def _standard_rudders(ship) -> tuple[float, float]:
    """The held turn's and the zig-zag's rudder [deg]: 35° and 10°, or the largest the ship's
    steering gear allows where that is less."""
    return ship.steering.capped_deg(35.0), ship.steering.capped_deg(10.0)


def _standard(ship, side: str) -> dict:
    """The held turn and the 10°/10° zig-zag of ``ship`` to ``side`` (``_standard_rudders``)."""
    from shipid.cli.targets import _ship_approach
    from shipid.trials.manoeuvres import turning_circle, zigzag

    # A propeller that follows the runs' rate turns at its trim for the approach.
    rps = _ship_approach(ship, None, None)[1]
    turn, zig = _standard_rudders(ship)
    return {"turning": turning_circle(ship, turn, side=side, rps=rps),
            "zigzag": zigzag(ship, zig, zig, first=side, rps=rps)}  # fmt: skip


def _beyond_the_logs(reference, corrected, replicates=()) -> list[dict]:
    """Print the standard manoeuvres of both ships side by side (with the 95 % interval over
    the bootstrap ``replicates`` where there are some), warn where the corrected ship's turn
    diverges, never comes round, or turns the other way; the rows, for the file."""
    from shipid.cli.printing import _pd
    from shipid.identification.uncertainty import interval

    rows = []
    turn_deg, zig_deg = _standard_rudders(corrected)
    labels = {"turning": f"{turn_deg:g}° turn", "zigzag": f"{zig_deg:g}°/{zig_deg:g}°"}
    for side in ("starboard", "port"):
        runs = {label: _standard(ship, side)
                for label, ship in (("reference", reference), ("corrected", corrected))}
        # Every reference ship corrected runs compiled: the replicates at the point's step.
        drawn = [_standard(ship, side) for ship in replicates]
        turn = runs["corrected"]["turning"]
        if turn.diverged or turn.indices.get("tactical_diameter") is None:
            _warn(f"the corrected ship's {labels['turning']} to {side} "
                  + ("diverges" if turn.diverged else "does not complete 180°")
                  + ": the correction does not hold beyond its logs; a smaller --gamma keeps it "
                  "nearer the reference")  # fmt: skip
        elif turn.indices.get("turn_direction") not in (None, side):
            _warn(f"the corrected ship turns to {turn.indices['turn_direction']} with its "
                  f"{turn_deg:g}° rudder to {side}")  # fmt: skip
        for kind, key in BEYOND:
            row = {"manoeuvre": f"{labels[kind]} {side}",
                   "index": key, **{label: runs[label][kind].indices.get(key) for label in runs}}
            if drawn:
                values = [d[kind].indices.get(key) for d in drawn]
                lo, hi = interval([float("nan") if v is None else v for v in values])
                row["95 % interval"] = f"[{lo:.4g}, {hi:.4g}]"
            rows.append(row)
    print("Beyond the logs (the standard manoeuvres from the reference's approach"
          + (f"; intervals over {len(replicates)} bootstrap replicates of the correction"
             if replicates else "") + "):")  # fmt: skip
    print(_pd().DataFrame(rows).to_markdown(index=False, floatfmt=".4g"))
    return rows
