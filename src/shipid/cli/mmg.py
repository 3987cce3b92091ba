"""``shipid mmg``: an MMG model file of a ship without captive tests, from a similar ship's."""

from __future__ import annotations

from shipid.cli.printing import _warn
from shipid.cli.targets import VESSEL_NAMES


def cmd_mmg(args) -> int:
    """``shipid mmg SOURCE --particulars FILE -o SHIP.yml``: the source's prime coefficients
    (the built-in KVLCC2, or an MMG file) with this ship's particulars."""
    from pathlib import Path

    from shipid.data.particulars import read_particulars
    from shipid.errors import ShipidError
    from shipid.outputs import atomic_write_text, check_outputs
    from shipid.vessels.mmg_file import FOLLOW, coefficients, mmg_vessel, read_document, sister_ship

    inputs = [args.particulars] + ([] if args.source in VESSEL_NAMES else [args.source])
    check_outputs({"-o": (args.output, "yaml or json")}, inputs)
    if args.source in VESSEL_NAMES:
        from shipid.vessels import get_vessel

        dyn = get_vessel(args.source).dynamics
        if not hasattr(dyn, "packed"):
            mmg_names = [n for n in VESSEL_NAMES if hasattr(get_vessel(n).dynamics, "packed")]
            raise ShipidError(f"{args.source} is not an MMG model (the MMG ones: "
                              f"{', '.join(mmg_names)}, or an MMG file)")  # fmt: skip
        source = dyn.c
    elif Path(args.source).is_file():
        source = coefficients(read_document(args.source), args.source)
    else:
        raise ShipidError(f"{args.source}: neither a built-in MMG ship nor an MMG model file")
    rps = args.rps
    if rps is not None and rps != FOLLOW:
        try:
            rps = float(rps)
        except ValueError:
            raise ShipidError(f"--rps must be a number or '{FOLLOW}', got {rps!r}") from None
    particulars = read_particulars(args.particulars)
    name = args.name or Path(args.output).stem
    doc, notes = sister_ship(source, particulars, name, args.speed, rps, args.rudder_rate)
    ship = mmg_vessel(doc, f"the MMG model of {name}")  # trims its propeller: checks it holds
    if Path(args.output).suffix.lower() == ".json":
        from shipid.cli.printing import _json_text

        text = _json_text(doc)
    else:
        import yaml

        text = (f"# {name}: the prime coefficients of {source.get('name')} with the particulars "
                f"of {args.particulars} (shipid mmg)\n" + yaml.safe_dump(doc, sort_keys=False))
    atomic_write_text(args.output, text)
    dyn = ship.dynamics
    print(f"{name}: L {doc['length']:g} m, approach {doc['approach_speed']:.4g} m/s at "
          f"{dyn.n_prop:.4g} rps" + (" (its propeller follows each log's rate and --rps)"
                                     if dyn.follow_rps else ""))  # fmt: skip
    print(f"MMG model written to {args.output} (a reference ship for validate, manoeuvre, "
          "criteria, correct, ...)")  # fmt: skip
    for note in notes:
        _warn(note)
    return 0
