"""``shipid rescale``: a model file carried to another scale by Froude similarity."""

from __future__ import annotations

import math

from shipid.cli.as_written import _print_prime
from shipid.cli.printing import _json_text
from shipid.errors import ShipidError


def cmd_rescale(args) -> int:
    """``shipid rescale``: a model file carried to a similar ship of another length (Froude)."""
    from shipid.data.particulars import Particulars
    from shipid.outputs import atomic_write_text, check_outputs
    from shipid.reporting.modelfile import load_document, model_from_document, rescaled_document

    check_outputs({"-o": (args.output, "json")}, [args.model])
    doc = load_document(args.model)
    length = Particulars.from_mapping(doc["particulars"]).length if doc.get("particulars") else None
    if (args.factor is None) == (args.length is None):
        raise ShipidError("give the scale factor --factor F (new length / old) or the new --length")
    factor = args.factor
    if args.length is not None:
        if length is None:
            raise ShipidError(f"{args.model}: --length needs the model's particulars (its length); "
                              "give --factor instead")  # fmt: skip
        factor = args.length / length
    out = rescaled_document(doc, factor, args.rho, args.model)
    model = model_from_document(out, args.output)
    k = math.sqrt(factor)
    what = f"{length:g} m → {length * factor:g} m" if length else f"× {factor:g} in length"
    print(f"Froude scaling {what}: speeds × {k:.4g}, times × {k:.4g}, rates ÷ {k:.4g}")
    speed = ((out.get("identification") or {}).get("preprocessing") or {}).get("approach_speed")
    if speed:
        print(f"approach speed {speed:.4g} m/s")
    print(model.equations())
    _print_prime(out.get("prime"))
    atomic_write_text(args.output, _json_text(out))
    print(f"model written to {args.output}")
    return 0
