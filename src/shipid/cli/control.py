"""``shipid linearise``, ``export``, ``autopilot`` and ``follow``: putting a model to work."""

from __future__ import annotations

import math
from pathlib import Path

from shipid.cli.notes import _step_note, _unused_inputs, _warn_beyond_training
from shipid.cli.printing import _json_text, _np, _pd, _warn
from shipid.cli.reading import _read_files
from shipid.cli.targets import (
    CONTROL_STEP,
    VESSEL_NAMES,
    _reference_ship,
    _run_approach,
    _ship_or_model,
    _steering,
)
from shipid.errors import ShipidError


def _controlled(args):
    """The model (or vessel) to control, the truth to test on, speed and rps."""
    from shipid.vessels import get_vessel

    target, cond = _ship_or_model(args.model)
    speed, rps, unsteady = _run_approach(target, cond, args.speed, args.rps)
    for note in ([unsteady] if unsteady else []) + _unused_inputs(target, args):
        _warn(note)
    speed = speed or getattr(target, "approach_speed", None)
    truth = get_vessel(args.truth) if args.truth else None
    if truth is not None and args.truth not in VESSEL_NAMES:
        raise ShipidError(f"--truth must be a reference ship ({', '.join(VESSEL_NAMES)})")
    steering, note = _steering(target, cond, args.rudder_rate)
    print(f"{args.model}: {note}")
    coarse = _step_note(cond, args.dt, CONTROL_STEP)
    if coarse:
        _warn(coarse)
    return target, truth, speed, rps, steering, cond


def _for_truth(pid, target, truth, speed, rps):
    """The model-tuned PID as it acts on the truth, and a note when it differs: its gains carry
    the model's rudder sign, so they are mirrored where the truth's positive rudder turns the
    other way (the MARIN KVLCC2 logs turn to port with positive rudder, the reference KVLCC2 to
    starboard; unmirrored, the truth was steered away from the ordered heading)."""
    from shipid.control.autopilot import PID
    from shipid.trials.manoeuvres import as_vessel

    side = as_vessel(target, speed, None, rps).rudder_positive
    if side == truth.rudder_positive:
        return pid, None
    return PID(-pid.kp, -pid.ki, -pid.kd), (
        f"the truth's positive rudder turns it to {truth.rudder_positive}, the model's to "
        f"{side}: the model-tuned controller's rudder is mirrored for the truth")


def _oscillatory_note(nm: dict) -> None:
    """Warn where the PID's first-order Nomoto model stands for an oscillatory sway–yaw pair."""
    if nm["oscillatory"]:
        _warn(f"the model's sway–yaw poles are a complex pair (damping ratio "
              f"{nm['damping_ratio']:.3g}): the PID is tuned on its first-order Nomoto "
              "approximation K/(1 + T s), which keeps its low-frequency response only; check the "
              "step on the model")  # fmt: skip


def _tuned(ship, speed, rps, omega):
    from shipid.control.autopilot import pid_from_nomoto
    from shipid.control.linear import nomoto

    nm = nomoto(ship, speed, rps)
    return nm, pid_from_nomoto(nm["K"], nm["T"], omega)


def cmd_linearise(args) -> int:
    """``shipid linearise``: state-space A, B and Nomoto K, T about the straight run."""
    from shipid.control.linear import nomoto

    target, cond = _ship_or_model(args.model)
    speed, rps, unsteady = _run_approach(target, cond, args.speed, args.rps)
    speed = speed or getattr(target, "approach_speed", None)
    if not speed:
        raise ShipidError("give the speed to linearise at (--speed)")
    for note in ([unsteady] if unsteady else []) + _unused_inputs(target, args):
        _warn(note)
    nm = nomoto(target, speed, rps)
    pd = _pd()
    trim = nm["trim"]
    held = ("rudder amidships: no rudder within ±35° holds it straight" if trim is None else
            f"trimmed: δ0 = {math.degrees(trim['delta']):.3g}° and v0 = {trim['v']:.3g} m/s hold "
            "it straight")  # fmt: skip
    # The signs of B and K are the rudder convention's: say which it is.
    side = cond.get("rudder_positive") or getattr(target, "rudder_positive", None)
    convention = f", positive to {side}" if side else ""
    print(f"Linearised about straight running at u = {speed:.4g} m/s, {held} (states u, v, r; "
          f"input δ{convention}; ν̇ ≈ A (ν − ν0) + B (δ − δ0)):")  # fmt: skip
    print("A =")
    print(pd.DataFrame(nm["A"], index=["u", "v", "r"], columns=["u", "v", "r"]).to_markdown(
        floatfmt=".5g"))
    print("B =")
    print(pd.DataFrame({"δ": nm["B"]}, index=["u", "v", "r"]).to_markdown(floatfmt=".5g"))
    print(_nomoto_line(nm))
    if cond.get("envelope"):
        # A model identified from logs (a reference ship's T2 is its published model's).
        from shipid.identification.plausibility import slow_mode_note

        note = slow_mode_note(nm["poles"])
        if note:
            print(f"{note[0].upper()}{note[1:]}.")
    return 0


def _nomoto_line(nm: dict) -> str:
    """Nomoto's parameters in one line; an oscillatory sway–yaw pair with its poles, natural
    frequency and damping ratio in place of the real T1, T2 it does not have."""
    verdict = "stable" if nm["stable"] else "UNSTABLE"
    if not nm["oscillatory"]:
        return (f"Nomoto: K = {nm['K']:.5g} 1/s, T1 = {nm['T1']:.5g} s, T2 = {nm['T2']:.5g} s, "
                f"T3 = {nm['T3']:.5g} s; first order T = T1 + T2 − T3 = {nm['T']:.5g} s; "
                f"{verdict}")  # fmt: skip
    p = nm["poles"][0]
    return (f"Nomoto: K = {nm['K']:.5g} 1/s; the sway–yaw poles are a complex pair, "
            f"{p.real:.4g} ± {abs(p.imag):.4g}i 1/s (natural frequency {nm['natural_frequency']:.4g} "
            f"rad/s, damping ratio {nm['damping_ratio']:.3g}), so T1 and T2 are not real; "
            f"T3 = {nm['T3']:.5g} s; first order T = T1 + T2 − T3 = {nm['T']:.5g} s (T1 + T2 "
            f"= −tr/det, real: the same low-frequency response K/(1 + T s)); {verdict}")  # fmt: skip


def cmd_export(args) -> int:
    """``shipid export``: write the model as a standalone NumPy function file."""
    from shipid.control.export import export_numpy
    from shipid.outputs import check_outputs
    from shipid.reporting.modelfile import load_document, model_from_document, training_conditions

    if Path(args.output).suffix != ".py":
        raise ShipidError(f"-o {args.output}: the exported module must be a .py file")
    check_outputs({"-o": (args.output, "python")},
                  [] if args.model in VESSEL_NAMES else [args.model])  # fmt: skip
    ship = _reference_ship(args.model)
    if ship is not None:  # an MMG ship (the KVLCC2, an MMG file, one corrected)
        from shipid.control.export import export_ship
        from shipid.dynamics.model import ManoeuvringModel

        if isinstance(ship.dynamics, ManoeuvringModel):  # a term model corrected: one model
            export_numpy(ship.dynamics, args.output, ship.rudder_positive)
        else:
            export_ship(ship, args.output)
        print(f"standalone NumPy module of {ship.name} written to {args.output} (accelerations, "
              "derivatives, simulate)")  # fmt: skip
        return 0
    doc = load_document(args.model)
    model = model_from_document(doc, args.model, hybrid=True)
    trained = training_conditions(doc)
    export_numpy(model, args.output, trained["rudder_positive"], trained["dt"])
    print(f"standalone NumPy module written to {args.output} (accelerations, derivatives, "
          "simulate)")  # fmt: skip
    return 0


def _model_inputs(args) -> list:
    """The files autopilot and follow read: the model file (not a reference ship's name) and the
    true ship's, where they are files (``follow m.json --json m.json`` overwrote the model)."""
    names = [getattr(args, key, None) for key in ("model", "truth")]
    return _read_files(args, *(n for n in names if n is not None and Path(n).is_file()))


def cmd_autopilot(args) -> int:
    """``shipid autopilot``: heading step of a PID tuned on the model, run on model and truth."""
    from shipid.control.autopilot import heading_step, heading_step_deg
    from shipid.outputs import check_outputs

    check_outputs({"-o": (args.output, "figure")}, _model_inputs(args))
    # Before the tuning: a step of 400° had turned the ship 40° and read "overshoot −359°".
    step = heading_step_deg(args.heading_step)
    target, truth, speed, rps, steering, cond = _controlled(args)
    nm, pid = _tuned(target, speed, rps, args.omega)
    print(f"PID tuned on {args.model} (Nomoto K = {nm['K']:.4g} 1/s, T = {nm['T']:.4g} s): "
          f"Kp = {pid.kp:.4g}, Ki = {pid.ki:.4g} 1/s, Kd = {pid.kd:.4g} s")
    _oscillatory_note(nm)
    runs = {args.model: heading_step(target, pid, step, args.duration, args.dt,
                                     speed, rps, steering=steering)}  # fmt: skip
    if truth is not None:
        pid_truth, note = _for_truth(pid, target, truth, speed, rps)
        if note:
            print(note)
        runs[f"{args.truth} (truth)"] = heading_step(truth, pid_truth, step,
                                                     args.duration, args.dt)  # fmt: skip
        longest = max(float(log["t"].iloc[-1]) for log in runs.values())
        if args.duration is None and any(log["t"].iloc[-1] < longest for log in runs.values()):
            # One length for both, so that the figure compares them over the same time.
            runs = {args.model: heading_step(target, pid, step, longest, args.dt, speed,
                                             rps, steering=steering),
                    f"{args.truth} (truth)": heading_step(truth, pid_truth, step,
                                                          longest, args.dt)}  # fmt: skip
    _warn_beyond_training(cond, args.model, runs[args.model])
    for name, log in runs.items():
        if log.attrs.get("incomplete") and log.attrs["incomplete"] != "diverged":
            _warn(f"{name}: {log.attrs['incomplete']}; give a longer --duration")
        psi = _np().degrees(log["psi"].to_numpy())
        over = float(psi.max() - step) if step > 0 else float(step - psi.min())
        print(f"{name}: overshoot {over:.3g}°, final heading {psi[-1]:.4g}°, max rudder "
              f"{_np().degrees(log['delta'].abs().max()):.3g}°")
    if args.output:
        from shipid.reporting.plots import autopilot_figure

        autopilot_figure(runs, args.output, f"heading autopilot, step to {step:g}°")
        print(f"figure written to {args.output}")
    return 0


def _parse_waypoints(text: str) -> list[tuple[float, float]]:
    try:
        pts = [tuple(float(x) for x in p.split(",")) for p in text.split(";") if p.strip()]
    except ValueError:
        raise ShipidError(f"--waypoints expects 'x,y;x,y;...' in metres, got {text!r}") from None
    if len(pts) < 2 or any(len(p) != 2 for p in pts):
        raise ShipidError(f"--waypoints expects at least two 'x,y' pairs, got {text!r}")
    if not all(math.isfinite(x) for p in pts for x in p):
        raise ShipidError(f"--waypoints must be finite numbers, got {text!r}")
    for k in range(1, len(pts)):
        if pts[k] == pts[k - 1]:
            raise ShipidError(f"--waypoints: waypoints {k} and {k + 1} are the same point "
                              f"{pts[k][0]:g},{pts[k][1]:g}")  # fmt: skip
    return pts


def cmd_follow(args) -> int:
    """``shipid follow``: line-of-sight path following of waypoints on model and truth."""
    from shipid.control.autopilot import follow_path
    from shipid.outputs import OutputSet, check_outputs

    check_outputs({"-o": (args.output, "figure"), "--json": (args.json, "json")},
                  _model_inputs(args))  # fmt: skip
    waypoints = _parse_waypoints(args.waypoints)  # before the model is loaded and run
    target, truth, speed, rps, steering, cond = _controlled(args)
    # A reference ship's length, else the model file's particulars', else the --truth ship's
    # (the ship the model stands for), else 10 m.
    length, of = getattr(target, "length", None), ""
    if not (length and length == length) and cond.get("particulars") is not None:
        length = cond["particulars"].length
    if not (length and length == length) and truth is not None:
        length, of = truth.length, f" of {truth.name}, the --truth ship: the model file gives none"
    known = bool(length and length == length)
    lookahead = args.lookahead or 2.0 * (length if known else 10.0)
    source = ("given" if args.lookahead else f"2 L{of}" if known
              else "the model file gives no length; --lookahead to set it")
    nm, pid = _tuned(target, speed, rps, args.omega)
    _oscillatory_note(nm)
    runs, rows = {}, []
    cases = [("model", target, pid, speed, rps, steering)]
    if truth is not None:
        _, pid_truth = _tuned(truth, truth.approach_speed, None, args.omega)
        pid_mirrored, note = _for_truth(pid, target, truth, speed, rps)
        if note:
            print(note)
        cases += [("truth, model-tuned PID", truth, pid_mirrored, None, None, None),
                  ("truth, truth-tuned PID", truth, pid_truth, None, None, None)]
    for label, ship, gains, sp, n, gear in cases:
        res = follow_path(ship, gains, waypoints, lookahead, dt=args.dt, speed=sp, rps=n,
                          steering=gear)  # fmt: skip
        runs[label] = res.log
        rows.append({"run": label, "rms cross-track [m]": res.rms_cross_track,
                     "max cross-track [m]": res.max_cross_track, "completed": res.completed,
                     "Kp": gains.kp, "Ki": gains.ki, "Kd": gains.kd})  # fmt: skip
    _warn_beyond_training(cond, args.model, runs["model"])
    table = _pd().DataFrame(rows)
    print(f"Line-of-sight path following (lookahead {lookahead:.3g} m, {source}), PID tuned "
          f"on {args.model}:")
    print(table.to_markdown(index=False, floatfmt=".4g"))
    if truth is not None:
        ratio = rows[1]["rms cross-track [m]"] / rows[2]["rms cross-track [m]"]
        print(f"on the truth, the model-tuned controller's rms cross-track error is {ratio:.3g} × "
              "the truth-tuned one's")
    with OutputSet() as out:
        if args.output:
            from shipid.reporting.plots import tracks_with_waypoints

            tracks_with_waypoints(runs, waypoints, args.output, "path following", out=out)
        if args.json:
            doc = {"waypoints": waypoints, "lookahead": lookahead, "runs": rows}
            out.write(args.json, lambda p: p.write_text(_json_text(doc), "utf-8"))
    return 0
