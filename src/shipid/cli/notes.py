"""Warnings a command gives where what it is asked differs from what its model was identified
from: another ship or scale, a coarser sampling or step, gyro offsets corrected one way and not
the other, inputs the model has no terms for, runs beyond its training logs, and what the model
does that no ship would."""

from __future__ import annotations

import math
from pathlib import Path

from shipid.cli.printing import _warn


def _std_errors(ident) -> dict:
    return {d: ident.diagnostics[d].get("std_errors", {}) for d in ident.diagnostics}


def _rudder_drag_note(model, logs, speed, rps, std_errors=None) -> str | None:
    """``identify``'s and ``select``'s warning where the fitted surge's rudder drag pushes the
    ship ahead (``beyond_the_logs.rudder_drag_ahead``), against the logs' particulars; None where it
    is a drag or they cannot tell. ``std_errors``: the fit's {term: ±} of u̇ (not an average's)."""
    from shipid.data.particulars import logs_particulars
    from shipid.identification.beyond_the_logs import rudder_drag_ahead

    return rudder_drag_ahead(model, logs_particulars(logs), speed, rps, std_errors)


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


def _warn_beyond_training(cond: dict, name: str, log) -> None:
    """A warning per signal where a model's run (``simulate``'s, a controller's) leaves its
    training logs' range: a run beyond the trials is a guess."""
    from shipid.evaluation.envelope import outside_envelope

    for note in outside_envelope(cond.get("envelope") or {}, log):
        _warn(f"{name}: {note}")
