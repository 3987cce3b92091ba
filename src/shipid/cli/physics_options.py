"""The physics a fit is given on the command line: --model and --drop as its structure,
--crossflow and --rudder-normal as its edit, --prior (Clarke's formulas, a reference ship, a model
file), --constraints, --bound and --steady-speed as ``PhysicsOptions``, and --gammas."""

from __future__ import annotations

import math
from pathlib import Path

from shipid.cli.printing import _warn
from shipid.cli.reading import _approach, _constant_rps, _logs_side, _one_rps
from shipid.cli.targets import _reference_ship, _vessel_names
from shipid.errors import ShipidError


def _structure_edit(args, logs):
    """--drop, --crossflow and --rudder-normal as one ``StructureEdit`` (the length and the
    rudder's inflow from the particulars)."""
    from shipid.data.particulars import logs_particulars
    from shipid.dynamics.model import StructureEdit

    length = rudder = None
    wanted = getattr(args, "crossflow", False) or getattr(args, "rudder_normal", False)
    found = logs_particulars(logs) if wanted else None  # --particulars among them
    if getattr(args, "crossflow", False):
        if found is None:
            raise ShipidError("--crossflow needs the hull's length: give --particulars FILE "
                              "(length, or Lpp)")  # fmt: skip
        length = found.length
    if getattr(args, "rudder_normal", False):
        from shipid.dynamics.rudder import RudderInflow

        if found is None:
            raise ShipidError("--rudder-normal needs the ship's particulars: give --particulars "
                              "FILE (length, propeller_diameter, block_coefficient; "
                              "rudder_height where known)")  # fmt: skip
        side = _logs_side(logs)
        if side is None:
            raise ShipidError("--rudder-normal needs the logs' rudder convention: give "
                              "--rudder-positive port|starboard")  # fmt: skip
        from shipid.data.log import log_name

        bare = [log_name(log) for log in logs if "n" not in log.columns]
        if bare:
            raise ShipidError(f"--rudder-normal needs the propeller speed: {', '.join(bare)} "
                              "has no column n [rps]")  # fmt: skip
        rudder = RudderInflow.from_particulars(found, side)
    return StructureEdit(_parse_drop(getattr(args, "drop", None)) or None, length,
                         compare_crossflow=getattr(args, "crossflow", None) is not False,
                         rudder=rudder)  # fmt: skip


BOUND_PATTERN = r"^\s*([uvr])\s*:\s*(.+?)\s*(<=|>=)\s*(\S+)\s*$"


def _parse_bounds(specs) -> dict[str, dict[str, tuple[float, float]]]:
    """--bound 'r: u*r <= 0' (repeatable) as {dof: {term: (lower, upper)}}."""
    import re

    out: dict[str, dict[str, tuple[float, float]]] = {}
    for spec in specs or []:
        m = re.match(BOUND_PATTERN, spec)
        if not m:
            raise ShipidError(f"--bound expects 'DOF: TERM <= X' or 'DOF: TERM >= X' (DOF u, v "
                              f"or r), got {spec!r}")  # fmt: skip
        dof, term, op, value = m.groups()
        try:
            x = float(value)
        except ValueError:
            raise ShipidError(f"--bound {spec!r}: {value!r} is not a number") from None
        if not math.isfinite(x):
            raise ShipidError(f"--bound {spec!r}: the bound must be finite")
        lo, hi = out.setdefault(dof, {}).get(term, (-math.inf, math.inf))
        out[dof][term] = (lo, min(hi, x)) if op == "<=" else (max(lo, x), hi)
    return out


def _physics(args, logs, structure, searched: bool = False, chosen: bool = False):
    """PhysicsOptions of --prior, --constraints, --bound (None when none is given);
    ``searched``: ``structure`` is a library terms are chosen from, not the structure fitted;
    ``chosen``: the structures fitted are chosen, not given, so one without a bounded term holds
    it at 0 (``PhysicsOptions.bounds_where_present``) instead of being refused."""
    from shipid.identification.physics import (
        PhysicsOptions,
        parse_constraints,
        parse_steady_speeds,
        similar_steady_speeds,
    )

    flags = parse_constraints(args.constraints)
    steady = parse_steady_speeds(getattr(args, "steady_speed", None))
    if steady:
        flags["steady_speed"] = True
        # Logs at one rps: the model file carries the fit to every rps by similarity (speed ∝
        # rps), so a speed given at another rps is imposed where similarity puts it at theirs.
        steady = similar_steady_speeds(steady, _one_rps(logs, args))
    bounds = _parse_bounds(args.bound)
    prior, source = None, ""
    name = args.prior
    if name and not Path(name).exists() and name.lower() in ("clarke", *_vessel_names()):
        name = name.lower()  # --prior KVLCC2, Clarke: a name, not a file
    if name and name != "clarke" and name not in _vessel_names() and not Path(name).exists():
        raise ShipidError(f"--prior {name}: no such model file, and not 'clarke' nor a reference "
                          f"ship ({', '.join(_vessel_names())})")  # fmt: skip
    if name == "clarke":
        from shipid.data.particulars import logs_particulars
        from shipid.identification.priors import clarke_prior

        # --particulars is among them (``_training_logs``): the file is not read again.
        part = logs_particulars(logs)
        if part is None:
            raise ShipidError("--prior clarke needs the ship's particulars (--particulars FILE)")
        speed = _approach(logs[0], "u")
        prior = clarke_prior(part, structure, speed or 0.0, _logs_side(logs))
    elif name and name in _vessel_names():
        prior, source = _reference_ship_prior(name, logs, structure, searched)
    elif args.prior and _reference_ship(args.prior) is not None:  # an MMG file, a corrected ship
        prior, source = _reference_ship_prior(args.prior, logs, structure, searched)
    elif args.prior:
        from shipid.identification.priors import prior_from_model, prior_in_forms

        model, source = _model_file_prior(args.prior, logs)
        prior = prior_in_forms(prior_from_model(model), structure)
        rps = _constant_rps(logs)
        if rps is not None:
            from shipid.identification.priors import prior_at_rps

            prior = prior_at_rps(prior, structure, rps)
    options = PhysicsOptions(prior=prior, bounds=bounds or None, approach=tuple(steady) or None,
                             prior_source=source, bounds_where_present=chosen,
                             **flags)  # fmt: skip
    return options if options.active else None


def _reference_ship_prior(name: str, logs, structure, searched: bool) -> tuple[dict, str]:
    """``--prior SHIP``: the reference ship ``name``'s prior for ``structure`` at the logs'
    length and rudder convention (``priors.reference_prior``), and where it comes from."""
    from shipid.data.particulars import logs_particulars

    if searched:
        # Fitted on the reference jointly, a library's terms would share its forces among
        # them at random: the prior is for the structure fitted.
        raise ShipidError(f"--prior {name} is fitted in the structure it is for: give "
                          "the structure with --model NAME (identify; not select, nor "
                          "identify's own choice of structure)")
    from shipid.identification.priors import reference_prior

    part = logs_particulars(logs)
    if part is None or part.length is None:
        raise ShipidError(f"--prior {name} needs the ship's length (--particulars FILE)")
    side = _logs_side(logs)
    if side is None:
        _warn(f"--prior {name}: the logs do not say which way a positive rudder turns "
              "the ship (rudder_positive), so the rudder's terms get no prior (the "
              "reference's sign could be the opposite of the logs')")  # fmt: skip
    prior = reference_prior(name, structure, part.length, side)
    source = (f"the reference ship {name}'s 10°/10° and 20°/20° zig-zags and 35° turns "
              f"fitted in this structure, carried to L = {part.length:g} m at equal Froude "
              "number: " + "; ".join(f"{d}: {', '.join(terms)}" for d, terms in prior.items()))
    from shipid.dynamics.model import HULL_DRAG
    from shipid.dynamics.terms import parse_term

    split = [t for t in map(parse_term, HULL_DRAG)
             if any(t.text in structure.terms.get(d, ()) for d in ("v", "r"))]  # fmt: skip
    if split:

        _warn(f"--prior {name}: the structure splits the hull's nonlinear damping over "
              f"{', '.join(t.display() for t in split)}, which share it "
              "differently on every hull: the reference's share carries over, not its hull "
              "(the Esso Osaka's one-file fits from the KVLCC2 at γ = 1: 35° turns 79 % off "
              "in the median against 35 % without it); --crossflow makes it one term, the "
              "cross-flow drag (10 % against 11 %: benchmarks/study_reference_prior.py)")
    return prior, source


def _model_file_prior(path: str, logs) -> tuple:
    """The model of the file ``path`` as a prior for ``logs``: carried to their ship's length at
    equal Froude number where both lengths are known and differ (a sister ship, a basin model),
    and to their rudder convention where both are known and differ (as a log is converted); and
    where it comes from, in words."""
    from shipid.data.particulars import Particulars, logs_particulars
    from shipid.dynamics.prime import froude_scaled
    from shipid.identification.priors import mirrored_rudder
    from shipid.reporting.modelfile import load_document, model_from_document

    doc = load_document(path)
    model = model_from_document(doc, path)
    said = []
    theirs = Particulars.from_mapping(doc["particulars"], f"{path}: particulars").length \
        if doc.get("particulars") else None  # fmt: skip
    part = logs_particulars(logs)
    ours = part.length if part is not None else None
    if theirs and ours and not math.isclose(theirs, ours, rel_tol=1e-3):
        model = froude_scaled(model, ours / theirs)
        said.append(f"carried from L = {theirs:g} m to the logs' {ours:g} m at equal Froude "
                    "number")  # fmt: skip
    elif bool(theirs) != bool(ours):
        whose = "logs'" if theirs else "model file's"
        _warn(f"--prior {path}: the {whose} ship length is not "
              "known, so the prior's coefficients are taken at the size they have (give "
              "--particulars)")  # fmt: skip
    prep = ((doc.get("identification") or {}).get("preprocessing") or {})
    side_then = prep.get("rudder_positive") if isinstance(prep, dict) else None
    side_now = _logs_side(logs)
    if side_then in ("port", "starboard") and side_now and side_then != side_now:
        model, dropped = mirrored_rudder(model)
        said.append(f"its rudder from the {side_then}-positive convention it was fitted in to "
                    f"the logs' {side_now}-positive one" + (
                        f" (no prior on {', '.join(dropped)}, one side of the rudder)"
                        if dropped else ""))  # fmt: skip
    return model, f"the model file {path}" + (f", {'; '.join(said)}" if said else "")


def _parse_drop(spec: str | None) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for item in (spec or "").split(","):
        if not item.strip():
            continue
        if ":" not in item:
            raise ShipidError(f"--drop expects dof:term pairs like u:r^2, got {item!r}")
        dof, term = (s.strip() for s in item.split(":", 1))
        out.setdefault(dof, []).append(term)
    return out


def _structure(args):
    """The structure of --model without the --drop terms."""
    from shipid.dynamics.model import get_structure

    try:
        structure = get_structure(args.model)
        drop = _parse_drop(args.drop)
        return structure.without(drop) if drop else structure
    except ValueError as exc:
        raise ShipidError(str(exc)) from None


def _parse_gammas(text: str | None) -> tuple[float, ...] | None:
    if not text:
        return None
    try:
        gammas = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise ShipidError(f"--gammas expects numbers separated by commas, got {text!r}") from None
    if not gammas or not all(math.isfinite(g) and g > 0 for g in gammas):
        raise ShipidError(f"--gammas must be numbers > 0, got {text!r}")
    return gammas
