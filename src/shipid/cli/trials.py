"""``shipid manoeuvre`` and ``criteria``: standard manoeuvres and the IMO criteria on a model or ship."""

from __future__ import annotations

import math
import sys
from functools import partial
from pathlib import Path

from shipid.cli.notes import _model_notes, _simulated_metadata, _step_note, _unused_inputs
from shipid.cli.printing import _json_text, _markdown_dashed, _pd, _warn
from shipid.cli.reading import _read_files
from shipid.cli.targets import (
    CRITERIA_STEP,
    MANOEUVRE_STEP,
    _check_length,
    _check_scale,
    _run_approach,
    _ship_or_model,
    _steady_window,
    _steering,
)
from shipid.errors import ShipidError

# A model's training rudder faster than this many times the SOLAS rate at its scale turns no
# ship's gear: a model basin's or pond's rudder turned by hand or by a fast servo. The KVLCC2's
# MARIN runs turn theirs at 1.0 times it (15.9 °/s at 1:45.7), the paper's trials at 1.0; the
# Esso Osaka's pond runs at 4.5 (109 °/s at 1:108.3), where their default model's 20/20 first
# overshoots came 2.7–2.8° smaller than at the SOLAS rate.
GEAR_BEYOND_SOLAS = 3.0


def _gear_beyond_ships(steering, scale: float | None):
    """``steering`` (the training logs' rudder rate) and None, or the SOLAS rate at the model's
    scale and a note where the training rate is more than ``GEAR_BEYOND_SOLAS`` times it: the
    criteria judge the full-scale ship, whose gear the model's rudder does not stand for. Only
    where the scale is known and above 1: a ship judged at its own scale (a USV) has the gear
    its logs show."""
    import dataclasses

    from shipid.trials.criteria import SOLAS_RUDDER_RATE_DEG

    if steering is None or not steering.max_rate or not (scale and scale > 1):
        return steering, None
    solas = math.radians(SOLAS_RUDDER_RATE_DEG * math.sqrt(scale))
    if not steering.max_rate > GEAR_BEYOND_SOLAS * solas:
        return steering, None
    ratio = steering.max_rate / solas
    note = (f"rudder: the training logs' rate, {math.degrees(steering.max_rate):.3g} °/s, is "
            f"{math.degrees(steering.max_rate) / math.sqrt(scale):.3g} °/s at full scale (1:"
            f"{scale:g}), {ratio:.2g} times SOLAS's {SOLAS_RUDDER_RATE_DEG:g} °/s: no ship's "
            f"steering gear, so the criteria are judged at the SOLAS rate, "
            f"{math.degrees(solas):.3g} °/s at this scale (a faster rudder checks a yaw sooner: "
            f"smaller overshoots); --rudder-rate {math.degrees(steering.max_rate):.3g} judges "
            "at the logs' rate")  # fmt: skip
    return dataclasses.replace(steering, max_rate=solas), note


def cmd_criteria(args) -> int:
    """``shipid criteria``: the IMO MSC.137(76) criteria of a model or vessel."""

    from shipid.data.particulars import read_particulars
    from shipid.outputs import OutputSet, check_outputs
    from shipid.trials.criteria import imo_criteria

    check_outputs({"--json": (args.json, "json")},
                  _read_files(args, args.model if Path(args.model).exists() else None))
    target, cond = _ship_or_model(args.model, hybrid=True)
    particulars = read_particulars(args.particulars) if args.particulars else cond["particulars"]
    if args.length:
        _check_length(args.model, target, cond, args.length, "--length")
    elif args.particulars:
        _check_length(args.model, target, cond, particulars.length,
                      f"--particulars {args.particulars}")  # fmt: skip
    if args.particulars and not args.scale:  # --scale is the user's to override with
        _check_scale(args.model, cond, particulars.scale, f"--particulars {args.particulars}")
    speed, rps, _ = _run_approach(target, cond, args.speed, args.rps)  # imo_criteria notes it
    model_notes = _model_notes(target, speed, rps)
    # Given, else the ship's gear or the training logs' rate, else imo_criteria's SOLAS rate.
    steering, _ = _steering(target, {**cond, "particulars": particulars}, args.rudder_rate,
                            fallback="caller")  # fmt: skip
    # The scale the training logs were read at, where neither option nor particulars give one.
    scale = args.scale or (particulars.scale if particulars else None) or cond.get("log_scale")
    rate_note = None
    if args.rudder_rate is None and getattr(target, "steering", None) is None:
        steering, rate_note = _gear_beyond_ships(steering, scale)
    run = partial(imo_criteria, particulars=particulars, length=args.length, speed=speed,
                  scale=scale, rps=rps, steering=steering, astern_rps=args.astern_rps,
                  dt=args.dt, steady_window=_steady_window(cond))  # fmt: skip
    crit = run(target)
    crit.notes += ([rate_note] if rate_note else []) + model_notes
    crit.notes += _unused_inputs(target, args)
    crit.notes += [n for n in (_step_note(cond, args.dt, CRITERIA_STEP),) if n]
    from shipid.evaluation.validate import faded_residual_notes

    crit.notes += [f"{name}: {note}" for name, res in crit.runs.items()
                   for note in faded_residual_notes(target, res.log)]  # fmt: skip
    outside = _runs_outside(cond["envelope"], crit.runs)
    crit.notes += _criteria_envelope_notes(cond["envelope"], crit.runs, outside)
    crit.notes += _criteria_unseen_kinds(cond.get("manoeuvres"), crit.runs)
    table = crit.table.copy()
    ensemble = cond.get("ensemble")
    if ensemble is not None and not args.no_bands:
        from shipid.trials.criteria import replicate_notes, with_intervals

        replicates = [run(m) for m in ensemble.members()]
        table = with_intervals(crit, replicates)
        crit.notes += replicate_notes(table, replicates, ensemble.members_label)
    beyond = _beyond_the_logs(crit, outside)
    if beyond is not None:
        table["beyond the logs"] = beyond
    tied = {}
    keys = list(zip(crit.table["criterion"], crit.table["manoeuvre"], strict=True))
    for name, alt in (cond.get("alternatives") or {}).items():
        # The structures the training logs could not tell apart from this one: their values
        # and verdicts beside the model's, from the same approach.
        rows = run(alt).table.to_dict(orient="records")
        tied[name] = rows
        other = {(row["criterion"], row["manoeuvre"]): row for row in rows}
        table[name] = [other.get(k, {}).get("value", math.nan) for k in keys]
        flips = [f"{k[0]} ({k[1]}): {'pass' if other[k]['passed'] else 'FAIL'}"
                 for k, mine in zip(keys, crit.table["passed"], strict=True)
                 if k in other and mine is not None and other[k]["passed"] is not None
                 and bool(mine) != bool(other[k]["passed"])]  # fmt: skip
        if flips:
            crit.notes.append(f"{name}, a structure the training logs could not tell apart from "
                              f"this one, reaches another verdict: {'; '.join(flips)}")
    c = crit.conditions
    print(f"IMO MSC.137(76) criteria for {args.model}: L = {c['length']:g} m, V = {c['speed']:.4g} "
          f"m/s, λ = {c['scale']:g} (full-scale L/V = {c['L_over_V_full_scale']:.3g} s), " + (
              f"rudder rate {c['rudder_rate_deg_s']:.3g} °/s" if c["rudder_rate_deg_s"]
              else "instantaneous rudder"))
    verdict = crit.verdict()
    extrapolated = [] if beyond is None else [
        b for b, ok in zip(beyond, crit.table["passed"], strict=True) if b and ok is not None]
    if extrapolated:
        verdict += (f"; {len(extrapolated)} of the {int(crit.table['passed'].notna().sum())} "
                    "verdicts are on manoeuvres beyond the training logs (column 'beyond the "
                    "logs': the signals that leave them), extrapolations a trial of that kind "
                    "decides")  # fmt: skip
    record = {**crit.to_dict(), "criteria": table.to_dict(orient="records"),
              "tied_structures": tied or None, "verdict": verdict}  # fmt: skip
    table["passed"] = table["passed"].map({True: "pass", False: "FAIL", None: "–"})
    print(_markdown_dashed(table, ".3g"))
    if "pass_share" in table:
        print(f"lower, upper: 95 % interval of the value, pass_share: the share of passes, "
              f"no_value: how many have none, over the model's {ensemble.replicates} "
              f"{ensemble.members_label} (more than 2.5 % without a value: not bounded)")
    if tied:
        print(f"{', '.join(tied)}: the value of each structure the training logs could not tell "
              f"apart from this one ({cond.get('alternatives_fit', '')}), from the same approach")
    print(verdict)
    for n in crit.notes:
        _warn(n)
    with OutputSet() as out:
        if args.json:
            out.write(args.json, lambda p: p.write_text(_json_text(record), "utf-8"))
    return 0


def _runs_outside(env, runs) -> dict[str, list[str]] | None:
    """Per manoeuvre run, the signals it takes beyond the model's training logs (None for a ship
    without logs): checked once, for the column and the notes."""
    from shipid.evaluation.envelope import signals_outside

    if not env:
        return None
    return {name: signals_outside(env, res.log) for name, res in runs.items()
            if getattr(res, "log", None) is not None}  # fmt: skip


def _beyond_the_logs(crit, outside) -> list[str] | None:
    """Per criterion, the signals its manoeuvre takes beyond the model's training logs ('' where
    none; None for a ship without logs). A verdict there is the model's extrapolation: the
    Mariner identified from two 20°/20° zig-zags met the 35° tactical diameter (4.78 L, 4.98 L)
    that the true Mariner fails (6.40 L, 6.65 L), with the rudder at 35° against ±20° trained."""
    if outside is None:
        return None
    names = {"delta": "δ"}
    return [", ".join(names.get(s, s) for s in outside.get(manoeuvre, []))
            for manoeuvre in crit.table["manoeuvre"]]


def _criteria_envelope_notes(env, runs, outside) -> list[str]:
    """Where the criteria's manoeuvres, together, leave the model's training envelope (one note
    per signal, naming the runs that do): a criterion judged beyond the trials is a guess."""
    import pandas as pd

    from shipid.evaluation.envelope import outside_envelope

    logs = [res.log for res in runs.values() if getattr(res, "log", None) is not None]
    if not outside or not logs:
        return []
    notes = []
    for note in outside_envelope(env, pd.concat(logs, ignore_index=True)):
        signal = note.split(" ", 1)[0]
        names = [name for name, signals in outside.items() if signal in signals]
        notes.append(f"criteria ({', '.join(names)}): {note}")
    return notes


def _criteria_unseen_kinds(trained, runs) -> list[str]:
    """``unseen_kind_note`` for each kind of manoeuvre the criteria run (a zig-zag, a turning
    circle) that none of the model's training logs is, naming the runs."""
    from shipid.evaluation.envelope import unseen_kind_note

    notes = []
    for kind in ("turning", "zigzag"):
        names = [name for name in runs if name.split(" ", 1)[0] == kind]  # "turning 35° port"
        note = unseen_kind_note(trained, kind) if names else None
        if note:
            notes.append(f"criteria ({', '.join(names)}): {note}")
    return notes


def _tied_manoeuvres(run, alternatives: dict, kind: str, fitted: str = "") -> dict:
    """The same manoeuvre on the structures that tied with the model's in ``identify``'s inflow
    comparison (``identification.structure_choice.alternatives``), printed one line each: what
    the training logs left open. Not an interval: on the KVLCC2's MMG model the truth's 10/10
    overshoots lay between the tied fits' in 9–12 of 16 cases (``study_auto_inflow.py``)."""
    if not alternatives or kind == "spiral":
        return {}
    out = {}
    for name, model in alternatives.items():
        res = run(model)
        out[name] = None if res.diverged else {k: v for k, v in res.indices.items()
                                                if isinstance(v, float)}  # fmt: skip
    print("The same manoeuvre on the structures the training logs could not tell apart from this "
          f"one ({fitted}; what the logs leave open, not an interval):")
    for name, indices in out.items():
        shown = "diverged" if indices is None else ", ".join(f"{k} {v:.4g}"
                                                             for k, v in indices.items())
        print(f"  {name}: {shown}")
    return out


# A pull-out whose yaw rate keeps more than this share of its rate at the release has not
# returned to a straight course: the straight run is unstable (to that side).
PULL_OUT_RESIDUAL = 0.05


def _pull_out_other_side(run, target, side: str, indices: dict):
    """The pull-out to the other side (the IMO's is run to both): its indices, and a note where
    it keeps a residual yaw rate this side does not. The KVLCC2's MMG model, unstable, pulled
    out from starboard returns to 0.1 % of its release rate, from port it keeps 40 %
    (−0.0205 rad/s); one side alone read as stable."""
    other = "port" if side == "starboard" else "starboard"
    res = run(target, side=other)
    if res.diverged:
        return None, f"the pull-out to {other} diverged: {res.reason}"
    this, that = (abs(x.get("residual_fraction") or 0.0) for x in (indices, res.indices))
    note = None
    if that > PULL_OUT_RESIDUAL >= this:
        note = (f"the pull-out to {other} keeps a residual yaw rate of "
                f"{res.indices['residual_yaw_rate']:.4g} rad/s ({100 * that:.0f} % of its rate at "
                f"the release) where this one keeps {100 * this:.1f} %: the straight run is "
                f"unstable to {other} (--first {other} shows it)")  # fmt: skip
    return res.indices, note


# The options each manoeuvre takes: another given to it changed nothing without a word (a
# spiral's --rudder, --first or wind, a stopping's rudder, a turn's --heading).
MANOEUVRE_OPTIONS = {
    "zigzag": {"rudder_deg", "heading", "first", "rudder_rate", "wind_speed"},
    "turning": {"rudder_deg", "first", "rudder_rate", "wind_speed"},
    "pull-out": {"rudder_deg", "first", "rudder_rate", "wind_speed"},
    "spiral": {"rudder_rate"},
    "stopping": {"astern_rps", "wind_speed"},
}
_OPTION_TEXT = {"rudder_deg": "--rudder", "heading": "--heading", "first": "--first",
                "rudder_rate": "--rudder-rate", "wind_speed": "--wind-speed",
                "astern_rps": "--astern-rps"}  # fmt: skip


def _unused_manoeuvre_options(args) -> list[str]:
    """A warning per option given that ``args.kind`` does not take (``MANOEUVRE_OPTIONS``)."""
    defaults = {"first": "starboard"}
    takes = MANOEUVRE_OPTIONS[args.kind]
    return [f"{text} changes nothing in a {args.kind} manoeuvre" for dest, text in
            _OPTION_TEXT.items() if dest not in takes
            and getattr(args, dest, None) not in (None, defaults.get(dest))]  # fmt: skip


def cmd_manoeuvre(args) -> int:
    """``shipid manoeuvre``: a standard manoeuvre on a model or vessel. The steps: the approach
    and steering gear, the manoeuvre chosen (its rudder capped at the gear's largest), the run
    and its ensemble's, the indices with their intervals and the notes, the outputs."""
    from shipid.evaluation.envelope import implausible_indices, outside_envelope, unseen_kind_note
    from shipid.evaluation.validate import faded_residual_notes
    from shipid.outputs import OutputSet, check_outputs
    from shipid.trials.manoeuvres import astern_thrust_note

    check_outputs({"--json": (args.json, "json"), "-o": (args.output, "log")},
                  _read_files(args, args.model if Path(args.model).exists() else None))
    for note in _unused_manoeuvre_options(args):
        _warn(note)
    target, cond = _ship_or_model(args.model, hybrid=True)
    speed, rps, unsteady = _run_approach(target, cond, args.speed, args.rps)
    # Said before the run, and kept for --json with the notes the run adds.
    plausibility_notes = _model_notes(target, speed, rps)
    for note in plausibility_notes:
        _warn(note)
    steering, rudder_note = _steering(target, cond, args.rudder_rate)
    kw = {"dt": args.step, "speed": speed, "rps": rps, "steering": steering}
    coarse = _step_note(cond, args.step, MANOEUVRE_STEP)
    if coarse:
        _warn(coarse)
    if args.wind_speed is not None:
        kw["wind"] = (args.wind_speed, math.radians(args.wind_from or 0.0))
    if args.duration is not None:
        kw["duration"] = args.duration
    run = _manoeuvre_to_run(args, target, steering, rps, kw)
    res = run(target)
    print(rudder_note)
    if getattr(target, "uses_wind", False) and "wind" not in kw:
        # The model's wind terms meet only the ship's own motion through the air.
        print("wind: still air (the model has wind terms; --wind-speed and --wind-from set a "
              "true wind)")  # fmt: skip
    gear = steering or getattr(target, "steering", None)  # the one the run used
    ensemble = cond.get("ensemble")
    runs = _ensemble_runs(args, run, ensemble)
    if res.diverged:
        print(res.reason, file=sys.stderr)
    notes = ([unsteady] if unsteady else []) + _unused_inputs(target, args)
    if args.kind == "stopping":
        astern = astern_thrust_note(target, speed, rps, args.astern_rps)
        notes += [astern.note] if astern else []
    notes += outside_envelope(cond["envelope"], res.log)
    notes += [n for n in (unseen_kind_note(cond.get("manoeuvres"), args.kind),) if n]
    notes += faded_residual_notes(target, res.log)
    if res.incomplete and not res.diverged:
        notes.append(f"{res.incomplete}: indices that need it are missing or those of a "
                     "transient; give a longer --duration")  # fmt: skip
    other_side = None
    if args.kind == "pull-out" and not res.diverged:
        other_side, note = _pull_out_other_side(run, target, args.first, res.indices)
        notes += [note] if note else []
    if args.kind == "turning" and not res.diverged:
        notes += implausible_indices(res.indices, speed or getattr(target, "approach_speed", None),
                                     getattr(target, "length", None), res.log)  # fmt: skip
    intervals, unbounded = _print_manoeuvre_indices(res, runs, ensemble, notes)
    tied = _tied_manoeuvres(run, cond.get("alternatives") or {}, args.kind,
                            cond.get("alternatives_fit", ""))  # fmt: skip
    for n in notes:
        _warn(n)
    with OutputSet() as out:
        if args.json:
            doc = {"manoeuvre": res.log.attrs.get("manoeuvre"), "diverged": res.diverged,
                   "approach": {"speed": speed, "rps": rps},
                   "diverged_at": res.diverged_at, "reason": res.reason,
                   "indices": res.indices, "index_intervals": intervals or None,
                   "index_not_bounded": unbounded or None, "tied_structures": tied or None,
                   "other_side_indices": other_side,
                   "rudder_rate_deg_s": (math.degrees(gear.max_rate) if gear and gear.max_rate
                                         else None),
                   "warnings": plausibility_notes + notes}  # fmt: skip
            out.write(args.json, lambda p: p.write_text(_json_text(doc), "utf-8"))
        if args.output:
            from shipid.data.io import write_log

            meta = _simulated_metadata(args.model, target, cond)
            meta.pop("rudder_positive", None)  # the run's own, as the model turns at its speed
            res.log.attrs.update(meta)
            write_log(res.log, args.output, out=out)
    return 0


def _manoeuvre_to_run(args, target, steering, rps, kw: dict):
    """The manoeuvre of ``args.kind`` as a function of the ship or model it runs on, with the
    run's options ``kw`` (changed here as the manoeuvre takes them); its rudder by default the
    standard one, or the gear's largest where that stops short of it (MSC.137(76) §4.2: the
    tanker's 10°, where `manoeuvre tanker turning` stopped on its own default, as its spiral on
    the 25°), said."""
    from shipid.trials.manoeuvres import (
        SPIRAL_ANGLES,
        pull_out,
        spiral,
        stopping,
        turning_circle,
        zigzag,
    )

    gear = steering if steering is not None else getattr(target, "steering", None)
    top = gear.capped_deg(SPIRAL_ANGLES[0]) if gear is not None else SPIRAL_ANGLES[0]
    if args.kind == "spiral" and top < SPIRAL_ANGLES[0]:
        _warn(f"the steering gear's largest rudder is {top:g}°: the spiral's angles run to it "
              f"instead of {SPIRAL_ANGLES[0]:g}°")  # fmt: skip
    if args.rudder_deg is None:
        standard = 35.0 if args.kind == "turning" else 20.0
        args.rudder_deg = gear.capped_deg(standard) if gear is not None else standard
        if args.rudder_deg < standard and args.kind in ("turning", "zigzag", "pull-out"):
            kind = {"turning": "turning circle", "zigzag": "zig-zag"}.get(args.kind, args.kind)
            _warn(f"the steering gear's largest rudder is {args.rudder_deg:g}°: the {kind} is "
                  f"run with it instead of {standard:g}° (--rudder to choose)")  # fmt: skip
    if args.kind == "zigzag":
        heading = args.heading if args.heading is not None else args.rudder_deg
        return partial(zigzag, rudder_deg=args.rudder_deg, heading_deg=heading,
                       first=args.first, **kw)  # fmt: skip
    if args.kind == "turning":
        return partial(turning_circle, rudder_deg=args.rudder_deg, side=args.first, **kw)
    if args.kind == "pull-out":
        if args.duration is not None:
            kw.pop("duration")
            kw["hold"] = kw["release"] = args.duration / 2
        return partial(pull_out, rudder_deg=args.rudder_deg, side=args.first, **kw)
    if args.kind == "spiral":
        kw.pop("wind", None)
        if args.duration is not None:
            kw["hold"] = kw.pop("duration")
        return partial(spiral, **kw)
    if not getattr(getattr(target, "dynamics", target), "uses_rps", False):
        raise ShipidError(f"{args.model}: a stopping test needs a model with propeller-speed "
                          "terms (n), whose thrust answers the astern order; "
                          + ("this reference ship's propeller turns at one rate"
                             if not Path(args.model).exists() else
                             "this model has none (identify it from logs with the n "
                             "column)"))  # fmt: skip
    if not rps:
        raise ShipidError("stopping needs the approach propeller speed (--rps, or a model "
                          "trained with the n column)")  # fmt: skip
    kw.pop("rps")
    kw.pop("steering")  # the rudder stays amidships
    return partial(stopping, rps=rps, astern_rps=args.astern_rps, **kw)


def _ensemble_runs(args, run, ensemble) -> list:
    """The manoeuvre on each of the model file's replicates (none with ``--no-bands``, for a
    spiral, or without an ensemble), the line that says how many diverged."""
    if ensemble is None or args.no_bands or args.kind == "spiral":
        return []
    runs = [run(member) for member in ensemble.members()]
    diverged = sum(r.diverged for r in runs)
    print(f"95 % intervals over the model's {ensemble.replicates} {ensemble.members_label}"
          + (f" ({diverged} diverged: an index is not bounded where more than 2.5 % of "
             "them diverged or lack it)" if diverged else "") + ":")
    return runs


def _print_manoeuvre_indices(res, runs: list, ensemble, notes: list) -> tuple[dict, dict]:
    """Each index of ``res``, with its 95 % interval over the replicates' ``runs`` (a diverged
    replicate has no indices: it widens the interval rather than vanishing), or why it is not
    bounded; a value outside its interval noted. Returns (intervals, not bounded: {index:
    why})."""
    from shipid.trials.manoeuvres import without_value

    intervals: dict = {}
    if runs:
        from shipid.identification.uncertainty import index_intervals

        intervals = index_intervals([{} if r.diverged else r.indices for r in runs])
    unbounded = {}  # index: how many replicates have none, and why
    for k, v in res.indices.items():
        if k == "table":
            print(_pd().DataFrame(v).to_markdown(index=False, floatfmt=".4g"))
            continue
        text = f"{k}: {v:.4g}" if isinstance(v, float) else f"{k}: {v}"
        lo, hi = intervals.get(k, (math.nan, math.nan))
        if math.isinf(lo) or math.isinf(hi):
            missing, why = without_value(runs, [r.indices.get(k) for r in runs])
            unbounded[k] = f"{missing} of {len(runs)} {ensemble.members_label} have none: {why}"
            text += f"  [not bounded: {unbounded[k]}]"
        elif math.isfinite(lo):
            text += f"  [{lo:.4g}, {hi:.4g}]"
            if isinstance(v, float) and not lo <= v <= hi:
                notes.append(f"{k} {v:.4g} lies outside the interval of the model's "
                             f"{ensemble.members_label}: they disagree with the fit, and the "
                             "interval does not describe it")  # fmt: skip
        print(text)
    return intervals, unbounded
