"""What the ``shipid`` commands share: reading logs with the log options, physics and bound options,
the model or reference ship a command runs on, its approach and steering machine, and notes."""

from __future__ import annotations

import json
import math
import sys
import warnings
from pathlib import Path

from shipid.errors import ShipidError, ShipidWarning

VESSEL_NAMES = ("scale-ship", "mariner", "kvlcc2", "cybership2", "tanker")
LINEAR_ESTIMATORS = ("lssvm", "ols", "ridge", "lasso", "svr")
KINDS = ("zigzag", "turning", "pull-out", "other")  # trials.trial.KINDS, without its imports


# ---------------------------------------------------------------------------- shared options
# The readers of shipid.data.formats (kept here so that --help and --version import no pandas;
# a test checks the two agree).
FORMATS = ("canonical", "simman-marin", "simman-hsva", "osaka-frt")


def _read_options(args):
    from shipid.data.io import ReadOptions, parse_column_map
    from shipid.data.track_velocities import TrackVelocities

    return ReadOptions(fmt=args.format, columns=parse_column_map(args.columns),
                       degrees=tuple(c.strip() for c in args.degrees.split(",") if c.strip()),
                       dt=args.dt, start=args.start, end=args.end, lead=args.lead,
                       rudder_positive=args.rudder_positive, scale=args.scale,
                       fill_gaps=args.fill_gaps,
                       yaw_rate_offset=args.yaw_rate_offset,
                       velocities="track" if args.velocities_from_track else "auto",
                       track=TrackVelocities(args.track_window, args.antenna or (0.0, 0.0)))  # fmt: skip


def _read_logs(args, paths=None, cut_from_rest: bool = False) -> list:
    """The logs of ``paths`` (default: the command's) read with the log options, each given the
    particulars; with ``cut_from_rest``, cut to the trials they hold unless --start or --end is
    given (zig-zags and turns from rest to their manoeuvre, other runs before a propulsion
    dropout: ``shipid.trials.reading.read_trial_log``)."""
    from shipid.data.io import read_log
    from shipid.data.log import frozen

    options = _read_options(args)
    paths = paths or args.logs
    if cut_from_rest:
        from shipid.trials.reading import read_trial_log

        logs = [read_trial_log(p, options) for p in paths]
        _warn_cut(paths, logs, options.lead)
    else:
        logs = [read_log(p, options) for p in paths]
    _print_yaw_rate_offsets(args, paths, logs)
    particulars = _particulars(args)
    if particulars is not None:
        from shipid.data.log import dimension_apart

        from_file = particulars.to_dict()
        for path, log in zip(paths, logs, strict=True):
            apart = dimension_apart(from_file, log.attrs.get("particulars"))
            if apart:  # a file of another ship's particulars, or the log of another ship
                key, given, own = apart
                _warn(f"{path}: --particulars {args.particulars} gives a {key} of {given:g} where "
                      f"the log's own particulars give {own:g}: the file's replace them; check "
                      "that both are of this ship")  # fmt: skip
            log.attrs["particulars"] = frozen(from_file)
    from shipid.data.particulars import rudder_beyond_limit

    for path, log in zip(paths, logs, strict=True):
        said = rudder_beyond_limit(log, str(path))
        if said:
            _warn(said)
    return logs


def _warn_cut(paths, logs, lead: float, judged: bool = False) -> None:
    """Name the logs ``read_trial_log`` cut (to their manoeuvre, before a dropout); ``judged``:
    they are logs a model is judged on (validate), not fitted to."""
    from shipid.trials.reading import CUT_AT_DROPOUT, CUT_TO_MANOEUVRE

    named = [(Path(p).name, log.attrs) for p, log in zip(paths, logs, strict=True)]
    cut, ended = ([name for name, attrs in named if attrs.get(key)]
                  for key in (CUT_TO_MANOEUVRE, CUT_AT_DROPOUT))  # fmt: skip
    whole = "validates" if judged else "reads"
    if cut:
        what = ("is a zig-zag or turn that starts" if len(cut) == 1
                else "are zig-zags or turns that start")  # fmt: skip
        _warn(f"{_count_logs(cut)} {what} from rest: cut to the manoeuvre, from {lead:g} s "
              "before the rudder's execute to its end, as --start auto --end auto cuts (the "
              "Esso Osaka's nine zig-zags read whole put the default model's 35° turns 47 % and "
              f"58 % long, cut 28 % and 2 %: benchmarks/study_esso_whole_logs.py); --start 0 "
              f"{whole} {'it' if len(cut) == 1 else 'them'} whole")
    if ended:
        what = "runs" if len(ended) == 1 else "run"
        why = ("a free run driven by them there is no prediction" if judged else
               "with the Esso Osaka's random run that ends in one among its training logs, the "
               "default's 35° turns came 2–22 % off, cut 4–10 %: "
               "benchmarks/study_esso_whole_logs.py")  # fmt: skip
        _warn(f"{_count_logs(ended)} {what} into a propulsion dropout (the propeller logged "
              "stopped or astern while the ship gains headway, so the logged inputs did not "
              f"drive it): read up to it, as --end dropout cuts ({why}); --start 0 {whole} "
              f"{'it' if len(ended) == 1 else 'them'} whole")


def _count_logs(names) -> str:
    """'1 of the logs (a.csv)', '4 of the logs (a.csv, b.csv, c.csv, …)'."""
    return f"{len(names)} of the logs ({', '.join(names[:3])}{', …' if len(names) > 3 else ''})"


def _training_logs(args) -> list:
    """The logs a model is fitted to: ``_read_logs``, cut to the trials they hold (zig-zags and
    turns from rest to their manoeuvre, other runs before a propulsion dropout), refused when
    they are not of one ship at one scale (a model-scale and a full-scale run fitted together
    mix two ships' time scales; ``refuse_other_ships``), and refused where a log is given twice
    (by name or as a copy)."""
    from shipid.data.log import GIVEN_TWICE, partly_logged, refuse_copies, refuse_other_ships

    seen: dict[Path, str] = {}
    for path in args.logs:
        key = Path(path).resolve()
        if key in seen:
            raise ShipidError(f"{path} is given twice{GIVEN_TWICE}")
        seen[key] = str(path)
    logs = _read_logs(args, cut_from_rest=True)
    # Resampled finer than measured (preprocess.resample).
    upsampled = [(path, log.attrs["measured_dt"]) for path, log in zip(args.logs, logs, strict=True)
                 if "measured_dt" in log.attrs]  # fmt: skip
    refuse_other_ships(logs, [str(p) for p in args.logs])
    refuse_copies(logs, [str(p) for p in args.logs])
    for note in partly_logged(logs, [str(p) for p in args.logs]):
        _warn(note)
    for path, own in upsampled:
        _warn(f"{path}: --dt {args.dt:g} s is finer than its own sampling ({own:.3g} s): the fit "
              f"sees straight lines between its samples as measurements (their second "
              f"differences 0, so its sensor noise reads as none); fit at --dt {own:.3g} or "
              f"coarser (validate may run a model finer than its logs)")  # fmt: skip
    from shipid.data.particulars import logs_particulars

    particulars = logs_particulars(logs)
    if particulars is not None and particulars.rudder_limit is not None:
        # The checks of every fit this command makes hold the gear's largest rudder: set in
        # the command's own context (``shipid.cli.main`` runs each in a copy of its caller's).
        from shipid.identification.plausibility import hold_rudder

        hold_rudder(particulars.largest_rudder_deg)
    return logs


def _particulars(args):
    """The particulars of --particulars (None when not given)."""
    if not getattr(args, "particulars", None):
        return None
    from shipid.data.particulars import read_particulars

    return read_particulars(args.particulars)


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


def _log_particulars(logs) -> dict | None:
    from shipid.data.particulars import logs_particulars

    found = logs_particulars(logs)
    return None if found is None else found.to_dict()


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


def _read_files(args, *given) -> list:
    """The files a command reads besides its logs: ``given`` and the ``--particulars`` and
    ``--prior`` files, for ``check_outputs`` to protect (``identify LOG --prior m.json -o
    m.json`` overwrote the prior with the fit)."""
    files = [g for g in given if g is not None]
    for option in ("particulars", "prior"):
        value = getattr(args, option, None)
        # 'clarke' and a reference ship are names, not files (unless such a file exists).
        if isinstance(value, str | Path) and (
                Path(value).exists() or str(value).lower() not in ("clarke", *_vessel_names())):
            files.append(value)
    return files


def _one_rps(logs, args) -> float | None:
    """The propeller speed every training log runs at (their approach's, as the model file
    records it), where it is one and positive and the model is to be carried to the others by
    advance-ratio similarity (``shipid.dynamics.similarity``; not with --no-rps-similarity);
    else None."""
    if not getattr(args, "rps_similarity", True):
        return None
    return _constant_rps(logs)


def _ahead(logs, args):
    """The forms the model of ``logs`` is written in (``shipid.dynamics.astern.AsternForms``):
    its ahead forms where every log runs ahead throughout (not with --no-ahead-forms), its
    thrust at --astern-thrust's ratio astern where no log reverses the propeller."""
    from shipid.dynamics.astern import AsternForms, logs_ahead, logs_never_reverse
    from shipid.dynamics.propeller import ASTERN_THRUST_RATIO

    ratio = getattr(args, "astern_thrust", ASTERN_THRUST_RATIO)
    return AsternForms(getattr(args, "ahead_forms", True) and logs_ahead(logs),
                       ratio if ratio is not None and logs_never_reverse(logs) else None)


def _constant_rps(logs) -> float | None:
    """The one positive propeller speed the logs run at (their approaches' median), else None
    (no rps logged, or one that varies)."""
    import numpy as np

    from shipid.identification.identify import varies

    if not all("n" in log.columns for log in logs):
        return None
    n = np.concatenate([log["n"].to_numpy(dtype=float) for log in logs])
    # Anchored at the median of the logs' approach rps, which the fit stands for whatever their
    # order: anchored at the first log's, the KVLCC2's MARIN and HSVA runs (10.33 and 10.23 rps,
    # one rps to the fit) gave models whose held-out errors moved by up to 11 % with the order
    # the files were given in.
    approaches = [a for a in (_approach(log, "n") for log in logs) if a is not None]
    rps = float(np.median(approaches)) if approaches else None
    return rps if rps is not None and rps > 0 and not varies(n) else None


def _vessel_names() -> tuple[str, ...]:
    from shipid.vessels import VESSELS

    return tuple(VESSELS)


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


def _logs_side(logs) -> str | None:
    """'port' or 'starboard': where a positive rudder turns the logs' ship; None, not known."""
    from shipid.identification.physics import rudder_sign

    sign = rudder_sign(logs)
    return None if sign is None else ("starboard" if sign > 0 else "port")


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


def _term_display(text: str) -> str:
    """A term as printed in a Markdown table cell (its bars escaped: ``\\|u\\|u``)."""
    from shipid.dynamics.terms import parse_term

    return (parse_term(text).display() or "1").replace("|", "\\|")


def _json_text(data) -> str:
    from shipid.reporting.modelfile import json_safe

    return json.dumps(json_safe(data), indent=2, ensure_ascii=False) + "\n"


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


def _markdown_dashed(table, fmt: str) -> str:
    """``table`` as markdown, its numbers to ``fmt`` and its blanks (NaN, None) as '–'."""
    # Mixed columns (numbers and blanks) are objects, which floatfmt leaves alone.
    table = table.map(lambda x: f"{x:{fmt}}" if isinstance(x, float) and x == x else x)
    return table.astype(object).where(table.notna(), "–").to_markdown(index=False, floatfmt=fmt)


def _warn(message: str) -> None:
    warnings.warn(message, ShipidWarning, stacklevel=2)


def _approach(log, column: str) -> float | None:
    from shipid.data.log import approach

    return approach(log, column)


def _warn_approach(logs, names) -> None:
    """Say so when the first log (whose approach the checks and manoeuvres use) starts without
    headway, and name the zig-zags and turns read whole from rest (``manoeuvres_from_rest``)."""
    from shipid.data.log import approach_note
    from shipid.trials.reading import manoeuvres_from_rest

    note = approach_note(logs[0], names[0]) if logs else None
    if note:
        _warn(note)
    whole = manoeuvres_from_rest(logs)
    if whole:
        which = _count_logs([Path(names[i]).name for i in whole])
        _warn(f"{which} {'is a zig-zag or turn' if len(whole) == 1 else 'are zig-zags or turns'}"
              " read whole, from rest: "
              "--start auto --end auto cuts them to the manoeuvre (the Esso Osaka's nine "
              "zig-zags read whole put the default model's 35° turns 47 % and 58 % long, cut "
              "28 % and 2 %: benchmarks/study_esso_whole_logs.py)")


def _std_errors(ident) -> dict:
    return {d: ident.diagnostics[d].get("std_errors", {}) for d in ident.diagnostics}


def _rudder_drag_note(model, logs, speed, rps, std_errors=None) -> str | None:
    """``identify``'s and ``select``'s warning where the fitted surge's rudder drag pushes the
    ship ahead (``beyond_the_logs.rudder_drag_ahead``), against the logs' particulars; None where it
    is a drag or they cannot tell. ``std_errors``: the fit's {term: ±} of u̇ (not an average's)."""
    from shipid.data.particulars import logs_particulars
    from shipid.identification.beyond_the_logs import rudder_drag_ahead

    return rudder_drag_ahead(model, logs_particulars(logs), speed, rps, std_errors)


def _print_yaw_rate_offsets(args, paths, logs) -> None:
    """One line of the offsets ``--yaw-rate-offset auto`` read off the logs' headings."""
    if args.yaw_rate_offset == "auto" and logs:
        shown = []
        for p, log in zip(paths, logs, strict=True):
            read, total = (math.degrees(log.attrs.get(k, 0.0))
                           for k in ("yaw_rate_offset_read", "yaw_rate_offset"))  # fmt: skip
            shown.append(f"{Path(p).name} {read:+.3g} °/s" + (
                "" if math.isclose(read, total) else f" ({total:+.3g} °/s with the offset its "
                "file had taken off before)"))
        print("yaw rate less each log's gyro offset read off its heading (--yaw-rate-offset "
              f"auto): {', '.join(shown)}", file=sys.stderr)


def _yaw_rate_notes(cond: dict, logs, names) -> list[str]:
    """Logs whose r is not corrected the way the model's training logs' was: read as measured
    where its offset is material (the checks name it) for a model of corrected rates, or
    corrected for a model of raw ones."""
    from shipid.data.checks import material_yaw_rate_offset

    trained = cond.get("yaw_rate_offset_deg_s")
    out = []
    for log, name in zip(logs, names, strict=True):
        if trained and "yaw_rate_offset" not in log.attrs and material_yaw_rate_offset(log):
            out.append(f"{name}: the model was identified from yaw rates less their gyro "
                       "offsets (--yaw-rate-offset), this log's r is as measured: its free "
                       "runs start from and are judged against another r; give "
                       "--yaw-rate-offset auto")  # fmt: skip
        elif not trained and log.attrs.get("yaw_rate_offset"):
            out.append(f"{name}: its r is less a gyro offset (--yaw-rate-offset), the model was "
                       "identified from yaw rates as measured, which hold their offsets in its "
                       "yaw equation: identify it from corrected logs too")  # fmt: skip
    return out


def _yaw_rate_offsets(logs) -> list[float] | None:
    """The gyro offsets [°/s] subtracted from each log's r (``--yaw-rate-offset``), or None."""
    if not any("yaw_rate_offset" in log.attrs for log in logs):
        return None
    return [math.degrees(float(log.attrs.get("yaw_rate_offset", 0.0))) for log in logs]


def _rudder_record(logs, trials) -> dict:
    """The training logs' rudder rate for the model file [rad/s] (None where none swings or the
    sampling does not resolve it), and whether their rudder swings faster than their sampling
    resolves (``rudder_unresolved``: the Esso Osaka's 35° in under 0.3 s at 10 Hz)."""
    from shipid.trials.trial import logs_rudder_rate, rudder_unresolved

    rate = logs_rudder_rate(logs, trials)
    return {"rudder_rate": rate,
            "rudder_unresolved": rate is None and any(rudder_unresolved(lg) for lg in logs)}


def _log_record(args, logs) -> dict:
    """The model file's ``preprocessing`` record of how the training logs were read (the read
    options given) and what they hold (approach, rudder, convention, scale, gyro offsets), as
    ``identify`` and ``select`` both write it."""
    from shipid.trials.reading import CUT_AT_DROPOUT, CUT_TO_MANOEUVRE
    from shipid.trials.trial import describe_trial

    cut, ended = ([log.attrs.get("name") for log in logs if log.attrs.get(key)]
                  for key in (CUT_TO_MANOEUVRE, CUT_AT_DROPOUT))  # fmt: skip
    # Read once: the rudder rate and what each log reads as (the commands that run the model
    # say where it is asked a kind of manoeuvre none of them was).
    trials = [describe_trial(log) for log in logs]
    return {"dt": args.dt, "start": args.start, "end": args.end, "lead": args.lead,
            "cut_to_manoeuvre": cut or None, "cut_at_dropout": ended or None,
            "columns": args.columns, "degrees": args.degrees, "format": args.format,
            "scale": args.scale, "approach_speed": _approach(logs[0], "u"),
            "approach_rps": _approach(logs[0], "n"), **_rudder_record(logs, trials),
            "rudder_positive": logs[0].attrs.get("rudder_positive"),
            "log_scale": _log_scale(logs), "yaw_rate_offset_deg_s": _yaw_rate_offsets(logs),
            "ship": next((lg.attrs["ship"] for lg in logs if lg.attrs.get("ship")), None),
            "manoeuvres": [trial.kind for trial in trials]}  # fmt: skip


def _log_scale(logs) -> float | None:
    """The scale λ of the training logs (their metadata), when they share one."""
    scales = {float(log.attrs["scale"]) for log in logs if "scale" in log.attrs}
    return scales.pop() if len(scales) == 1 and all("scale" in log.attrs for log in logs) \
        else None


def _simulated_metadata(name: str, target, cond: dict) -> dict:
    """Metadata of a log simulated on ``name`` (a reference ship or a model file): the ship, the
    source and the scale are the simulated ship's. ``simulate`` copied the driving log's (a
    KVLCC2 run on the scale ship's rudder was written as the scale ship at 1:16.95, with the
    log's manoeuvre and gyro offset), and a model file's runs were written at scale 1 whatever
    the scale of the logs it was identified from."""
    if hasattr(target, "log_metadata"):
        return target.log_metadata()
    out = {"ship": Path(name).name, "source": f"simulated: model file {name}"}
    # Training logs that said no scale leave it unknown: 1 reads as full scale (as
    # ``Vessel.log_metadata`` leaves out a model's).
    if cond.get("log_scale"):
        out["scale"] = float(cond["log_scale"])
    if cond.get("particulars") is not None:
        out["particulars"] = cond["particulars"].to_dict()
    return out


def _scale_notes(cond: dict, logs, names) -> list[str]:
    """Logs at another scale than the model's training logs: read with the wrong --scale."""
    trained = cond.get("log_scale")
    out = []
    for log, name in zip(logs, names, strict=True):
        lam = log.attrs.get("scale")
        if trained and lam and abs(lam / trained - 1) > 0.01:
            # Only MARIN's reader Froude-scales its data by --scale; HSVA's (model scale) takes
            # λ as a label, and "--scale 1" there called the 7 m model's data full scale.
            read = (f"read it with --scale {trained:g}, or "
                    if str(log.attrs.get("source", "")).startswith("MARIN") else "")
            out.append(f"{name}: this log is at scale 1:{lam:g} and the model's training logs were"
                       f" at 1:{trained:g}: {read}carry the model over with shipid rescale "
                       f"--factor {trained / lam:g}")  # fmt: skip
    return out


def _ship_notes(cond: dict, logs, names) -> list[str]:
    """Logs of another ship than the model's training logs (by name, or by the main dimensions
    of their particulars): a KVLCC2 model judged on an Esso Osaka log printed its errors as any
    other's."""
    from shipid.data.log import dimension_apart, same_ship_key, ship_name

    trained, particulars = cond.get("ship"), cond.get("particulars")
    out = []
    for log, name in zip(logs, names, strict=True):
        ship = ship_name(log)
        if trained and ship and ship != same_ship_key(trained):
            out.append(f"{name}: a log of ship {log.attrs['ship']!r}, and the model was "
                       f"identified from logs of {trained!r}: it predicts another ship")
            continue
        apart = dimension_apart(log.attrs.get("particulars"),
                                particulars.to_dict() if particulars is not None else None)
        if apart:
            key, mine, theirs = apart
            out.append(f"{name}: its particulars give a {key} of {mine:g}, the model's training "
                       f"logs {theirs:g}: it predicts another ship")
    return out


def _sampling_notes(cond: dict, logs, names) -> list[str]:
    """Logs sampled coarser than the model's Δk: the free runs step at the log's sampling, so
    the model is integrated more coarsely than it was identified (the paper ship's 10/10 second
    overshoot in closed loop: 10.8° at its Δk 0.2 s, 13.4° at 0.5 s)."""
    import numpy as np

    trained = cond.get("dt")
    out = []
    for log, name in zip(logs, names, strict=True):
        t = log["t"].to_numpy()
        step = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
        if trained and step > SAMPLING_SLACK * trained:
            out.append(f"{name}: its samples are {step:.3g} s apart, {step / trained:.3g} times the "
                       f"model's Δk ({trained:.3g} s): the free runs are integrated at the "
                       f"log's step, coarser than the model was identified at, and lose accuracy; "
                       f"give --dt {trained:.3g}")  # fmt: skip
    return out


# A log sampled up to this many times the model's Δk is run as it is without a note.
SAMPLING_SLACK = 1.5
# The commands' default integration steps [s].
MANOEUVRE_STEP = CRITERIA_STEP = 0.05
CONTROL_STEP = 0.1  # autopilot, follow


def _step_note(cond: dict, step: float, default: float, option: str = "--dt") -> str | None:
    """A run of a model integrated at a step coarser than its Δk: its manoeuvres lose
    accuracy without a word (a KVLCC2 model's 10/10 first overshoot: 9.77° at 0.05 s, 10.99°
    at 1 s, 13.5° at 2 s; its Δk 0.2 s). Not at the command's ``default`` step or finer, which
    resolves any model's motions (a model of the MARIN logs at their own 0.02 s would be
    warned on every run)."""
    trained = cond.get("dt")
    if not trained or not step > SAMPLING_SLACK * max(trained, default):
        return None
    return (f"{option} {step:g} s is {step / trained:.3g} times the model's Δk ({trained:.3g} s): "
            f"its runs are integrated more coarsely than it was identified at and lose accuracy "
            f"(overshoots by degrees); give {option} {trained:.3g} or less")  # fmt: skip


def _fmt_speed(u: float | None) -> str:
    return "none" if u is None else f"{u:.3g} m/s"


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


def _pd():
    import pandas as pd

    return pd


def _cores() -> int:
    import os

    return os.cpu_count() or 1


def _np():
    import numpy as np

    return np


# A log whose approach is this many times a reference ship's own (or less than its inverse)
# is of another ship or scale (MARIN's KVLCC2 files read without --scale run at 8.1 m/s, the
# reference 7 m model at 1.18).
REFERENCE_SPEED_FACTOR = 2.0


def _reference_speed_notes(vessel, logs, names) -> list[str]:
    """A warning per log whose approach speed is far from the reference ship's own: the logs
    carry no length to check, their speed says the scale."""
    own = getattr(vessel, "approach_speed", None)
    out = []
    for log, name in zip(logs, names, strict=True):
        u0 = float(log["u"].iloc[0]) if len(log) else math.nan
        if own and u0 > 0 and not 1 / REFERENCE_SPEED_FACTOR <= u0 / own <= REFERENCE_SPEED_FACTOR:
            # Only MARIN's reader Froude-scales its full-scale data (``_scale_notes``).
            marin = str(log.attrs.get("source", "")).startswith("MARIN")
            out.append(f"{name}: it starts at {u0:.3g} m/s, {u0 / own:.2g} times {vessel.name}'s "
                       f"approach ({own:.3g} m/s, its {vessel.length:g} m): a log of another "
                       "ship or scale" + (" (MARIN's files at the 7 m model: --scale 45.7)"
                                          if marin else "")
                       + " is run at a speed the reference ship was never made for")  # fmt: skip
    return out


def _vessel_conditions() -> dict:
    """A reference ship's "training conditions": none (no logs, no envelope, no convention of
    logs: the ship says its own)."""
    return {"speed": None, "rps": None, "envelope": {}, "particulars": None,
            "rudder_rate": None, "rudder_positive": None, "alternatives": {},
            "alternatives_fit": ""}  # fmt: skip


def _reference_ship(name: str):
    """The reference ship ``name`` says: a built-in one, or a ship's file (an MMG model,
    ``shipid correct``'s corrected ship); None for a model file."""
    if name in VESSEL_NAMES:
        from shipid.vessels import get_vessel

        return get_vessel(name)
    from shipid.identification.correction import reference_file

    return reference_file(name)


def _ship_or_model(name: str, hybrid: bool = False):
    """A reference ship (its trimmed speed applies) or a model file with its training
    conditions (approach speed, propeller speed, envelope); a model with a kernel residual
    where the command runs one (``hybrid``), else refused."""
    from shipid.reporting.modelfile import load_document, model_from_document, training_conditions
    if name not in VESSEL_NAMES and not Path(name).exists():
        raise ShipidError(f"{name}: neither a model file nor a known vessel "
                          f"({', '.join(VESSEL_NAMES)})")  # fmt: skip
    from shipid.identification.correction import ship_ensemble

    ship = _reference_ship(name)
    if ship is not None:
        # A corrected ship's bootstrap replicates, where its file has them: the bands.
        return ship, {**_vessel_conditions(), "ensemble": ship_ensemble(ship)}
    from shipid.reporting.modelfile import (
        alternatives_fit,
        alternatives_from_document,
        ensemble_from_document,
    )

    doc = load_document(name)
    model = model_from_document(doc, name, hybrid=hybrid)
    cond = training_conditions(doc)
    cond["ensemble"] = ensemble_from_document(doc, name, model)
    cond["alternatives"] = alternatives_from_document(doc, name)
    cond["alternatives_fit"] = alternatives_fit(doc)
    return model, cond


# Lengths of one ship further apart than this are two ships (another scale), not a correction.
LENGTH_SLACK = 0.05


def _check_length(name: str, target, cond: dict, given: float | None, source: str) -> None:
    """Refuse a length that is not the one of the ship ``target`` runs as: its indices in ship
    lengths were divided by another ship's (a 4 m model judged with full-scale particulars of
    67.8 m had tactical diameters of 0.19 L, and passed). ``source`` names the option."""
    own = getattr(target, "length", math.nan)
    if not (isinstance(own, float) and math.isfinite(own)):
        own = cond["particulars"].length if cond.get("particulars") is not None else None
    if own and given and abs(given / own - 1.0) > LENGTH_SLACK:
        remedy = (f"to judge a ship {given / own:.4g} times as long, carry the model over first "
                  f"(shipid rescale {name} --length {given:g} -o OUT.json)"
                  if name not in VESSEL_NAMES else "a reference ship is judged at its own")
        raise ShipidError(f"{source} gives a length of {given:g} m, but {name} runs as a ship of "
                          f"{own:g} m: its manoeuvres are that ship's, so their lengths would be "
                          f"divided by another's; {remedy}")  # fmt: skip


SCALE_SLACK = 0.01  # a scale this close to the training logs' is theirs (rounding, 45.7 vs 45.71)


def _check_scale(name: str, cond: dict, scale: float | None, source: str) -> None:
    """Refuse a scale λ that is not the one of the logs the model was identified from: its
    manoeuvres run at their ship's size and speed. A model of MARIN's full-scale KVLCC2 files
    (read without --scale, λ = 1, 8.1 m/s) judged with the 7 m model's particulars (λ = 45.7)
    ran its manoeuvres at 8.1 m/s over a 7 m ship's times and printed not one value, and its
    verdict: NOT all criteria met."""
    trained = cond.get("log_scale")
    if not trained or not scale or abs(scale / trained - 1.0) <= SCALE_SLACK:
        return
    raise ShipidError(f"{source} gives the ship at 1:{scale:g}, but {name} was identified from "
                      f"logs at 1:{trained:g}: its manoeuvres run at that ship's size and speed; "
                      f"identify from the trial files read with --scale {scale:g}, or carry the "
                      f"model over first (shipid rescale {name} --factor {trained / scale:.4g} -o "
                      "OUT.json)")  # fmt: skip


def _steady_window(cond: dict) -> float:
    """The seconds over which a model's approach is judged steady: ``STEADY_WINDOW`` at the
    scale it was identified at, √λ times as long for each Froude rescaling by λ since
    (``modelfile.time_scale``), that a rescaled model start its manoeuvres as its original."""
    from shipid.data.log import STEADY_WINDOW

    return STEADY_WINDOW * cond.get("time_scale", 1.0)


def _run_approach(target, cond: dict, speed: float | None, rps: float | None):
    """Approach speed and rps of a run on ``target``: a reference ship's own trim, or a model's
    steady straight approach (``shipid.dynamics.equilibrium.steady_approach``), printed, with a
    warning when it is not steady. Returns (speed, rps, warning or None)."""
    from shipid.dynamics.equilibrium import steady_approach
    from shipid.dynamics.hybrid import HybridModel
    from shipid.dynamics.model import ManoeuvringModel

    if not isinstance(target, ManoeuvringModel | HybridModel):
        return _ship_approach(target, speed, rps)
    if target.uses_thrust:  # its straight approach needs the thrust too
        from shipid.trials.manoeuvres import THRUST_REFUSED

        raise ShipidError(THRUST_REFUSED)
    if speed is None and not cond["speed"]:
        return None, rps if rps is not None else cond["rps"], None  # the run names what is missing
    app = steady_approach(target, cond["speed"], cond["rps"], speed, rps,
                          window=_steady_window(cond))  # fmt: skip
    print(app.describe())
    return app.speed, app.rps, app.warning


def _ship_approach(ship, speed: float | None, rps: float | None):
    """A reference ship's run: its own trim; where its propeller follows the run's rate (an MMG
    file's ``rps: logs``), the trimmed rps unless given, and at a given rps without --speed the
    ship's straight-running speed at it, printed. Returns (speed, rps, None)."""
    dyn = getattr(ship, "dynamics", None)
    if not getattr(dyn, "uses_rps", False):
        return speed, rps, None
    if rps is None:
        return speed, dyn.reference.n_prop if hasattr(dyn, "reference") else dyn.n_prop, None
    if speed is None:
        from shipid.dynamics.equilibrium import vessel_straight_speed

        speed = vessel_straight_speed(ship, rps)
        if speed is None:
            raise ShipidError(f"{ship.name}: no straight-running speed at {rps:g} rps (the "
                              "propeller's thrust does not meet the resistance); give --speed")
        print(f"approach: {speed:.4g} m/s, {ship.name}'s straight-running speed at {rps:g} rps")
    return speed, rps, None


def _model_notes(target, speed: float | None, rps: float | None) -> list[str]:
    """The plausibility warnings of a model file the commands run (``validate``, ``manoeuvre``,
    ``criteria``), checked on the model as they run it: its surge pushes a ship at rest astern
    (``from_rest_warning``), its rudder turns the ship the other way at speeds ahead short of its
    straight speed or with the propeller stopped (``rudder_reversed_warning``); none for a
    reference ship."""
    from shipid.dynamics.hybrid import HybridModel
    from shipid.dynamics.model import ManoeuvringModel

    if not isinstance(target, ManoeuvringModel | HybridModel):
        return []
    from shipid.identification.beyond_the_logs import from_rest_warning, rudder_reversed_warning

    return [f"plausibility: {note}" for note in (from_rest_warning(target, speed, rps),
                                                 rudder_reversed_warning(target, speed, rps))
            if note]  # fmt: skip


def _unused_inputs(target, args) -> list[str]:
    """Warnings for --rps, --astern-rps and --wind-speed given to a model without a term in the
    propeller speed or the wind: the run takes them and nothing changes (a manoeuvre "at 5 rps"
    of the paper's blanke model was its training condition, without a word)."""
    from shipid.dynamics.hybrid import HybridModel
    from shipid.dynamics.model import ManoeuvringModel

    if not isinstance(target, ManoeuvringModel | HybridModel):
        return []
    inputs = set(target.structure.inputs)
    name = target.structure.name
    notes = []
    for option, value in (("--rps", getattr(args, "rps", None)),
                          ("--astern-rps", getattr(args, "astern_rps", None))):  # fmt: skip
        if value is not None and "n" not in inputs:
            notes.append(f"{option} {value:g} changes nothing: the model ({name}) has no term in "
                         "the propeller speed n; its condition is set by --speed")  # fmt: skip
    wind = getattr(args, "wind_speed", None)
    if wind and not target.uses_wind:
        notes.append(f"--wind-speed {wind:g} changes nothing: the model ({name}) has no wind "
                     "terms")  # fmt: skip
    return notes


def _steering(target, cond: dict, rate_deg_s: float | None, fallback: str = "instantaneous"):
    """The steering machine of a run and a line saying which: ``--rudder-rate`` (a reference
    ship keeps its gear's other limits), else a reference ship's own gear (None: the ship's),
    else the rate of the model's training logs (overshoots depend on it as much as on the
    model), else ``fallback``: an instantaneous rudder, said so, or 'caller' (None: the caller
    chooses, as the IMO criteria take the SOLAS rate)."""
    import dataclasses

    from shipid.dynamics.steering import SteeringMachine

    own = getattr(target, "steering", None)
    # A model's gear: 35°, or the particulars' rudder_limit where the ship's stops short of it.
    particulars = cond.get("particulars")
    largest = math.radians(particulars.largest_rudder_deg if particulars else 35.0)
    if rate_deg_s is not None:
        rate, source = math.radians(rate_deg_s), "--rudder-rate"
    elif own is not None:
        rate = own.max_rate
        return None, ("rudder: the ship's own steering gear" + (
            f", {math.degrees(rate):.3g} °/s" if rate else ", instantaneous"))
    elif cond.get("rudder_rate"):
        rate, source = float(cond["rudder_rate"]), "the training logs' rudder rate"
    elif fallback == "caller":
        return None, None
    elif cond.get("rudder_unresolved"):
        return SteeringMachine(largest), ("rudder: instantaneous (the training logs' rudder "
                                          "swings between two samples, faster than they "
                                          "resolve; give a rate with --rudder-rate DEG/S)")
    else:
        return SteeringMachine(largest), ("rudder: instantaneous (the model file has no "
                                          "training rudder rate; give one with --rudder-rate "
                                          "DEG/S)")  # fmt: skip
    steering = (SteeringMachine(largest, rate) if own is None
                else dataclasses.replace(own, max_rate=rate))  # fmt: skip
    return steering, f"rudder rate {math.degrees(rate):.3g} °/s ({source})"


def _warn_beyond_training(cond: dict, name: str, log) -> None:
    """A warning per signal where a model's run (``simulate``'s, a controller's) leaves its
    training logs' range: a run beyond the trials is a guess."""
    from shipid.evaluation.envelope import outside_envelope

    for note in outside_envelope(cond.get("envelope") or {}, log):
        _warn(f"{name}: {note}")
