"""The ``shipid`` command line.

Exit 0 on success, 1 on a user error (one-line message, no traceback, no output file), 2 on a usage
error, 130 when interrupted (Ctrl-C or SIGTERM: temporaries removed, one line). Option values are
checked before any work, and so are output paths: an output that is also an input, an unknown
extension or an unwritable folder is refused before anything is computed. A command's output files
are written together at its end (``shipid.outputs.OutputSet``). Warnings print as ``warning:``
lines on stderr and go into the JSON outputs.
"""

from __future__ import annotations

import argparse
import io
import json
import math
import signal
import sys
import time
import warnings
from functools import partial
from pathlib import Path

from shipid import __version__
from shipid.errors import ShipidError, ShipidWarning
from shipid.outputs import Interrupted, check_stop, clear_stop, request_stop, stop_requested

VESSEL_NAMES = ("scale-ship", "mariner", "kvlcc2")
LINEAR_ESTIMATORS = ("lssvm", "ols", "ridge", "lasso", "svr")
KINDS = ("zigzag", "turning", "other")

# Range checks of numeric options: dest → (rule, option as typed). Rules: '>0', '>=0', 'finite',
# 'int>=N'. Checked before any work; a bad value is a user error (exit 1), not a usage error.
OPTION_RULES = {
    "gamma": (">0", "--gamma"), "dt": (">0", "--dt"), "lead": (">=0", "--lead"),
    "filter": (">0", "--filter"), "segment": (">0", "--segment"),
    "refine_evals": ("int>=1", "--refine-evals"), "rudder_deg": (">0", "--rudder"),
    "heading": (">0", "--heading"), "duration": (">0", "--duration"), "step": (">0", "--dt"),
    "speed": (">0", "--speed"), "rps": ("finite", "--rps"), "smooth": (">=0", "--smooth"),
    "length": (">0", "--length"), "rudder_rate": (">0", "--rudder-rate"),
    "astern_rps": ("finite", "--astern-rps"),
    "scale": (">0", "--scale"), "start": ("finite", "--start"), "end": ("finite", "--end"),
    "wind_speed": (">=0", "--wind-speed"), "wind_from": ("finite", "--wind-from"),
    "max_evaluations": ("int>=1", "--max-evaluations"), "show": ("int>=1", "--show"),
    "max_lag": ("int>=1", "--max-lag"), "omega": (">0", "--omega"),
    "lookahead": (">0", "--lookahead"), "bootstrap": ("int>=10", "--bootstrap"),
    "block": (">0", "--block"), "workers": ("int>=1", "--workers"), "factor": (">0", "--factor"),
    "rho": (">0", "--rho"),
}  # fmt: skip


def _on_sigterm(signum, frame) -> None:
    request_stop()
    raise Interrupted()


def _on_sigint(signum, frame) -> None:
    request_stop()
    raise KeyboardInterrupt()


def _ignore_unraisable(unraisable) -> None:
    """``sys.unraisablehook`` while an interrupt unwinds: finaliser errors are not the user's."""


def _quiet_lost_interrupts(hook):
    """``sys.unraisablehook`` while a command runs: an interrupt raised inside a finaliser is
    dropped by Python; it is recorded (``request_stop``) and acted on, so it is not printed."""

    def unraisable(info) -> None:
        if not isinstance(info.exc_value, KeyboardInterrupt):
            hook(info)

    return unraisable


def check_options(args) -> None:
    """Range checks of the numeric options (``OPTION_RULES``) before any work."""
    for dest, (rule, option) in OPTION_RULES.items():
        value = getattr(args, dest, None)
        if value is None or isinstance(value, str):
            continue
        if rule.startswith("int>="):
            least = int(rule[5:])
            if not value >= least:
                raise ShipidError(f"{option} must be a whole number ≥ {least}, got {value}")
            continue
        if not math.isfinite(value):
            raise ShipidError(f"{option} must be a finite number, got {value}")
        if rule == ">0" and not value > 0:
            raise ShipidError(f"{option} must be > 0, got {value:g}")
        if rule == ">=0" and not value >= 0:
            raise ShipidError(f"{option} must be ≥ 0, got {value:g}")


# ---------------------------------------------------------------------------- shared options
# The readers of shipid.data.formats (kept here so that --help and --version import no pandas;
# a test checks the two agree).
FORMATS = ("canonical", "simman-marin", "simman-hsva", "osaka-frt")


def _add_log_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("log files")
    g.add_argument("--format", default="canonical", choices=FORMATS,
                   help="file format (default: %(default)s CSV/Parquet)")
    g.add_argument("--scale", type=float, metavar="LAMBDA",
                   help="simman-marin: Froude-scale the full-scale data to model scale 1/λ")
    g.add_argument("--columns", metavar="MAP", help="map file columns to canonical names, "
                   "e.g. t=time,delta=rudder_angle")
    g.add_argument("--degrees", metavar="COLS", default="",
                   help="angle columns given in degrees, e.g. delta,psi,r")
    g.add_argument("--dt", type=float, help="resample to this uniform sampling time [s]")
    g.add_argument("--start", type=_time_or_auto, metavar="S|auto",
                   help="trim: first time [s], or 'auto': --lead s before the detected rudder execute")
    g.add_argument("--lead", type=float, default=5.0, metavar="S",
                   help="with --start auto: seconds kept before the execute (default %(default)s)")
    g.add_argument("--end", type=_end_time, metavar="S|auto|dropout",
                   help="trim: last time [s], or 'auto': the end of the manoeuvre (last large rudder, "
                   "propeller still running), or 'dropout': before the first span where the "
                   "ship gains headway with the propeller stopped (its logging dropped out)")
    g.add_argument("--fill-gaps", action="store_true",
                   help="interpolate missing values inside signals (default: refuse the log)")
    g.add_argument("--rudder-positive", choices=("port", "starboard"),
                   help="where a positive rudder angle turns the ship (default: the file's "
                   "metadata, else port as in the paper)")
    g.add_argument("--particulars", metavar="FILE",
                   help="ship particulars (YAML or JSON: length, beam, draught, ...; the MARIN "
                   "ship_data.yml reads as is), kept with the logs and the model")


def _number_or_auto(text: str) -> float | str:
    return _time_or_auto(text)


def _number_or_auto_or_none(text: str) -> float | str:
    if text in ("auto", "none"):
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, 'auto' or 'none', got {text!r}") \
            from None


def _time_or_auto(text: str) -> float | str:
    if text == "auto":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds or 'auto', got {text!r}") from None


def _end_time(text: str) -> float | str:
    return text if text == "dropout" else _time_or_auto(text)


def _read_options(args):
    from shipid.data.io import ReadOptions, parse_column_map

    return ReadOptions(fmt=args.format, columns=parse_column_map(args.columns),
                       degrees=tuple(c.strip() for c in args.degrees.split(",") if c.strip()),
                       dt=args.dt, start=args.start, end=args.end, lead=args.lead,
                       rudder_positive=args.rudder_positive, scale=args.scale,
                       fill_gaps=args.fill_gaps)  # fmt: skip


def _read_logs(args, paths=None) -> list:
    from shipid.data.io import read_log

    options = _read_options(args)
    logs = [read_log(p, options) for p in (paths or args.logs)]
    particulars = _particulars(args)
    if particulars is not None:
        for log in logs:
            log.attrs["particulars"] = particulars.to_dict()
    return logs


def _training_logs(args) -> list:
    """The logs a model is fitted to: ``_read_logs``, refused when they are at different
    scales (a model-scale and a full-scale run fitted together mix two ships' time scales)."""
    logs = _read_logs(args)
    scales = {}
    for path, log in zip(args.logs, logs, strict=True):
        if "scale" in log.attrs:
            scales.setdefault(float(log.attrs["scale"]), str(path))
    if len(scales) > 1:
        (a, pa), (b, pb) = list(scales.items())[:2]
        raise ShipidError(f"{pb} is at scale 1:{b:g} and {pa} at 1:{a:g}: the logs of one fit "
                          "must be at one scale (read the trial files with the same "
                          "--scale)")  # fmt: skip
    return logs


def _particulars(args):
    """The particulars of --particulars (None when not given)."""
    if not getattr(args, "particulars", None):
        return None
    from shipid.data.particulars import read_particulars

    return read_particulars(args.particulars)


def _log_particulars(logs) -> dict | None:
    return next((log.attrs["particulars"] for log in logs if log.attrs.get("particulars")), None)


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


def _physics(args, logs, structure):
    """PhysicsOptions of --prior, --constraints, --bound (None when none is given)."""
    from shipid.identification.physics import PhysicsOptions, parse_constraints, rudder_sign

    signs, steady, stable = parse_constraints(args.constraints)
    bounds = _parse_bounds(args.bound)
    prior = None
    if args.prior == "clarke":
        from shipid.data.particulars import Particulars
        from shipid.identification.priors import clarke_prior

        found = _particulars(args) or _log_particulars(logs)
        if found is None:
            raise ShipidError("--prior clarke needs the ship's particulars (--particulars FILE)")
        part = found if isinstance(found, Particulars) else Particulars.from_mapping(found)
        sign = rudder_sign(logs)
        side = None if sign is None else ("starboard" if sign > 0 else "port")
        speed = _approach(logs[0], "u")
        prior = clarke_prior(part, structure, speed or 0.0, side)
    elif args.prior:
        from shipid.identification.priors import prior_from_model
        from shipid.reporting.modelfile import load_model

        prior = prior_from_model(load_model(args.prior))
    options = PhysicsOptions(prior=prior, signs=signs, bounds=bounds or None, steady_speed=steady,
                             stable=stable)
    return options if options.active else None


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


def _warn(message: str) -> None:
    warnings.warn(message, ShipidWarning, stacklevel=2)


# ---------------------------------------------------------------------------- commands
def cmd_demo(args) -> int:
    """``shipid demo``: the paper's experiment on the embedded scale ship."""
    from shipid.demo import run_demo, summary
    from shipid.outputs import check_outputs

    check_outputs({"--out": (args.out, "dir")})
    t0 = time.perf_counter()
    result = run_demo(args.out, args.seed, progress=lambda m: print(m, file=sys.stderr))
    print(summary(result))
    print(f"figures and report written to {Path(args.out) / 'report.md'} "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0


def _approach(log, column: str) -> float | None:
    from shipid.data.log import approach

    return approach(log, column)


def _warn_approach(logs, names) -> None:
    """Say so when the first log (whose approach the checks and manoeuvres use) starts without
    headway."""
    from shipid.data.log import approach_note

    note = approach_note(logs[0], names[0]) if logs else None
    if note:
        _warn(note)


def _free_run_table(refinement) -> str:
    lines = ["| training log | LS-SVM u / v / r std | refined u / v / r std |", "|---|---|---|"]
    for row in refinement.free_run:
        cells = []
        for key in ("initial", "refined"):
            e = row[key]
            div = " (diverged)" if row[f"{key}_diverged"] else ""
            cells.append(f"{e['u']:.4f} / {e['v']:.4f} / {e['r']:.4f}{div}")
        lines.append(f"| {row['name']} | {cells[0]} | {cells[1]} |")
    return "\n".join(lines)


def _std_errors(ident) -> dict:
    return {d: ident.diagnostics[d].get("std_errors", {}) for d in ident.diagnostics}


def _rudder_rate(logs) -> float | None:
    """The training logs' rudder rate [rad/s] (90th percentile while the rudder moves)."""
    from shipid.trials.trial import describe_trial

    rates = [describe_trial(log).rudder_rate for log in logs]
    rates = [r for r in rates if r]
    return max(rates) if rates else None


def _log_scale(logs) -> float | None:
    """The scale λ of the training logs (their metadata), when they share one."""
    scales = {float(log.attrs["scale"]) for log in logs if "scale" in log.attrs}
    return scales.pop() if len(scales) == 1 and all("scale" in log.attrs for log in logs) \
        else None


def _scale_notes(cond: dict, logs, names) -> list[str]:
    """Logs at another scale than the model's training logs: read with the wrong --scale."""
    trained = cond.get("log_scale")
    out = []
    for log, name in zip(logs, names, strict=True):
        lam = log.attrs.get("scale")
        if trained and lam and abs(lam / trained - 1) > 0.01:
            out.append(f"{name}: this log is at scale 1:{lam:g} and the model's training logs were"
                       f" at 1:{trained:g}: read it with --scale {trained:g} (if its format "
                       f"takes one), or carry the model over with shipid rescale --factor "
                       f"{trained / lam:g}")  # fmt: skip
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


def _fmt_speed(u: float | None) -> str:
    return "none" if u is None else f"{u:.3g} m/s"


def cmd_identify(args) -> int:
    """``shipid identify``: a model from logs (LS-SVM, optional refinement, checks)."""
    from shipid.data.preprocess import lowpass
    from shipid.identification.identify import identify
    from shipid.identification.plausibility import new_failures, plausibility_at_approach
    from shipid.outputs import atomic_write_text, check_outputs
    from shipid.reporting.modelfile import model_text

    check_outputs({"-o": (args.output, "json")}, args.logs)
    if args.bootstrap is not None and args.refine:
        raise ShipidError("--bootstrap describes the LS-SVM fit; it does not go with --refine")
    if args.output_error and (args.refine or args.bootstrap is not None):
        raise ShipidError("--output-error is its own fit with its own intervals; it does not go "
                          "with --refine or --bootstrap")  # fmt: skip
    if args.error_band is not None and (args.refine or args.output_error):
        raise ShipidError("--error-band describes the LS-SVM fit; it does not go with --refine "
                          "or --output-error")  # fmt: skip
    logs = _training_logs(args)
    raw_logs = logs  # the output-error fit needs the noise as measured, not prefiltered
    names = [str(p) for p in args.logs]
    physics = _physics(args, logs, _structure(args))
    cutoff, filter_by = args.filter, "given"
    if cutoff == "auto":
        from shipid.identification.prefilter import choose_prefilter

        def fit(candidate_logs):
            return identify(candidate_logs, model=args.model, form=args.form,
                            gamma=1e4 if args.gamma == "auto" else args.gamma,
                            drop=_parse_drop(args.drop), names=names, force=True,
                            estimator=args.estimator, physics=physics).model  # fmt: skip

        cutoff, table = choose_prefilter(logs, fit)
        filter_by = "free-run error, one-standard-error rule"
        shown = "none" if cutoff is None else f"{cutoff:.4g} Hz"
        print(f"prefilter of u, v, r: {shown} (chosen by the free-run error on the logs; "
              "--filter HZ|none to set it)")  # fmt: skip
    elif cutoff == "none":
        cutoff = None
    if cutoff is not None:
        logs = [lowpass(log, cutoff) for log in logs]
    gamma, gamma_report = args.gamma, None
    if gamma == "auto":
        gamma, gamma_report = _auto_gamma(args, logs, names, physics)
    ident = identify(logs, model=args.model, form=args.form, gamma=gamma,
                     drop=_parse_drop(args.drop), names=names, force=args.force,
                     estimator=args.estimator, physics=physics)  # fmt: skip
    speed, rps = _approach(logs[0], "u"), _approach(logs[0], "n")
    _warn_approach(logs, names)
    prep = {"dt": args.dt, "start": args.start, "end": args.end, "lead": args.lead,
            "filter_hz": cutoff, "filter_by": filter_by if cutoff is not None else None,
            "columns": args.columns, "degrees": args.degrees,
            "format": args.format, "scale": args.scale,
            "approach_speed": speed, "approach_rps": rps, "rudder_rate": _rudder_rate(logs),
            "rudder_positive": logs[0].attrs.get("rudder_positive"),
            "log_scale": _log_scale(logs)}  # fmt: skip
    refinement = None
    print(ident.model.equations(std_errors=_std_errors(ident)))
    print("(± standard errors of the equation-error fit: they hold the scatter of the fitted "
          "accelerations, not the bias that noise in u, v, r leaves in the coefficients; "
          "--output-error gives intervals that hold the true values, --bootstrap N intervals "
          "of the predictions)")  # fmt: skip
    for dof, d in ident.diagnostics.items():
        print(f"{dof}: condition number {d['condition_number']:.3g}, one-step R² "
              f"{d['one_step_r2']:.4f}, bias b = {ident.discrete[dof]['bias']:.4g}")
    band = None
    if args.error_band is not None:
        from shipid.evaluation.error_band import cross_validated_band

        def refit_without(train):  # the same prefilter, structure, γ and physics
            return identify([lowpass(x, cutoff) for x in train] if cutoff is not None else train,
                            model=args.model, form=args.form, gamma=gamma,
                            drop=_parse_drop(args.drop), force=True, estimator=args.estimator,
                            physics=physics).model  # fmt: skip

        band = cross_validated_band(refit_without, raw_logs, names, args.error_band)
        print(f"{band.describe()} (γ and the prefilter as chosen on all logs); stored for "
              "validate")  # fmt: skip
    ensemble = None
    if args.bootstrap is not None:
        from shipid.identification.identify import weighted_refit
        from shipid.identification.uncertainty import bootstrap

        refit = weighted_refit(logs, model=args.model, form=args.form, gamma=gamma,
                               drop=_parse_drop(args.drop), names=names,
                               estimator=args.estimator, physics=physics)  # fmt: skip
        ensemble = bootstrap(logs, refit, args.bootstrap, args.block, args.seed, progress=True)
        table = ensemble.coefficient_table()
        table["term"] = [_term_display(t) for t in table["term"]]
        print(f"\n95 % intervals of the coefficients ({ensemble.method}, "
              f"{ensemble.replicates} replicates, {ensemble.block_s:g} s blocks):")
        print(table.to_markdown(index=False, floatfmt=".4g"))
    if args.refine:
        from shipid.identification.refine import refine  # scipy.optimize: only when asked

        how = "whole logs" if args.segment is None else f"{args.segment:g} s segments"
        print(f"refining by output error ({how})…", file=sys.stderr)
        refinement = refine(ident.model, logs, segment_s=args.segment, gamma=gamma,
                            max_nfev=args.refine_evals, names=names, progress=True)  # fmt: skip
        print()
        print("refined by output error:")
        print(refinement.model.equations())
        print(f"cost {refinement.cost_initial:.4g} → {refinement.cost_final:.4g} in "
              f"{refinement.nfev} evaluations ({refinement.message})")
        print(_free_run_table(refinement))
    if args.output_error:
        refinement, ensemble = _output_error(ident, raw_logs, names, args)
    final = ident.model
    if speed is None or not speed > 0:
        raise ShipidError(f"{names[0]}: the first training log starts without headway (u = "
                          f"{speed}); trim it to the manoeuvre (--start)")  # fmt: skip
    plausibility, notes = plausibility_at_approach(ident.model, speed, rps)
    if refinement:
        refined_report, refined_notes = plausibility_at_approach(refinement.model, speed, rps)
        worse = new_failures(plausibility, refined_report, ident.model)
        if worse:
            # Never hand out a model that fails checks the LS-SVM model passes, or fails worse.
            ident.warnings.append(
                "refinement: the refined model fails plausibility checks the LS-SVM model passes ("
                + "; ".join(worse[:2]) + "); the model file's model is the LS-SVM one, the "
                "refined one is kept under identification.refinement.refined_model")
            if args.output_error:
                ensemble = None  # its draws describe the output-error model, not this one
        else:
            final, plausibility, notes = refinement.model, refined_report, refined_notes
    sl = plausibility["straight_line"]
    if sl:
        print(f"straight-line {'stable' if sl['stable'] else 'UNSTABLE'} (largest sway–yaw "
              f"eigenvalue real part {sl['max_real_part']:.3g} 1/s); surge equilibrium "
              f"{_fmt_speed(plausibility['surge_equilibrium'])}; checked from the "
              f"{plausibility['approach']}")  # fmt: skip
    ident.warnings.extend(f"plausibility: {n}" for n in notes)
    if refinement:
        ident.warnings.extend(f"refinement: {n}" for n in refinement.warnings)
    text = model_text(ident, args.logs, preprocessing=prep, refinement=refinement,
                      plausibility=plausibility, model=final, selection=gamma_report,
                      particulars=_log_particulars(logs),
                      uncertainty=ensemble.to_dict() if ensemble else None,
                      error_band=band.to_dict() if band else None)  # fmt: skip
    from shipid.reporting.modelfile import prime_record

    _print_prime(prime_record(final, _log_particulars(logs), speed))
    atomic_write_text(args.output, text)
    for w in ident.warnings:
        _warn(w)
    print(f"model written to {args.output}")
    return 0


def _output_error(ident, logs, names, args):
    """``identify --output-error``: the maximum-likelihood output-error fit from the LS-SVM model,
    printed with its standard errors and intervals; returns the fit and its ensemble."""
    from shipid.identification.output_error import coefficient_intervals, output_error

    print("fitting by maximum-likelihood output error (unfiltered logs)…", file=sys.stderr)
    fit, ensemble = output_error(ident.model, logs, max_nfev=args.refine_evals, names=names,
                                 seed=args.seed)  # fmt: skip
    st = fit.statistics
    print("\nmaximum-likelihood output error (± standard error):")
    print(fit.model.equations(std_errors=st["standard_errors"]))
    noise = ", ".join(f"{s} {v:.3g}" for s, v in st["noise"].items())
    print(f"measurement noise from the residuals: {noise}; cost {fit.cost_initial:.4g} → "
          f"{fit.cost_final:.4g} in {fit.nfev} evaluations; covariance inflation for residual "
          f"correlation ×{st['covariance_inflation']:.3g}")  # fmt: skip
    table = coefficient_intervals(fit)
    table["term"] = [_term_display(t) for t in table["term"]]
    print(f"\n{st['level'] * 100:g} % intervals of the coefficients (estimate ± 1.96 standard "
          "errors; the LS-SVM start beside them):")  # fmt: skip
    print(table.to_markdown(index=False, floatfmt=".4g"))
    print(_free_run_table(fit))
    return fit, ensemble


def _print_prime(record: dict | None) -> None:
    """The prime (non-dimensional) coefficients next to the dimensional ones."""
    if not record:
        return
    print(f"\nPrime form (L = {record['length']:g} m, U = {record['speed']:.4g} m/s, the "
          f"{record['speed_basis']}; ρ = {record['rho']:g} kg/m³; u̇′ = u̇ L/U², ṙ′ = ṙ L²/U²):")
    rows = [{"equation": f"{dof}̇′", "term": _term_display(t), "prime": c}
            for dof, terms in record["coefficients"].items() for t, c in terms.items()]
    print(_pd().DataFrame(rows).to_markdown(index=False, floatfmt=".5g"))


def _structure(args):
    """The structure of --model without the --drop terms."""
    from shipid.dynamics.model import get_structure

    try:
        structure = get_structure(args.model)
        drop = _parse_drop(args.drop)
        return structure.without(drop) if drop else structure
    except ValueError as exc:
        raise ShipidError(str(exc)) from None


def _auto_gamma(args, logs, names, physics=None) -> tuple[float, dict]:
    """γ for the given structure: exact LOO of the LS-SVM pre-screens the grid, free-run
    cross-validation over the logs decides (``shipid.identification.select``)."""
    from shipid.identification.select import select

    structure = _structure(args)
    cv = args.cv or ("logo" if len(logs) >= 2 else "blocks:4")
    sel = select(logs, library=structure, search="none", names=names, cv=cv,
                 estimator=args.estimator, plausibility=False, physics=physics)  # fmt: skip
    table = sel.candidates[["gamma", "score", "score_se", "folds_diverged"]]
    print(f"γ chosen by free-run cross-validation ({cv}): {sel.gamma:g}")
    print(table.to_markdown(index=False, floatfmt=".4g"))
    print()
    return sel.gamma, {"gamma_by": "free-run CV", **sel.to_dict()}


def _parse_gammas(text: str | None) -> tuple[float, ...] | None:
    if not text:
        return None
    try:
        return tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise ShipidError(f"--gammas expects numbers separated by commas, got {text!r}") from None


def cmd_select(args) -> int:
    """``shipid select``: structure and γ by cross-validated free-run error."""
    from shipid.identification.select import RESAMPLES, SelectOptions, select
    from shipid.outputs import OutputSet, check_outputs
    from shipid.reporting.modelfile import model_text

    check_outputs({"-o": (args.output, "json"), "--table": (args.table, "log")}, args.logs)
    logs = _training_logs(args)
    names = [str(p) for p in args.logs]
    from shipid.dynamics.model import get_structure
    from shipid.identification.select import default_library

    try:
        library = (get_structure(args.library) if args.library is not None
                   else default_library(logs)[0])  # fmt: skip
    except ValueError as exc:
        raise ShipidError(str(exc)) from None
    # The default library is passed as None: select trims it to the logs and says so.
    options = SelectOptions(library=library if args.library is not None else None,
                            search=args.search, cv=args.cv,
                            estimator=args.estimator, method=args.method,
                            max_evaluations=args.max_evaluations,
                            plausibility=not args.no_plausibility, speed=args.speed,
                            rps=args.rps, one_standard_error=not args.best,
                            progress=not args.quiet, physics=_physics(args, logs, library),
                            average=args.average,
                            **({"gammas": _parse_gammas(args.gammas)} if args.gammas else {}))
    sel = select(logs, options, names=names)
    ident = sel.identification
    if sel.model is not sel.chosen_model:
        print(f"The chosen candidate:\n{sel.chosen_model.equations()}\n\nThe model written, "
              f"the average of {len(sel.shares)} candidates weighted by how often the choice "
              "rule picks them on resampled held-out logs (--average):")  # fmt: skip
    print(sel.model.equations())
    whose = " of the chosen candidate" if sel.model is not sel.chosen_model else ""
    print(f"\nγ = {sel.gamma:g}; free-run CV score{whose} {sel.score:.4f} ({options.cv}; 1 ≈ "
          f"predicting the mean); {len(sel.candidates)} candidates")
    cols = ["chosen", "score", "score_se", "score_u", "score_v", "score_r", "gamma", "n_terms",
            "folds_diverged", "plausible", "share", "stage", "note"]
    shown = sel.candidates.head(args.show)
    if not shown["chosen"].any():
        shown = _pd().concat([shown, sel.candidates[sel.candidates["chosen"]]])
    print(shown[cols].to_markdown(index=False, floatfmt=".4g"))
    fitted = "the average" if sel.model is not sel.chosen_model else "the chosen structure"
    print(f"\nHeld-out logs ({fitted} fitted without each):")
    print(_fold_table(sel.folds))
    if sel.error_band is not None:
        print(f"Their {sel.error_band.describe()}; stored in the model file, validate reports "
              "each log's share of samples inside it.")  # fmt: skip
    speed, rps = _approach(logs[0], "u"), _approach(logs[0], "n")
    _warn_approach(logs, names)
    plausibility, notes = sel.plausibility, sel.plausibility_notes
    ident.warnings.extend(f"plausibility: {n}" for n in notes)
    prep = {"dt": args.dt, "start": args.start, "end": args.end, "lead": args.lead,
            "columns": args.columns, "degrees": args.degrees, "format": args.format,
            "scale": args.scale, "approach_speed": speed, "approach_rps": rps,
            "rudder_rate": _rudder_rate(logs),
            "rudder_positive": logs[0].attrs.get("rudder_positive"),
            "log_scale": _log_scale(logs)}  # fmt: skip
    ensemble = None
    others = len(sel.shares) - (sel.chosen_share > 0)
    print(f"\nThe choice on {RESAMPLES} resamples of the held-out logs: this candidate "
          f"{100 * sel.chosen_share:.0f} %, {others} other(s) the rest (column share)")
    if args.bootstrap is not None:
        from shipid.identification.selection_ensemble import selection_ensemble

        # Each replicate: a candidate drawn by its share, refitted on a block resample.
        ensemble = selection_ensemble(logs, sel, args.bootstrap, args.block, args.seed,
                                      names=names, progress=not args.quiet)  # fmt: skip
        table = ensemble.coefficient_table()
        table["term"] = [_term_display(t) for t in table["term"]]
        print(f"\n95 % intervals of the coefficients ({ensemble.replicates} replicates: "
              f"{ensemble.method}, {ensemble.block_s:g} s blocks; a term outside the model "
              "has value 0, inclusion the share of replicates that hold it):")  # fmt: skip
        print(table.to_markdown(index=False, floatfmt=".4g"))
    text = model_text(ident, args.logs, preprocessing=prep, plausibility=plausibility,
                      model=sel.model, selection=sel.to_dict(), particulars=_log_particulars(logs),
                      uncertainty=ensemble.to_dict() if ensemble else None)  # fmt: skip
    with OutputSet() as out:
        out.write(args.output, lambda p: p.write_text(text, encoding="utf-8"))
        if args.table:
            from shipid.data.io import write_table

            write_table(sel.candidates, args.table, out)
    for w in sel.warnings:
        _warn(w)
    print(f"model written to {args.output}")
    return 0


def _pd():
    import pandas as pd

    return pd


def _fold_table(folds) -> str:
    pd = _pd()

    rows = []
    for f in folds:
        if "error" in f:
            rows.append({"held-out log": f["held_out"], "error": f["error"]})
            continue
        m, sp = f["metrics"], f["spread"]
        ind = (f.get("indices") or {})
        meas = ind.get("measured", {})
        # Zig-zags: the closed-loop run of the trial on the model, not the open-loop replay.
        sim = ind.get("closed_loop") or {} if f.get("kind") == "zigzag" else ind.get("simulated", {})
        key = "tactical_diameter" if f.get("kind") == "turning" else "first_overshoot_deg"
        rows.append({"held-out log": Path(f["held_out"]).name, "kind": f.get("kind"),
                     "u err / spread": f"{m['u']:.4f} / {sp['u']:.4f}",
                     "v err / spread": f"{m['v']:.4f} / {sp['v']:.4f}",
                     "r err / spread": f"{m['r']:.4f} / {sp['r']:.4f}",
                     "diverged": f["diverged"],
                     key.replace("_", " ") + " meas / pred": (
                         f"{meas.get(key):.3g} / {sim.get(key):.3g}"
                         if meas.get(key) is not None and sim.get(key) is not None else "–")})
    return pd.DataFrame(rows).to_markdown(index=False)


def cmd_compare(args) -> int:
    """``shipid compare``: methods × held-out logs in one table."""
    from shipid.evaluation.compare import compare, summary
    from shipid.outputs import OutputSet, check_outputs

    check_outputs({"--json": (args.json, "json")}, args.logs)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    logs = _training_logs(args)
    names = [Path(p).name for p in args.logs]
    table = compare(logs, args.model, methods, names, gamma=args.gamma, cv=args.cv,
                    method=args.method, progress=not args.quiet)  # fmt: skip
    print(f"Free-run score per held-out log ({args.cv}; error RMS over the log's spread, mean of "
          "u, v, r; 1 ≈ predicting the mean), model structure " + str(args.model) + ":")
    print(summary(table).to_markdown(floatfmt=".3f"))
    with OutputSet() as out:
        if args.json:
            doc = {"structure": args.model, "cv": args.cv, "gamma": args.gamma,
                   "rows": table.to_dict(orient="records")}  # fmt: skip
            out.write(args.json, lambda p: p.write_text(_json_text(doc), "utf-8"))
    return 0


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


def cmd_study(args) -> int:
    """``shipid study``: a Monte Carlo study, or the identification of many log sets, on Dask."""
    from shipid.data.io import write_table
    from shipid.evaluation.study import GRID_KEYS, read_spec, run_study, summary
    from shipid.outputs import OutputSet, check_outputs

    check_outputs({"-o": (args.output, "log")}, [args.spec])
    spec = read_spec(args.spec)
    where = ("this process" if args.scheduler == "serial" else args.scheduler
             or f"a local Dask cluster of {args.workers or _cores()} workers")  # fmt: skip
    if hasattr(spec, "jobs"):
        return _study_logs(args, spec, where)
    if args.models:
        raise ShipidError("--models is for a study of kind logs (model files of its jobs)")
    n = len(spec.trials())
    print(f"{n} trials ({len(spec.seeds)} seeds × {n // len(spec.seeds)} grid points) on {where}")
    start = time.perf_counter()
    results = run_study(spec, scheduler=args.scheduler, workers=args.workers,
                        progress=not args.quiet)  # fmt: skip
    wall = time.perf_counter() - start
    print("Held-out error std of the identified model over the true model's on the same noisy "
          "log (1 = as good as the truth):")  # fmt: skip
    table = summary(results)
    varying = [k for k in GRID_KEYS if table[k].nunique() > 1]
    fixed = ", ".join(f"{k} {table[k].iloc[0]:g}" if isinstance(table[k].iloc[0], float)
                      else f"{k} {table[k].iloc[0]}" for k in GRID_KEYS if k not in varying)
    print(f"({fixed}; per held-out manoeuvre: the median over the seeds and the largest)")
    table.index = [", ".join(f"{k} {row[k]}" for k in varying) or "all"
                   for _, row in table.iterrows()]  # fmt: skip
    print(table.drop(columns=list(GRID_KEYS)).T.to_markdown(floatfmt=".3g"))
    print(f"\n{n} trials in {wall:.1f} s wall ({results['seconds'].sum():.1f} s of trial time)")
    with OutputSet() as out:
        write_table(results, args.output, out)
    failed = results[results["error"] != ""]
    if len(failed):
        _warn(f"{len(failed)} of {n} trials failed (first: seed {failed['seed'].iloc[0]}: "
              f"{failed['error'].iloc[0]}); their rows have the error")  # fmt: skip
    print(f"results written to {args.output}")
    return 0


def _study_logs(args, spec, where: str) -> int:
    """A study of kind logs: every job's model file into --models, the table to -o."""
    from shipid.data.io import write_table
    from shipid.identification.batch import run_batch
    from shipid.outputs import OutputSet, check_outputs

    if not args.models:
        raise ShipidError(f"{args.spec}: a study of kind logs writes model files: give --models DIR")
    inputs = [args.spec, *(p for job in spec.jobs for p in job.logs)]
    check_outputs({"-o": (args.output, "log"), "--models": (args.models, "dir")}, inputs)
    print(f"{len(spec.jobs)} jobs ({sum(len(j.logs) for j in spec.jobs)} logs) on {where}")
    start = time.perf_counter()
    table, texts = run_batch(spec, scheduler=args.scheduler, workers=args.workers,
                             progress=not args.quiet)  # fmt: skip
    cols = ["name", "command", "logs", "terms", "gamma", "prefilter_hz", "cv_score", "seconds",
            "error"]
    print(table[[c for c in cols if c in table]].to_markdown(index=False, floatfmt=".4g"))
    print(f"\n{len(spec.jobs)} jobs in {time.perf_counter() - start:.1f} s wall")
    models = Path(args.models)
    with OutputSet() as out:
        for name, text in texts.items():
            out.write(models / f"{name}.json", lambda p, t=text: p.write_text(t, encoding="utf-8"))
        write_table(table, args.output, out)
    failed = table[table["error"] != ""]
    print(f"{len(texts)} model files written to {models}, the table to {args.output}")
    for _, row in failed.iterrows():  # as validate's batch: the others are written, exit 1
        print(f"shipid: error: job {row['name']}: {row['error']}", file=sys.stderr)
    return 1 if len(failed) else 0


def _cores() -> int:
    import os

    return os.cpu_count() or 1


def cmd_criteria(args) -> int:
    """``shipid criteria``: the IMO MSC.137(76) criteria of a model or vessel."""

    from shipid.data.particulars import read_particulars
    from shipid.outputs import OutputSet, check_outputs
    from shipid.trials.criteria import imo_criteria

    check_outputs({"--json": (args.json, "json")},
                  [args.model] if Path(args.model).exists() else [])  # fmt: skip
    target, cond = _ship_or_model(args.model)
    particulars = read_particulars(args.particulars) if args.particulars else cond["particulars"]
    speed, rps, _ = _run_approach(target, cond, args.speed, args.rps)  # imo_criteria notes it
    # Given, else the ship's gear or the training logs' rate, else imo_criteria's SOLAS rate.
    steering, _ = _steering(target, cond, args.rudder_rate, fallback="caller")
    run = partial(imo_criteria, particulars=particulars, length=args.length, speed=speed,
                  scale=args.scale, rps=rps, steering=steering, astern_rps=args.astern_rps,
                  dt=args.dt)  # fmt: skip
    crit = run(target)
    table = crit.table.copy()
    ensemble = cond.get("ensemble")
    if ensemble is not None and not args.no_bands:
        from shipid.trials.criteria import replicate_notes, with_intervals

        replicates = [run(m) for m in ensemble.members()]
        table = with_intervals(crit, replicates)
        crit.notes += replicate_notes(table, replicates, ensemble.members_label)
    c = crit.conditions
    print(f"IMO MSC.137(76) criteria for {args.model}: L = {c['length']:g} m, V = {c['speed']:.4g} "
          f"m/s, λ = {c['scale']:g} (full-scale L/V = {c['L_over_V_full_scale']:.3g} s), " + (
              f"rudder rate {c['rudder_rate_deg_s']:.3g} °/s" if c["rudder_rate_deg_s"]
              else "instantaneous rudder"))
    record = {**crit.to_dict(), "criteria": table.to_dict(orient="records")}
    table["passed"] = table["passed"].map({True: "pass", False: "FAIL", None: "–"})
    print(table.to_markdown(index=False, floatfmt=".3g"))
    if "pass_share" in table:
        print(f"lower, upper: 95 % interval of the value, pass_share: the share of passes, "
              f"no_value: how many have none, over the model's {ensemble.replicates} "
              f"{ensemble.members_label} (more than 2.5 % without a value: not bounded)")
    print("all criteria met" if crit.passed else "NOT all criteria met")
    for n in crit.notes:
        _warn(n)
    with OutputSet() as out:
        if args.json:
            out.write(args.json, lambda p: p.write_text(_json_text(record), "utf-8"))
    return 0


def _controlled(args):
    """The model (or vessel) to control, the truth to test on, speed and rps."""
    from shipid.vessels import get_vessel

    target, cond = _ship_or_model(args.model)
    speed, rps, unsteady = _run_approach(target, cond, args.speed, args.rps)
    if unsteady:
        _warn(unsteady)
    speed = speed or getattr(target, "approach_speed", None)
    truth = get_vessel(args.truth) if args.truth else None
    if truth is not None and args.truth not in VESSEL_NAMES:
        raise ShipidError(f"--truth must be a reference ship ({', '.join(VESSEL_NAMES)})")
    steering, note = _steering(target, cond, args.rudder_rate)
    print(f"{args.model}: {note}")
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
    if unsteady:
        _warn(unsteady)
    nm = nomoto(target, speed, rps)
    pd = _pd()
    print(f"Linearised about straight running at u = {speed:.4g} m/s (states u, v, r; input δ):")
    print("A =")
    print(pd.DataFrame(nm["A"], index=["u", "v", "r"], columns=["u", "v", "r"]).to_markdown(
        floatfmt=".5g"))
    print("B =")
    print(pd.DataFrame({"δ": nm["B"]}, index=["u", "v", "r"]).to_markdown(floatfmt=".5g"))
    print(f"Nomoto: K = {nm['K']:.5g} 1/s, T1 = {nm['T1']:.5g} s, T2 = {nm['T2']:.5g} s, "
          f"T3 = {nm['T3']:.5g} s; first order T = T1 + T2 − T3 = {nm['T']:.5g} s; "
          f"{'stable' if nm['stable'] else 'UNSTABLE'}")  # fmt: skip
    return 0


def cmd_export(args) -> int:
    """``shipid export``: write the model as a standalone NumPy function file."""
    from shipid.control.export import export_numpy
    from shipid.outputs import check_outputs
    from shipid.reporting.modelfile import load_model

    if Path(args.output).suffix != ".py":
        raise ShipidError(f"-o {args.output}: the exported module must be a .py file")
    check_outputs({"-o": (args.output, "python")}, [args.model])
    model = load_model(args.model)
    export_numpy(model, args.output)
    print(f"standalone NumPy module written to {args.output} (accelerations, derivatives, "
          "simulate)")  # fmt: skip
    return 0


def cmd_autopilot(args) -> int:
    """``shipid autopilot``: heading step of a PID tuned on the model, run on model and truth."""
    from shipid.control.autopilot import heading_step
    from shipid.outputs import check_outputs

    check_outputs({"-o": (args.output, "figure")}, [])
    target, truth, speed, rps, steering, cond = _controlled(args)
    nm, pid = _tuned(target, speed, rps, args.omega)
    print(f"PID tuned on {args.model} (Nomoto K = {nm['K']:.4g} 1/s, T = {nm['T']:.4g} s): "
          f"Kp = {pid.kp:.4g}, Ki = {pid.ki:.4g} 1/s, Kd = {pid.kd:.4g} s")
    runs = {args.model: heading_step(target, pid, args.heading, args.duration, args.dt,
                                     speed, rps, steering=steering)}  # fmt: skip
    if truth is not None:
        pid_truth, note = _for_truth(pid, target, truth, speed, rps)
        if note:
            print(note)
        runs[f"{args.truth} (truth)"] = heading_step(truth, pid_truth, args.heading,
                                                     args.duration, args.dt)  # fmt: skip
        longest = max(float(log["t"].iloc[-1]) for log in runs.values())
        if args.duration is None and any(log["t"].iloc[-1] < longest for log in runs.values()):
            # One length for both, so that the figure compares them over the same time.
            runs = {args.model: heading_step(target, pid, args.heading, longest, args.dt, speed,
                                             rps, steering=steering),
                    f"{args.truth} (truth)": heading_step(truth, pid_truth, args.heading,
                                                          longest, args.dt)}  # fmt: skip
    for name, log in runs.items():
        if log.attrs.get("incomplete") and log.attrs["incomplete"] != "diverged":
            _warn(f"{name}: {log.attrs['incomplete']}; give a longer --duration")
        psi = _np().degrees(log["psi"].to_numpy())
        over = float(psi.max() - args.heading) if args.heading > 0 else float(args.heading - psi.min())
        print(f"{name}: overshoot {over:.3g}°, final heading {psi[-1]:.4g}°, max rudder "
              f"{_np().degrees(log['delta'].abs().max()):.3g}°")
    if args.output:
        from shipid.reporting.plots import autopilot_figure

        autopilot_figure(runs, args.output, f"heading autopilot, step to {args.heading:g}°")
        print(f"figure written to {args.output}")
    return 0


def _parse_waypoints(text: str) -> list[tuple[float, float]]:
    try:
        pts = [tuple(float(x) for x in p.split(",")) for p in text.split(";") if p.strip()]
    except ValueError:
        raise ShipidError(f"--waypoints expects 'x,y;x,y;...' in metres, got {text!r}") from None
    if len(pts) < 2 or any(len(p) != 2 for p in pts):
        raise ShipidError(f"--waypoints expects at least two 'x,y' pairs, got {text!r}")
    return pts


def cmd_follow(args) -> int:
    """``shipid follow``: line-of-sight path following of waypoints on model and truth."""
    from shipid.control.autopilot import follow_path
    from shipid.outputs import OutputSet, check_outputs

    check_outputs({"-o": (args.output, "figure"), "--json": (args.json, "json")}, [])
    target, truth, speed, rps, steering, cond = _controlled(args)
    waypoints = _parse_waypoints(args.waypoints)
    # A reference ship's length, else the model file's particulars', else 10 m.
    length = getattr(target, "length", None)
    if not (length and length == length) and cond.get("particulars") is not None:
        length = cond["particulars"].length
    lookahead = args.lookahead or 2.0 * (length if length and length == length else 10.0)
    nm, pid = _tuned(target, speed, rps, args.omega)
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
    table = _pd().DataFrame(rows)
    print(f"Line-of-sight path following (lookahead {lookahead:.3g} m), PID tuned on "
          f"{args.model}:")
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


def _np():
    import numpy as np

    return np


def _unique_figure_names(names: list[str]) -> list[str]:
    """File stems for figures of logs that may share a file name: a, a-2, a-3, ..."""
    out, used = [], {}
    for n in names:
        stem = Path(n).stem or "log"
        used[stem] = used.get(stem, 0) + 1
        out.append(stem if used[stem] == 1 else f"{stem}-{used[stem]}")
    return out


def cmd_validate(args) -> int:
    """``shipid validate``: free runs on logs, metrics, indices, figures, report."""
    from shipid.evaluation.envelope import outside_envelope
    from shipid.evaluation.validate import validate
    from shipid.outputs import OutputSet, check_outputs
    from shipid.reporting.modelfile import (
        ensemble_from_document,
        error_band_from_document,
        has_refinement,
        load_document,
        model_from_document,
        training_conditions,
    )
    from shipid.reporting.report import indices_frame, metrics_frame

    check_outputs({"--json": (args.json, "json"), "--plots": (args.plots, "dir"),
                   "--report": (args.report, "dir")}, [args.model, *args.logs])  # fmt: skip
    doc = load_document(args.model)
    if args.lssvm and not has_refinement(doc):
        _warn(f"{args.model} has no refinement: its model is the LS-SVM one, which --lssvm "
              "validates")  # fmt: skip
    model = model_from_document(doc, args.model, "lssvm" if args.lssvm else "model")
    ensemble = None if args.no_bands else ensemble_from_document(doc, args.model, model)
    band = None if args.no_bands or args.lssvm else error_band_from_document(doc, args.model)
    cond = training_conditions(doc)
    env = cond["envelope"]
    from shipid.data.io import read_log
    from shipid.data.log import common_rudder_convention

    options = _read_options(args)
    logs, names, failed = [], [], []
    for p in args.logs:
        try:
            logs.append(read_log(p, options))
            names.append(str(p))
        except ShipidError as exc:
            failed.append(str(exc))
    if cond["rudder_positive"]:  # a file that does not say its convention: no guess
        logs, notes = common_rudder_convention(logs, cond["rudder_positive"])
        for note in notes:
            _warn(note)
    for note in _scale_notes(cond, logs, names) + _sampling_notes(cond, logs, names):
        _warn(note)
    from tqdm.auto import tqdm

    vals = [validate(model, log, [name], method=args.method, kind=args.kind,
                     smooth_s=args.smooth, ensemble=ensemble, error_band=band)[0]
            for log, name in tqdm(list(zip(logs, names, strict=True)), desc="logs", unit="log",
                                  disable=args.quiet or len(logs) < 3)]  # fmt: skip
    for v, log in zip(vals, logs, strict=True):
        if v.error is None:
            v.warnings.extend(outside_envelope(env, log))
    good = [v for v in vals if v.error is None]
    if good:
        if band is not None:
            print(f"The model's {band.describe()}: a log like those is inside it for about "
                  f"{100 * band.level:g} % of its samples (columns 'in CV band').")  # fmt: skip
        print(metrics_frame(good).to_markdown(index=False, floatfmt=".4g"))
        table = indices_frame(good)
        if len(table):
            # Mixed columns (numbers and blanks) are objects, which floatfmt leaves alone.
            table = table.map(lambda x: f"{x:.4g}" if isinstance(x, float) and x == x else x)
            table = table.astype(object).where(table.notna(), "–")
            print()
            print(table.to_markdown(index=False, floatfmt=".4g"))
    residuals = {}
    if args.resid or args.report:
        from shipid.evaluation.metrics import residual_correlations

        for v, log in zip(vals, logs, strict=True):
            if v.error is None:
                n = len(v.simulation.log)
                residuals[v.name] = {s: residual_correlations(
                    log[s].to_numpy()[:n], v.simulation.log[s].to_numpy(),
                    log["delta"].to_numpy()[:n], args.max_lag) for s in ("u", "v", "r")}
    if args.resid and residuals:
        rows = [{"log": Path(name).name, **{f"{s} autocorr. outside band": a[s]["auto_outside"]
                                            for s in ("u", "v", "r")},
                 **{f"{s} corr. with δ outside band": a[s]["cross_outside"]
                    for s in ("u", "v", "r")}} for name, a in residuals.items()]  # fmt: skip
        print("\nResidual analysis of the free-run errors (share of lags outside the 95 % band "
              "of white noise; ≈ 0.05 when the error is white and independent of the rudder):")
        print(_pd().DataFrame(rows).to_markdown(index=False, floatfmt=".2f"))
    particulars = _particulars(args) or training_conditions(doc)["particulars"]
    crit = None
    if particulars is not None:
        crit = _criteria_of_logs(good, logs, vals, particulars)
        if crit is not None:
            print("\nIMO criteria of the logs that are standard manoeuvres (measured, predicted):")
            print(crit.to_markdown(index=False, floatfmt=".3g"))
    for v in good:
        if v.simulation.diverged:
            print(f"{v.name}: {v.simulation.reason}", file=sys.stderr)
        for w in v.warnings:
            _warn(f"{v.name}: {w}")
    errors = failed + [v.error for v in vals if v.error is not None]
    for e in errors:
        print(f"shipid: error: {e}", file=sys.stderr)
    if not good:
        return 1  # nothing validated: nothing to write
    # Some logs validated: the outputs record every log, failed ones with their error.
    with OutputSet() as out:
        if args.json:
            records = [v.to_dict() for v in vals] + [{"name": None, "error": e} for e in failed]
            out.write(args.json, lambda p: p.write_text(_json_text({"logs": records}), "utf-8"))
        figures: dict[str, dict[str, bytes]] = {}
        if args.plots:
            from shipid.reporting import plots

            stems = _unique_figure_names([v.name for v in good])
            pairs = [(v, log) for v, log in zip(vals, logs, strict=True) if v.error is None]
            ext = "." + args.plot_format
            # PNGs drawn once serve the folder and the report alike.
            share = args.report is not None and args.plot_format == "png"
            for (v, log), stem in zip(pairs, stems, strict=True):
                title = Path(v.name).name
                jobs = [("fit", stem + ext, partial(plots.measured_vs_simulated, log,
                                                   v.simulation.log, title=title,
                                                   bands=v.bands,
                                                   error_band=v.error_band))]  # fmt: skip
                if args.resid:
                    jobs.append(("resid", stem + "-resid" + ext, partial(
                        plots.residuals, residuals[v.name], title=f"{title}: residual analysis")))
                for key, file_name, plot in jobs:
                    if not share:
                        plot(Path(args.plots) / file_name, out=out)
                        continue
                    buf = io.BytesIO()
                    plot(buf)
                    figures.setdefault(v.name, {})[key] = png = buf.getvalue()
                    out.write(Path(args.plots) / file_name, partial(Path.write_bytes, data=png))
        if args.report:
            from shipid.reporting.html import validation_report

            ident = doc.get("identification") or {}
            se = {d: (ident.get("diagnostics") or {}).get(d, {}).get("std_errors")
                  for d in model.structure.dofs} if not args.lssvm else None  # fmt: skip
            text = validation_report(model, vals, logs, f"Validation of {Path(args.model).name}",
                                     std_errors=se, criteria=crit,
                                     warnings=[w for v in good for w in v.warnings],
                                     residuals=residuals, figures=figures)  # fmt: skip
            out.write(Path(args.report) / "report.html",
                      lambda p: p.write_text(text, encoding="utf-8"))
    return 1 if errors else 0


def cmd_plot(args) -> int:
    """``shipid plot``: a figure of any logs."""
    from shipid.outputs import check_outputs
    from shipid.reporting.plots import logs_figure

    check_outputs({"-o": (args.output, "figure")}, args.logs)
    logs = _read_logs(args)
    logs_figure({Path(p).name: log for p, log in zip(args.logs, logs, strict=True)}, args.output,
                args.title or ", ".join(Path(p).name for p in args.logs))  # fmt: skip
    print(f"figure written to {args.output}")
    return 0


def _criteria_of_logs(good, logs, vals, particulars):
    """Measured and predicted criteria rows of 35° turns and 10/10, 20/20 zig-zags."""
    import math

    from shipid.trials.criteria import measured_criteria
    from shipid.trials.trial import describe_trial

    rows = []
    by_name = {v.name: log for v, log in zip(vals, logs, strict=True)}
    for v in good:
        log = by_name[v.name]
        trial = describe_trial(log, v.kind)
        rudder = math.degrees(trial.plateau_angle)
        speed = float(log["u"].iloc[: max(1, len(log) // 50)].mean())
        if not speed > 0:
            continue
        meas = v.indices.get("measured", {})
        pred = v.indices.get("closed_loop") if v.kind == "zigzag" else v.indices.get("simulated")
        args = (rudder, meas.get("switch_heading_deg"), particulars.length, speed, particulars.scale)
        m_rows = measured_criteria(meas, *args)
        p_rows = {r["criterion"]: r for r in measured_criteria({**(pred or {}), "kind": v.kind},
                                                               *args)}  # fmt: skip
        for r in m_rows:
            p = p_rows.get(r["criterion"], {})
            rows.append({"log": Path(v.name).name, "criterion": r["criterion"], "unit": r["unit"],
                         "limit": r["limit"], "measured": r["value"],
                         "measured passes": r["passed"], "predicted": p.get("value"),
                         "predicted passes": p.get("passed")})  # fmt: skip
    return _pd().DataFrame(rows) if rows else None


def _ship_or_model(name: str):
    """A reference ship (its trimmed speed applies) or a model file with its training
    conditions (approach speed, propeller speed, envelope)."""
    from shipid.reporting.modelfile import load_document, model_from_document, training_conditions
    from shipid.vessels import get_vessel

    if name in VESSEL_NAMES:
        return get_vessel(name), {"speed": None, "rps": None, "envelope": {}, "particulars": None,
                                  "rudder_rate": None, "rudder_positive": None}  # fmt: skip
    if not Path(name).exists():
        raise ShipidError(f"{name}: neither a model file nor a known vessel "
                          f"({', '.join(VESSEL_NAMES)})")  # fmt: skip
    from shipid.reporting.modelfile import ensemble_from_document

    doc = load_document(name)
    model = model_from_document(doc, name)
    cond = training_conditions(doc)
    cond["ensemble"] = ensemble_from_document(doc, name, model)
    return model, cond


def _run_approach(target, cond: dict, speed: float | None, rps: float | None):
    """Approach speed and rps of a run on ``target``: a reference ship's own trim, or a model's
    steady straight approach (``shipid.dynamics.equilibrium.steady_approach``), printed, with a
    warning when it is not steady. Returns (speed, rps, warning or None)."""
    from shipid.dynamics.equilibrium import steady_approach
    from shipid.dynamics.model import ManoeuvringModel

    if not isinstance(target, ManoeuvringModel):
        return speed, rps, None
    if speed is None and not cond["speed"]:
        return None, rps if rps is not None else cond["rps"], None  # the run names what is missing
    app = steady_approach(target, cond["speed"], cond["rps"], speed, rps)
    print(app.describe())
    return app.speed, app.rps, app.warning


def cmd_simulate(args) -> int:
    """``shipid simulate``: drive a model or vessel with a log's inputs."""
    from shipid.data.io import read_log, write_log
    from shipid.dynamics.simulate import simulate_log
    from shipid.outputs import check_outputs

    log_path = args.log
    check_outputs({"-o": (args.output, "log")}, [args.model, log_path])
    from shipid.data.log import in_rudder_convention

    target, cond = _ship_or_model(args.model)
    dynamics = getattr(target, "dynamics", target)
    log, note = in_rudder_convention(read_log(log_path, _read_options(args)),
                                     getattr(target, "rudder_positive", None)
                                     or cond.get("rudder_positive"))  # fmt: skip
    if note:
        _warn(note)
    for note in (_scale_notes(cond, [log], [str(log_path)])
                 + _sampling_notes(cond, [log], [str(log_path)])):
        _warn(note)
    res = simulate_log(dynamics, log, method=args.method)
    write_log(res.log, args.output)
    if res.diverged:
        print(res.reason, file=sys.stderr)
    print(f"{len(res.log)} samples written to {args.output}")
    return 0


def _steering(target, cond: dict, rate_deg_s: float | None, fallback: str = "instantaneous"):
    """The steering machine of a run and a line saying which: ``--rudder-rate`` (a reference
    ship keeps its gear's other limits), else a reference ship's own gear (None: the ship's),
    else the rate of the model's training logs (overshoots depend on it as much as on the
    model), else ``fallback``: an instantaneous rudder, said so, or 'caller' (None: the caller
    chooses, as the IMO criteria take the SOLAS rate)."""
    import dataclasses

    from shipid.dynamics.steering import SteeringMachine

    own = getattr(target, "steering", None)
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
    else:
        return SteeringMachine(), ("rudder: instantaneous (the model file has no training rudder "
                                   "rate; give one with --rudder-rate DEG/S)")  # fmt: skip
    steering = (SteeringMachine(math.radians(35.0), rate) if own is None
                else dataclasses.replace(own, max_rate=rate))  # fmt: skip
    return steering, f"rudder rate {math.degrees(rate):.3g} °/s ({source})"


def cmd_manoeuvre(args) -> int:
    """``shipid manoeuvre``: a standard manoeuvre on a model or vessel."""
    from shipid.evaluation.envelope import implausible_indices, outside_envelope
    from shipid.outputs import OutputSet, check_outputs
    from shipid.trials.manoeuvres import (
        pull_out,
        spiral,
        stopping,
        turning_circle,
        without_value,
        zigzag,
    )

    check_outputs({"--json": (args.json, "json"), "-o": (args.output, "log")},
                  [args.model] if Path(args.model).exists() else [])  # fmt: skip
    target, cond = _ship_or_model(args.model)
    speed, rps, unsteady = _run_approach(target, cond, args.speed, args.rps)
    steering, rudder_note = _steering(target, cond, args.rudder_rate)
    kw = {"dt": args.step, "speed": speed, "rps": rps, "steering": steering}
    if args.wind_speed is not None:
        kw["wind"] = (args.wind_speed, math.radians(args.wind_from or 0.0))
    if args.duration is not None:
        kw["duration"] = args.duration
    if args.rudder_deg is None:
        args.rudder_deg = 35.0 if args.kind == "turning" else 20.0
    if args.kind == "zigzag":
        heading = args.heading if args.heading is not None else args.rudder_deg
        run = partial(zigzag, rudder_deg=args.rudder_deg, heading_deg=heading, first=args.first,
                      **kw)  # fmt: skip
    elif args.kind == "turning":
        run = partial(turning_circle, rudder_deg=args.rudder_deg, side=args.first, **kw)
    elif args.kind == "pull-out":
        if args.duration is not None:
            kw.pop("duration")
            kw["hold"] = kw["release"] = args.duration / 2
        run = partial(pull_out, rudder_deg=args.rudder_deg, side=args.first, **kw)
    elif args.kind == "spiral":
        kw.pop("wind", None)
        if args.duration is not None:
            kw["hold"] = kw.pop("duration")
        run = partial(spiral, **kw)
    else:
        if not rps:
            raise ShipidError("stopping needs the approach propeller speed (--rps, or a model "
                              "trained with the n column)")  # fmt: skip
        kw.pop("rps")
        kw.pop("steering")  # the rudder stays amidships
        run = partial(stopping, rps=rps, astern_rps=args.astern_rps, **kw)
    res = run(target)
    print(rudder_note)
    gear = steering or getattr(target, "steering", None)  # the one the run used
    intervals = {}
    ensemble = cond.get("ensemble")
    if ensemble is not None and not args.no_bands and args.kind != "spiral":
        from shipid.identification.uncertainty import index_intervals

        runs = [run(member) for member in ensemble.members()]
        # A diverged replicate has no indices; it widens the intervals rather than vanishing.
        intervals = index_intervals([{} if r.diverged else r.indices for r in runs])
        diverged = sum(r.diverged for r in runs)
        print(f"95 % intervals over the model's {ensemble.replicates} {ensemble.members_label}"
              + (f" ({diverged} diverged: an index is not bounded where more than 2.5 % of "
                 "them diverged or lack it)" if diverged else "") + ":")
    if res.diverged:
        print(res.reason, file=sys.stderr)
    notes = ([unsteady] if unsteady else []) + outside_envelope(cond["envelope"], res.log)
    if res.incomplete and not res.diverged:
        notes.append(f"{res.incomplete}: indices that need it are missing or those of a "
                     "transient; give a longer --duration")  # fmt: skip
    if args.kind == "turning" and not res.diverged:
        notes += implausible_indices(res.indices, speed or getattr(target, "approach_speed", None),
                                     getattr(target, "length", None))  # fmt: skip
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
    for n in notes:
        _warn(n)
    with OutputSet() as out:
        if args.json:
            doc = {"manoeuvre": res.log.attrs.get("manoeuvre"), "diverged": res.diverged,
                   "approach": {"speed": speed, "rps": rps},
                   "diverged_at": res.diverged_at, "reason": res.reason,
                   "indices": res.indices, "index_intervals": intervals or None,
                   "index_not_bounded": unbounded or None,
                   "rudder_rate_deg_s": (math.degrees(gear.max_rate) if gear and gear.max_rate
                                         else None),
                   "warnings": notes}  # fmt: skip
            out.write(args.json, lambda p: p.write_text(_json_text(doc), "utf-8"))
        if args.output:
            from shipid.data.io import write_log

            write_log(res.log, args.output, out=out)
    return 0


def cmd_indices(args) -> int:
    """``shipid indices``: IMO indices of measured logs."""
    from shipid.outputs import atomic_write_text, check_outputs
    from shipid.trials.indices import manoeuvre_indices

    check_outputs({"--json": (args.json, "json")}, args.logs)
    logs = _read_logs(args)
    out = []
    for path, log in zip(args.logs, logs, strict=True):
        ind = manoeuvre_indices(log, args.kind, heading_deg=args.heading, smooth_s=args.smooth)
        out.append({"name": str(path), "indices": ind})
        kind = ind.get("kind")
        print(f"{path}: {kind}" + (f" ({ind['reason']})" if kind == "other" else ""))
        for k, v in ind.items():
            if k not in ("kind", "reason"):
                print(f"  {k}: {v:.4g}" if isinstance(v, float) else f"  {k}: {v}")
    if args.json:
        atomic_write_text(args.json, _json_text({"logs": out}))
    return 0


def cmd_import(args) -> int:
    """``shipid import``: trial files to canonical logs."""
    from shipid.data.io import write_log
    from shipid.outputs import OutputSet, check_outputs

    # Several files, or one into an existing folder (as cp does): -o is a folder; each file
    # keeps its name with the extension of --ext.
    several = len(args.logs) > 1 or Path(args.output).is_dir()
    if several:
        check_outputs({"-o": (args.output, "dir")}, args.logs)
        targets = [Path(args.output) / (Path(p).stem + args.ext) for p in args.logs]
        check_outputs({f"-o {t.name}": (t, "log") for t in targets}, args.logs)
        stems = [t.name for t in targets]
        dup = next((n for n in stems if stems.count(n) > 1), None)
        if dup:
            raise ShipidError(f"-o {args.output}: two inputs would both be written as {dup}")
    else:
        check_outputs({"-o": (args.output, "log")}, args.logs)
        targets = [Path(args.output)]
    logs = _read_logs(args)
    with OutputSet() as out:
        for log, target in zip(logs, targets, strict=True):
            write_log(log, target, out=out)
    for log, target in zip(logs, targets, strict=True):
        meta = ", ".join(f"{k}={log.attrs[k]}" for k in ("ship", "rudder_positive", "scale")
                         if k in log.attrs)  # fmt: skip
        print(f"{len(log)} samples, {log['t'].iloc[-1] - log['t'].iloc[0]:.1f} s ({meta}) "
              f"written to {target}")
    return 0


# ---------------------------------------------------------------------------- parser
def _add_physics_options(p) -> None:
    g = p.add_argument_group("physics (increment form; lssvm or ols)")
    g.add_argument("--prior", metavar="clarke|MODEL.json",
                   help="draw the fit toward a prior instead of zero: 'clarke' (linear sway–yaw "
                   "and rudder terms from the particulars, Clarke et al. 1983) or a model file")
    g.add_argument("--constraints", metavar="LIST",
                   help="comma list: signs (damping, resistance, thrust and rudder terms keep "
                   "their physical sign), steady-speed (u̇ = 0 on the approach), stable "
                   "(straight-line stability at the approach: the yaw equation given the "
                   "sway one)")
    g.add_argument("--bound", action="append", metavar="'DOF: TERM <= X'",
                   help="a bound on one coefficient, e.g. 'r: u*r <= 0' (repeatable)")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command."""
    ap = argparse.ArgumentParser(prog="shipid", description="Semiphysical identification of ship "
                                 "manoeuvring models with LS-SVM (Moreno-Salinas et al. 2013).")
    ap.add_argument("--version", action="version", version=f"shipid {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)

    p = sub.add_parser("demo", help="the paper's experiment on the embedded scale ship")
    p.add_argument("--out", default="shipid-demo", help="output folder (default ./%(default)s)")
    p.add_argument("--seed", type=int, default=0, help="noise seed (default %(default)s)")
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("identify", help="identify a model from trial logs")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--model", default="blanke",
                   help="structure: blanke (default), blanke-thrust, blanke-speed, blanke-race, "
                   "blanke-rps, abkowitz3, low-speed, wind, race-damping, propeller-asymmetry, "
                   "astern, linear-sway-yaw, nomoto1; combine "
                   "with + (blanke-rps+wind, blanke-race+race-damping) or write terms: "
                   "'u: |u|u, v*r, 1; v: ...; r: ...'")
    p.add_argument("--form", default="increment", choices=("increment", "paper"),
                   help="regression form (default %(default)s)")
    p.add_argument("--gamma", type=_number_or_auto, default=1e4, metavar="G|auto",
                   help="LS-SVM regularisation γ, or 'auto': chosen by free-run cross-validation "
                   "over the logs (default %(default)g)")
    p.add_argument("--estimator", default="lssvm", choices=LINEAR_ESTIMATORS,
                   help="equation-error estimator (default %(default)s, the paper's)")
    p.add_argument("--cv", help="with --gamma auto: logo, kfold:K or blocks:K (default: logo, "
                   "blocks:4 for one log)")
    p.add_argument("--drop", help="terms to drop, e.g. u:r^2 (the paper drops r²)")
    p.add_argument("--filter", type=_number_or_auto_or_none, default="auto", metavar="HZ|auto|none",
                   help="zero-phase low-pass of u, v, r against the errors-in-variables bias: a "
                   "cut-off, 'none', or 'auto' (default): the cut-off whose model has the "
                   "smallest free-run error on the logs (one-standard-error rule, so clean data "
                   "keep none)")
    p.add_argument("--force", action="store_true",
                   help="keep a fit whose regressors are nearly dependent (still reported)")
    p.add_argument("--refine", action="store_true",
                   help="refine the LS-SVM model by output error (free-run fit to the logs); the "
                   "model file holds the refined model and keeps the LS-SVM one")
    p.add_argument("--output-error", action="store_true",
                   help="fit the coefficients by maximum-likelihood output error (free runs from "
                   "estimated initial states against the unfiltered logs; consistent under "
                   "measurement noise, unlike any equation-error fit), with standard errors, "
                   "95 %% intervals and 200 covariance draws stored for prediction bands and "
                   "index intervals; the LS-SVM model is its start and stays in the file")
    p.add_argument("--segment", type=float, metavar="S",
                   help="with --refine: simulate segments of S seconds (default: whole logs)")
    p.add_argument("--refine-evals", type=int, default=200, metavar="N",
                   help="with --refine or --output-error: cap on cost evaluations (default "
                   "%(default)s)")
    p.add_argument("--bootstrap", type=int, metavar="N",
                   help="uncertainty: N moving-block bootstrap refits (≥ 10; e.g. 200), stored in "
                   "the model file: coefficient intervals here, prediction bands and index "
                   "intervals in validate, manoeuvre and criteria")
    p.add_argument("--block", type=float, default=10.0, metavar="S",
                   help="with --bootstrap: block length [s] (default %(default)g)")
    p.add_argument("--seed", type=int, default=0, help="with --bootstrap or --output-error: "
                   "random seed "
                   "(default %(default)s)")
    p.add_argument("--error-band", nargs="?", const="auto", metavar="CV",
                   help="the cross-validated 95 %% error band of the free runs, stored for "
                   "validate: the same fit without each log (logo) or block (blocks:K), run free "
                   "over it (default auto: logo from two logs, blocks:4 of one)")
    # --out spelled out: since --output-error, argparse no longer takes it for --output.
    p.add_argument("-o", "--output", "--out", required=True, metavar="MODEL.json")
    _add_physics_options(p)
    _add_log_options(p)
    p.set_defaults(func=cmd_identify)

    p = sub.add_parser("select", help="choose the structure and γ by cross-validated free-run "
                       "error over several logs")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--library",
                   help="candidate terms: a structure name, a sum (abkowitz3+blanke) or written "
                   "terms 'u: ...; v: ...; r: ...' (default low-speed+wind+propeller-asymmetry, "
                   "less the terms whose log columns the logs lack, said so)")
    p.add_argument("--search", default="stepwise", choices=("stepwise", "frols", "stlsq", "none"),
                   help="how candidates are generated (default %(default)s)")
    p.add_argument("--gammas", metavar="G,G,...", help="γ grid (default 1e2,1e3,1e4,1e5,1e6)")
    p.add_argument("--cv", default="logo", help="logo (leave one log out, default), kfold:K or "
                   "blocks:K (every log cut into K blocks)")
    p.add_argument("--estimator", default="lssvm", choices=LINEAR_ESTIMATORS,
                   help="equation-error estimator (default %(default)s)")
    p.add_argument("--method", default="euler", choices=("euler", "rk4"),
                   help="integration scheme of the free runs (default %(default)s)")
    p.add_argument("--max-evaluations", type=int, default=400, metavar="N",
                   help="cap on candidates evaluated (default %(default)s)")
    p.add_argument("--best", action="store_true",
                   help="take the best CV score instead of the sparsest within one standard error")
    p.add_argument("--average", action="store_true",
                   help="write the average of the candidates the choice picks on resampled "
                   "held-out logs, weighted by how often (bagging), instead of the chosen one")
    p.add_argument("--no-plausibility", action="store_true",
                   help="do not restrict the choice to plausible models")
    p.add_argument("--speed", type=float, help="plausibility checks at this speed [m/s] "
                   "(default: each candidate's steady straight speed at the first log's rps, "
                   "or the first log's approach without propeller terms)")
    p.add_argument("--rps", type=float, help="... and this propeller speed [rps]")
    p.add_argument("--show", type=int, default=10, metavar="N", help="candidates printed (default 10)")
    p.add_argument("--bootstrap", type=int, metavar="N",
                   help="uncertainty of the selected model: N replicates (≥ 10), each a "
                   "candidate drawn by how often it is chosen on resampled held-out logs, "
                   "refitted on a moving-block resample; stored in the model file for bands "
                   "and intervals")
    p.add_argument("--block", type=float, default=10.0, metavar="S",
                   help="with --bootstrap: block length [s] (default %(default)g)")
    p.add_argument("--seed", type=int, default=0, help="with --bootstrap: random seed "
                   "(default %(default)s)")
    p.add_argument("--table", metavar="OUT.csv", help="write every candidate with its scores")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("-o", "--output", required=True, metavar="MODEL.json")
    _add_physics_options(p)
    _add_log_options(p)
    p.set_defaults(func=cmd_select)

    p = sub.add_parser("compare", help="methods × held-out logs: free-run cross-validation")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--model", default="blanke", help="structure for the semiphysical methods "
                   "(default %(default)s)")
    p.add_argument("--methods", default="lssvm,ols,ridge,lasso,svr,elm",
                   help="comma-separated: lssvm, ols, ridge, lasso, svr, elm, lssvm-rbf, "
                   "select:LIBRARY (default %(default)s)")
    p.add_argument("--gamma", type=float, default=1e4, help="γ (α = 1/γ) (default %(default)g)")
    p.add_argument("--cv", default="logo", help="logo (default) or kfold:K")
    p.add_argument("--method", default="euler", choices=("euler", "rk4"),
                   help="integration scheme (default %(default)s)")
    p.add_argument("--json", metavar="OUT.json", help="write every (method, log) row")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    _add_log_options(p)
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("validate", help="free-run a model against logs: error table and indices")
    p.add_argument("model", metavar="MODEL.json")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--json", metavar="OUT.json", help="write the results as JSON")
    p.add_argument("--plots", metavar="DIR", help="write measured-vs-simulated figures")
    p.add_argument("--method", default="euler", choices=("euler", "rk4"),
                   help="integration scheme (default %(default)s, the paper's)")
    p.add_argument("--kind", choices=KINDS, help="manoeuvre of the logs (default: detected)")
    p.add_argument("--smooth", type=float, default=0.0,
                   help="heading smoothing window for measured indices [s] (default 0)")
    p.add_argument("--lssvm", action="store_true",
                   help="validate the LS-SVM model a refined model file keeps")
    p.add_argument("--no-bands", action="store_true",
                   help="skip the bootstrap ensemble of the model file (its prediction bands and "
                   "index intervals cost one free run per replicate) and its cross-validated "
                   "error band")
    p.add_argument("--plot-format", default="png", choices=("png", "svg", "pdf"),
                   help="format of the --plots figures (default %(default)s)")
    p.add_argument("--resid", action="store_true",
                   help="residual analysis: autocorrelation of the errors and correlation with "
                   "the rudder (a table, and figures with --plots)")
    p.add_argument("--max-lag", type=int, default=50, metavar="N",
                   help="with --resid: largest lag [samples] (default %(default)s)")
    p.add_argument("--report", metavar="DIR", help="write a self-contained HTML report")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    _add_log_options(p)
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("plot", help="figure of any logs: u, v, r, rudder, heading, track")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("-o", "--output", required=True, metavar="FIG.png|.svg|.pdf")
    p.add_argument("--title", help="figure title (default: the file names)")
    _add_log_options(p)
    p.set_defaults(func=cmd_plot)

    p = sub.add_parser("simulate", help="drive a model or vessel with a logged rudder")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("log", metavar="LOG", help="log whose rudder and inputs drive it")
    p.add_argument("--method", default="rk4", choices=("euler", "rk4"),
                   help="integration scheme (default %(default)s)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.csv")
    _add_log_options(p)
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("manoeuvre", help="run a standard manoeuvre on a model or vessel")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("kind", choices=("zigzag", "turning", "pull-out", "spiral", "stopping"))
    p.add_argument("--rudder", dest="rudder_deg", type=float, metavar="DEG",
                   help="rudder angle [deg] (default 35 for the turning circle, 20 otherwise)")
    p.add_argument("--heading", type=float, metavar="DEG",
                   help="zig-zag switch heading [deg] (default = rudder)")
    p.add_argument("--first", default="starboard", choices=("starboard", "port"),
                   help="first rudder (zig-zag) or turn side (default %(default)s)")
    p.add_argument("--duration", type=float,
                   help="length of the run [s] (default: from 90 s for a zig-zag, 240 s for a "
                        "turning circle, 60 + 60 s for a pull-out, 120 s per spiral step, "
                        "600 s for stopping, "
                        "doubled until the run is complete and its yaw rate settled; a full-"
                        "scale ship takes ten times a 1:100 model)")
    p.add_argument("--dt", "--step", dest="step", type=float, default=0.05,
                   help="integration step [s] (default %(default)s)")
    p.add_argument("--speed", type=float, help="approach speed [m/s] (models: default from training)")
    p.add_argument("--rps", type=float,
                   help="propeller speed [rps] for models with n terms (default from training)")
    p.add_argument("--astern-rps", type=float, help="stopping: the full-astern order (default −rps)")
    p.add_argument("--rudder-rate", type=float, metavar="DEG/S",
                   help="steering machine rate (default: a reference ship's own, else the model "
                   "file's training rudder rate, else instantaneous)")
    p.add_argument("--wind-speed", type=float, metavar="M/S",
                   help="constant true wind for models with wind terms (default: still air)")
    p.add_argument("--wind-from", type=float, metavar="DEG",
                   help="direction the wind blows from, clockwise from north [deg] (default 0)")
    p.add_argument("--json", metavar="OUT.json")
    p.add_argument("-o", "--output", metavar="LOG.csv", help="write the simulated log")
    p.add_argument("--no-bands", action="store_true",
                   help="skip the intervals from the model file's bootstrap ensemble")
    p.set_defaults(func=cmd_manoeuvre)

    p = sub.add_parser("criteria", help="IMO MSC.137(76) criteria: run the standard manoeuvres "
                       "on a model or vessel and judge them")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("--particulars", metavar="FILE", help="ship particulars (default: the model "
                   "file's)")
    p.add_argument("--length", type=float, help="Lpp [m] (default: the particulars')")
    p.add_argument("--speed", type=float, help="test speed [m/s] (default: the training approach)")
    p.add_argument("--scale", type=float, metavar="LAMBDA",
                   help="model scale λ, for the full-scale L/V and rudder rate (default: the "
                   "particulars', else 1)")
    p.add_argument("--rps", type=float, help="propeller speed for models with n terms (default: "
                   "the training approach)")
    p.add_argument("--astern-rps", type=float, help="stopping test order (default −rps)")
    p.add_argument("--rudder-rate", type=float, metavar="DEG/S",
                   help="steering machine rate (default: the training logs' rudder rate, else "
                   "SOLAS 2.32 °/s at full scale, × √λ)")
    p.add_argument("--dt", type=float, default=0.05, help="integration step [s] (default %(default)s)")
    p.add_argument("--json", metavar="OUT.json")
    p.add_argument("--no-bands", action="store_true",
                   help="skip the intervals from the model file's bootstrap ensemble")
    p.set_defaults(func=cmd_criteria)

    p = sub.add_parser("linearise", help="state-space A, B and Nomoto K, T of a model or vessel")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("--speed", type=float, help="straight-running speed [m/s] (default: training)")
    p.add_argument("--rps", type=float, help="propeller speed for models with n terms")
    p.set_defaults(func=cmd_linearise)

    p = sub.add_parser("export", help="a model as a standalone NumPy module (no shipid needed)")
    p.add_argument("model", metavar="MODEL.json")
    p.add_argument("-o", "--output", required=True, metavar="MODEL.py")
    p.set_defaults(func=cmd_export)

    for name, helptext in (("autopilot", "PID heading autopilot tuned on a model: a heading step "
                            "on the model and on a true ship"),
                           ("follow", "line-of-sight path following along waypoints with a PID "
                            "tuned on a model, on the model and on a true ship")):  # fmt: skip
        p = sub.add_parser(name, help=helptext)
        p.add_argument("model", metavar="MODEL.json|VESSEL")
        p.add_argument("--truth", metavar="VESSEL", help="reference ship to test the controller "
                       "on (scale-ship, mariner, kvlcc2)")
        p.add_argument("--speed", type=float, help="approach speed [m/s] (default: training)")
        p.add_argument("--rps", type=float, help="propeller speed for models with n terms")
        p.add_argument("--rudder-rate", type=float, metavar="DEG/S",
                       help="the model's steering machine rate (default: its training logs' "
                       "rudder rate; a reference ship: its own gear)")
        p.add_argument("--omega", type=float, help="closed-loop natural frequency [rad/s] "
                       "(default max(1/|T|, √|K/T|): Kp at least 1)")
        p.add_argument("--dt", type=float, default=0.1, help="step [s] (default %(default)s)")
        if name == "autopilot":
            p.add_argument("--heading", type=float, default=20.0, metavar="DEG",
                           help="heading step (default %(default)s; positive to starboard)")
            p.add_argument("--duration", type=float,
                           help="[s] (default: from 120 s, doubled until the heading settles)")
            p.add_argument("-o", "--output", metavar="FIG.png", help="figure of the responses")
            p.set_defaults(func=cmd_autopilot)
        else:
            p.add_argument("--waypoints", required=True, metavar="X,Y;X,Y;...",
                           help="waypoints [m], x north, y east")
            p.add_argument("--lookahead", type=float, metavar="M",
                           help="line-of-sight lookahead [m] (default 2 L, from the ship or the model "
                           "file's particulars, else 20 m)")
            p.add_argument("-o", "--output", metavar="FIG.png", help="figure of the tracks")
            p.add_argument("--json", metavar="OUT.json")
            p.set_defaults(func=cmd_follow)

    p = sub.add_parser("rescale", help="a model carried to a geometrically similar ship of "
                       "another length (Froude scaling, equal prime coefficients)")
    p.add_argument("model", metavar="MODEL.json")
    p.add_argument("--factor", type=float, help="new length / old length (e.g. 45.7: model "
                   "basin to full scale)")
    p.add_argument("--length", type=float, help="the new Lpp [m] (the model file's particulars "
                   "give the old one)")
    p.add_argument("--rho", type=float, help="the new water density [kg/m³] (default: the "
                   "particulars', else 1025; matters for thrust terms only)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.json")
    p.set_defaults(func=cmd_rescale)

    p = sub.add_parser("study", help="Monte Carlo identifiability study of the paper's "
                       "experiment (seeds × noise × γ × structure), or identify many log sets "
                       "(kind: logs), on Dask")
    p.add_argument("spec", metavar="SPEC.yml", help="the grid and seeds (see docs/study.yml)")
    p.add_argument("-o", "--output", required=True, metavar="RESULTS.parquet|RESULTS.csv",
                   help="one row per trial")
    p.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler "
                   "(tcp://host:8786), or 'serial' for this process alone (default: a local "
                   "cluster)")
    p.add_argument("--workers", type=int, help="worker processes of the local cluster "
                   "(default: the machine's cores)")
    p.add_argument("--models", metavar="DIR", help="kind logs: the folder of the jobs' model "
                   "files")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_study)

    p = sub.add_parser("import", help="convert trial files to canonical logs")
    p.add_argument("logs", nargs="+", metavar="FILE")
    p.add_argument("-o", "--output", required=True, metavar="LOG.csv|LOG.parquet|DIR",
                   help="the canonical log; with several files, or into an existing folder, a "
                   "folder (each file keeps its name)")
    p.add_argument("--ext", default=".csv", choices=(".csv", ".parquet"),
                   help="into a folder: the output format (default %(default)s)")
    _add_log_options(p)
    p.set_defaults(func=cmd_import)

    p = sub.add_parser("indices", help="IMO indices of measured logs")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--kind", choices=KINDS, help="default: detected")
    p.add_argument("--heading", type=float, help="zig-zag switch heading [deg] (default: inferred)")
    p.add_argument("--smooth", type=float, default=0.0,
                   help="heading smoothing window [s] (default 0)")
    p.add_argument("--json", metavar="OUT.json")
    _add_log_options(p)
    p.set_defaults(func=cmd_indices)
    return ap


class _ClosableStdout:
    """stdout that goes quiet once its reader has gone (``shipid identify ... | head``): the
    command still finishes and writes its files instead of failing on a broken pipe."""

    def __init__(self, stream):
        self._stream = stream
        self._closed = False

    def write(self, text: str) -> int:
        if not self._closed:
            try:
                return self._stream.write(text)
            except BrokenPipeError:
                self._close()
        return len(text)

    def flush(self) -> None:
        if not self._closed:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self._close()

    def _close(self) -> None:
        import os

        self._closed = True
        try:  # what is still buffered goes nowhere, not into an error at exit
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, self._stream.fileno())
            os.close(null)
        except (OSError, ValueError, AttributeError):
            pass

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (0, 1, 2 usage, 130 interrupted)."""
    args = build_parser().parse_args(argv)
    import threading

    # Only the main thread may handle signals; a Dask worker runs jobs in its own threads.
    in_main = threading.current_thread() is threading.main_thread()
    if in_main:
        clear_stop()
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
        previous_int = signal.signal(signal.SIGINT, _on_sigint)
    unraisablehook = sys.unraisablehook
    if in_main:
        sys.unraisablehook = _quiet_lost_interrupts(unraisablehook)
    caught: list[warnings.WarningMessage] = []
    stdout = sys.stdout
    sys.stdout = _ClosableStdout(stdout)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ShipidWarning)
            check_options(args)
            try:
                code = args.func(args)
            except Exception:
                # An error after an interrupt is the interrupt's doing (it broke a JIT compile,
                # which then fails with its own RuntimeError), not a bug: exit 130 all the same.
                if in_main and stop_requested():
                    raise Interrupted() from None
                raise
            if in_main:
                check_stop()  # an interrupt whose exception a finaliser dropped
    except ShipidError as exc:
        print(f"shipid: error: {_one_line(exc)}", file=sys.stderr)
        code = 1
    except KeyboardInterrupt:
        print("shipid: interrupted", file=sys.stderr)
        code = 130
        # What the interrupted work leaves half-built (a JIT compile's LLVM objects) may fail in
        # its finaliser when the traceback is dropped at the end of this clause: stay one line.
        sys.unraisablehook = _ignore_unraisable
    except MemoryError:
        print("shipid: error: out of memory (ask for fewer samples: a shorter run, a larger "
              "step or --dt)", file=sys.stderr)  # fmt: skip
        code = 1
    except (ValueError, OSError) as exc:
        print(f"shipid: error: {_one_line(exc)}", file=sys.stderr)
        code = 1
    except Exception as exc:  # a bug: still one line, no traceback (SHIPID_DEBUG=1 shows it)
        import os

        if os.environ.get("SHIPID_DEBUG"):
            raise
        print(f"shipid: error: internal error ({type(exc).__name__}: {_one_line(exc)}); please "
              "report it with the command line (SHIPID_DEBUG=1 shows the traceback)",
              file=sys.stderr)  # fmt: skip
        code = 1
    finally:
        if in_main:
            signal.signal(signal.SIGTERM, previous)
            signal.signal(signal.SIGINT, previous_int)
        sys.stdout = stdout
        if sys.unraisablehook is _ignore_unraisable:
            import gc

            gc.collect()  # the finalisers of cycles, while they are still ignored
        sys.unraisablehook = unraisablehook
    seen = set()
    for w in caught:
        if issubclass(w.category, ShipidWarning) and str(w.message) not in seen:
            seen.add(str(w.message))
            print(f"warning: {_one_line(w.message)}", file=sys.stderr)
    return code


def _one_line(exc) -> str:
    text = str(exc)
    if isinstance(exc, OSError) and exc.strerror:
        text = f"{exc.filename}: {exc.strerror}" if exc.filename else exc.strerror
    return text.splitlines()[0] if text else type(exc).__name__


def run() -> None:
    """Console entry point: :func:`main`, then exit with its code.

    After an interrupt the process ends at once (``os._exit``) once the streams are flushed:
    the temporaries are already removed while unwinding, and an interrupted JIT compile
    leaves objects whose finalisers would print tracebacks during interpreter teardown.
    """
    code = main()
    if code == 130:
        import os

        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":
    run()
