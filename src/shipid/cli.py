"""The ``shipid`` command line. Exit 0 on success, 1 on a user error (one-line message, no
traceback), 2 on a usage error. Every output file is written atomically."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from shipid.errors import ShipidError

VESSEL_NAMES = ("scale-ship", "mariner", "kvlcc2")


def _add_log_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("log files")
    g.add_argument("--format", default="canonical", choices=("canonical", "simman-marin", "osaka-frt"),
                   help="file format (default canonical CSV/Parquet)")
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
                   help="with --start auto: seconds kept before the execute (default 5)")
    g.add_argument("--end", type=_time_or_auto, metavar="S|auto",
                   help="trim: last time [s], or 'auto': the end of the manoeuvre (last large rudder, "
                   "propeller still running)")
    g.add_argument("--fill-gaps", action="store_true",
                   help="interpolate missing values inside signals (default: refuse the log)")
    g.add_argument("--rudder-positive", choices=("port", "starboard"),
                   help="where a positive rudder angle turns the ship (default port, as the paper)")


def _time_or_auto(text: str) -> float | str:
    if text == "auto":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds or 'auto', got {text!r}") from None


def _read_logs(args) -> list:
    from shipid.data.io import parse_column_map, read_log

    degrees = [c.strip() for c in args.degrees.split(",") if c.strip()]
    cols = parse_column_map(args.columns)
    return [read_log(p, cols, degrees, args.dt, args.start, args.end, args.rudder_positive,
                     args.format, args.scale, args.lead, args.fill_gaps)
            for p in args.logs]  # fmt: skip


def _write_json(path: str, data) -> None:
    from shipid.outputs import atomic_write_text
    from shipid.reporting.modelfile import json_safe

    atomic_write_text(path, json.dumps(json_safe(data), indent=2, ensure_ascii=False) + "\n")


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


# ---------------------------------------------------------------------------- commands
def cmd_demo(args) -> int:
    from shipid.demo import run_demo, summary

    t0 = time.perf_counter()
    result = run_demo(args.out, args.seed, progress=lambda m: print(m, file=sys.stderr))
    print(summary(result))
    print(f"figures and report written to {Path(args.out) / 'report.md'} "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0


def _approach(log, column: str) -> float | None:
    """Mean of a column over the first 2 % of a log (the approach), None if absent."""
    if column not in log.columns:
        return None
    return float(log[column].iloc[: max(1, len(log) // 50)].mean())


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


def cmd_identify(args) -> int:
    from shipid.data.preprocess import lowpass
    from shipid.identification.identify import identify
    from shipid.identification.plausibility import check_plausibility
    from shipid.identification.refine import refine
    from shipid.reporting.modelfile import save_model

    logs = _read_logs(args)
    if args.filter is not None:
        logs = [lowpass(log, args.filter) for log in logs]
    names = [str(p) for p in args.logs]
    ident = identify(logs, model=args.model, form=args.form, gamma=args.gamma,
                     drop=_parse_drop(args.drop), names=names)  # fmt: skip
    speed, rps = _approach(logs[0], "u"), _approach(logs[0], "n")
    prep = {"dt": args.dt, "start": args.start, "end": args.end, "lead": args.lead,
            "filter_hz": args.filter, "columns": args.columns, "degrees": args.degrees,
            "approach_speed": speed, "approach_rps": rps,
            "rudder_positive": logs[0].attrs.get("rudder_positive")}  # fmt: skip
    refinement = None
    print(ident.model.equations())
    for dof, d in ident.diagnostics.items():
        print(f"{dof}: condition number {d['condition_number']:.3g}, one-step R² "
              f"{d['one_step_r2']:.4f}, bias b = {ident.discrete[dof]['bias']:.4g}")
    if args.refine:
        how = "whole logs" if args.segment is None else f"{args.segment:g} s segments"
        print(f"refining by output error ({how})…", file=sys.stderr)
        refinement = refine(ident.model, logs, segment_s=args.segment, gamma=args.gamma,
                            max_nfev=args.refine_evals, names=names)  # fmt: skip
        print()
        print("refined by output error:")
        print(refinement.model.equations())
        print(f"cost {refinement.cost_initial:.4g} → {refinement.cost_final:.4g} in "
              f"{refinement.nfev} evaluations ({refinement.message})")
        print(_free_run_table(refinement))
    final = ident.model
    n = rps if ident.model.uses_rps else None
    plausibility, notes = check_plausibility(ident.model, speed, n)
    if refinement:
        refined_report, refined_notes = check_plausibility(refinement.model, speed, n)
        if len(refined_notes) > len(notes):
            # Never hand out a model that fails checks the LS-SVM model passes.
            ident.warnings.append(
                "refinement: the refined model fails plausibility checks the LS-SVM model passes ("
                + "; ".join(refined_notes[:2]) + "); the model file's model is the LS-SVM one, the "
                "refined one is kept under identification.refinement.refined_model")
        else:
            final, plausibility, notes = refinement.model, refined_report, refined_notes
    sl = plausibility["straight_line"]
    if sl:
        print(f"straight-line {'stable' if sl['stable'] else 'UNSTABLE'} (largest sway–yaw "
              f"eigenvalue real part {sl['max_real_part']:.3g} 1/s); surge equilibrium "
              f"{_fmt_speed(plausibility['surge_equilibrium'])}")  # fmt: skip
    ident.warnings.extend(f"plausibility: {n}" for n in notes)
    if refinement:
        ident.warnings.extend(f"refinement: {n}" for n in refinement.warnings)
    save_model(args.output, ident, args.logs, prep, refinement, plausibility, final)
    for w in ident.warnings:
        print(f"warning: {w}", file=sys.stderr)
    print(f"model written to {args.output}")
    return 0


def _fmt_speed(u: float | None) -> str:
    return "none" if u is None else f"{u:.3g} m/s"


def cmd_validate(args) -> int:
    from shipid.evaluation.validate import validate
    from shipid.reporting.modelfile import load_model
    from shipid.reporting.plots import measured_vs_simulated
    from shipid.reporting.report import error_table, indices_table

    model = load_model(args.model, "lssvm" if args.lssvm else "model")
    logs = _read_logs(args)
    vals = validate(model, logs, [str(p) for p in args.logs], method=args.method)
    print(error_table(vals))
    table = indices_table(vals)
    if table.count("\n") > 1:
        print()
        print(table)
    for v in vals:
        if v.simulation.diverged:
            print(f"{v.name}: {v.simulation.reason}", file=sys.stderr)
    if args.json:
        _write_json(args.json, {"logs": [v.to_dict() for v in vals]})
    if args.plots:
        for v, log in zip(vals, logs, strict=True):
            measured_vs_simulated(log, v.simulation.log,
                                  Path(args.plots) / f"{Path(v.name).stem}.png", v.name)  # fmt: skip
    return 0


def _ship_or_model(name: str):
    """A reference ship (its trimmed speed applies) or a model file with its training speed and
    propeller speed."""
    from shipid.reporting.modelfile import load_document, model_from_document
    from shipid.vessels import get_vessel

    if name in VESSEL_NAMES:
        return get_vessel(name), None, None
    doc = load_document(name)
    prep = doc.get("identification", {}).get("preprocessing", {})
    return model_from_document(doc, name), prep.get("approach_speed"), prep.get("approach_rps")


def cmd_simulate(args) -> int:
    from shipid.data.io import read_log, write_log
    from shipid.dynamics.simulate import simulate_log

    target, _, _ = _ship_or_model(args.model)
    dynamics = getattr(target, "dynamics", target)
    log = read_log(args.rudder, degrees=[c for c in args.degrees.split(",") if c])
    res = simulate_log(dynamics, log, method=args.method)
    write_log(res.log, args.output)
    if res.diverged:
        print(res.reason, file=sys.stderr)
    print(f"{len(res.log)} samples written to {args.output}")
    return 0


def cmd_manoeuvre(args) -> int:
    from shipid.trials.manoeuvres import turning_circle, zigzag

    target, training_speed, training_rps = _ship_or_model(args.model)
    kw = {"dt": args.step, "speed": args.speed or training_speed, "rps": args.rps or training_rps}
    if args.duration:
        kw["duration"] = args.duration
    if args.kind == "zigzag":
        res = zigzag(target, args.rudder, args.heading or args.rudder, first=args.first, **kw)
    else:
        res = turning_circle(target, args.rudder, side=args.first, **kw)
    if res.diverged:
        print(res.reason, file=sys.stderr)
    for k, v in res.indices.items():
        print(f"{k}: {v:.4g}" if isinstance(v, float) else f"{k}: {v}")
    if args.json:
        _write_json(args.json, {"manoeuvre": res.log.attrs.get("manoeuvre"), "diverged": res.diverged,
                                "diverged_at": res.diverged_at, "indices": res.indices})
    if args.output:
        from shipid.data.io import write_log

        write_log(res.log, args.output)
    return 0


def cmd_indices(args) -> int:
    from shipid.trials.indices import manoeuvre_indices

    logs = _read_logs(args)
    out = []
    for path, log in zip(args.logs, logs, strict=True):
        ind = manoeuvre_indices(log, args.kind, heading_deg=args.heading, smooth_s=args.smooth)
        out.append({"name": str(path), "indices": ind})
        print(f"{path}: {ind.get('kind') or 'no manoeuvre detected'}")
        for k, v in ind.items():
            if k != "kind":
                print(f"  {k}: {v:.4g}" if isinstance(v, float) else f"  {k}: {v}")
    if args.json:
        _write_json(args.json, {"logs": out})
    return 0


def cmd_import(args) -> int:
    from shipid.data.io import write_log

    log = _read_logs(args)[0]
    write_log(log, args.output)
    meta = ", ".join(f"{k}={log.attrs[k]}" for k in ("ship", "rudder_positive", "scale")
                     if k in log.attrs)  # fmt: skip
    print(f"{len(log)} samples, {log['t'].iloc[-1] - log['t'].iloc[0]:.1f} s ({meta}) "
          f"written to {args.output}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="shipid", description="Semiphysical identification of ship "
                                 "manoeuvring models with LS-SVM (Moreno-Salinas et al. 2013).")
    sub = ap.add_subparsers(dest="command", required=True)

    p = sub.add_parser("demo", help="the paper's experiment on the embedded scale ship")
    p.add_argument("--out", default="shipid-demo", help="output folder (default ./shipid-demo)")
    p.add_argument("--seed", type=int, default=0, help="noise seed (default 0)")
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("identify", help="identify a model from trial logs")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--model", default="blanke",
                   help="blanke (default), blanke-thrust, blanke-speed (u² δ rudder), "
                   "blanke-rps (u² δ and |n|n thrust), linear-sway-yaw, nomoto1")
    p.add_argument("--form", default="increment", help="increment (default) or paper")
    p.add_argument("--gamma", type=float, default=1e4, help="LS-SVM regularisation γ (default 1e4)")
    p.add_argument("--drop", help="terms to drop, e.g. u:r^2 (the paper drops r²)")
    p.add_argument("--filter", type=float, metavar="HZ", help="zero-phase low-pass of u, v, r")
    p.add_argument("--refine", action="store_true",
                   help="refine the LS-SVM model by output error (free-run fit to the logs); the "
                   "model file holds the refined model and keeps the LS-SVM one")
    p.add_argument("--segment", type=float, metavar="S",
                   help="with --refine: simulate segments of S seconds (default: whole logs)")
    p.add_argument("--refine-evals", type=int, default=200, metavar="N",
                   help="with --refine: cap on cost evaluations (default 200)")
    p.add_argument("-o", "--output", required=True, metavar="MODEL.json")
    _add_log_options(p)
    p.set_defaults(func=cmd_identify)

    p = sub.add_parser("validate", help="free-run a model against logs: error table and indices")
    p.add_argument("model", metavar="MODEL.json")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--json", metavar="OUT", help="write the results as JSON")
    p.add_argument("--plots", metavar="DIR", help="write measured-vs-simulated figures")
    p.add_argument("--method", default="euler", choices=("euler", "rk4"))
    p.add_argument("--lssvm", action="store_true",
                   help="validate the LS-SVM model a refined model file keeps")
    _add_log_options(p)
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("simulate", help="drive a model or vessel with a logged rudder")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("--rudder", required=True, metavar="LOG", help="log with t, delta, u, v, r")
    p.add_argument("--degrees", default="", help="angle columns of the rudder log in degrees")
    p.add_argument("--method", default="rk4", choices=("euler", "rk4"))
    p.add_argument("-o", "--output", required=True, metavar="OUT.csv")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("manoeuvre", help="run a standard manoeuvre on a model or vessel")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("kind", choices=("zigzag", "turning"))
    p.add_argument("--rudder", type=float, default=20.0, help="rudder angle [deg]")
    p.add_argument("--heading", type=float, help="zig-zag switch heading [deg] (default = rudder)")
    p.add_argument("--first", default="starboard", choices=("starboard", "port"),
                   help="first rudder (zig-zag) or turn side")
    p.add_argument("--duration", type=float, help="length of the run [s]")
    p.add_argument("--step", type=float, default=0.05, help="integration step [s]")
    p.add_argument("--speed", type=float, help="approach speed [m/s] (models: default from training)")
    p.add_argument("--rps", type=float,
                   help="propeller speed [rps] for models with n terms (default from training)")
    p.add_argument("--json", metavar="OUT")
    p.add_argument("-o", "--output", metavar="LOG.csv", help="write the simulated log")
    p.set_defaults(func=cmd_manoeuvre)

    p = sub.add_parser("import", help="convert a trial file to a canonical log")
    p.add_argument("logs", nargs=1, metavar="FILE")
    p.add_argument("-o", "--output", required=True, metavar="LOG.csv")
    _add_log_options(p)
    p.set_defaults(func=cmd_import)

    p = sub.add_parser("indices", help="IMO indices of measured logs")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--kind", choices=("zigzag", "turning"), help="default: detected")
    p.add_argument("--heading", type=float, help="zig-zag switch heading [deg] (default: inferred)")
    p.add_argument("--smooth", type=float, default=0.0, help="heading smoothing window [s]")
    p.add_argument("--json", metavar="OUT")
    _add_log_options(p)
    p.set_defaults(func=cmd_indices)
    return ap


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except ShipidError as exc:
        print(f"shipid: error: {exc}", file=sys.stderr)
        return 1
    except (ValueError, OSError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(f"shipid: error: {msg}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
