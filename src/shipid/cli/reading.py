"""The logs a command reads: the log options as ``ReadOptions``, the logs read with the ship's
particulars (a model's training logs cut to their trials and checked as one ship's at one scale),
what they hold (approach, propeller speed, rudder convention, gyro offsets) and the model file's
record of them."""

from __future__ import annotations

import math
import sys
from pathlib import Path

from shipid.cli.printing import _count_logs, _warn
from shipid.cli.targets import _vessel_names
from shipid.errors import ShipidError


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


def _log_particulars(logs) -> dict | None:
    from shipid.data.particulars import logs_particulars

    found = logs_particulars(logs)
    return None if found is None else found.to_dict()


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


def _logs_side(logs) -> str | None:
    """'port' or 'starboard': where a positive rudder turns the logs' ship; None, not known."""
    from shipid.identification.physics import rudder_sign

    sign = rudder_sign(logs)
    return None if sign is None else ("starboard" if sign > 0 else "port")


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
