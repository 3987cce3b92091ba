"""``shipid import``, ``indices`` and ``plot``: logs in, their IMO indices and figures."""

from __future__ import annotations

from pathlib import Path

from shipid.cli.printing import _json_text, _warn
from shipid.cli.reading import _read_files, _read_logs
from shipid.errors import ShipidError


def _number(value: float) -> str:
    """Four significant digits, or tenths where more digits are needed: an execute time of a log
    in epoch seconds (1700000003.1) printed as 1.7e+09."""
    return f"{value:.4g}" if abs(value) < 1e4 else f"{value:.1f}"


def cmd_plot(args) -> int:
    """``shipid plot``: a figure of any logs."""
    from shipid.data.log import common_rudder_convention
    from shipid.outputs import check_outputs
    from shipid.reporting.plots import logs_figure

    check_outputs({"-o": (args.output, "figure")}, [*args.logs, *_read_files(args)])
    # One rudder convention on one axis: a port-positive and a starboard-positive log drew the
    # same rudder with opposite signs, side by side.
    logs, notes = common_rudder_convention(_read_logs(args))
    for note in notes:
        _warn(note)
    logs_figure({Path(p).name: log for p, log in zip(args.logs, logs, strict=True)}, args.output,
                args.title or ", ".join(Path(p).name for p in args.logs))  # fmt: skip
    print(f"figure written to {args.output}")
    return 0


def cmd_indices(args) -> int:
    """``shipid indices``: IMO indices of measured logs."""
    from shipid.outputs import atomic_write_text, check_outputs
    from shipid.trials.indices import manoeuvre_indices
    from shipid.trials.trial import describe_trial, turning_at_order_note

    check_outputs({"--json": (args.json, "json")}, [*args.logs, *_read_files(args)])
    logs = _read_logs(args)
    out = []
    for path, log in zip(args.logs, logs, strict=True):
        trial = describe_trial(log, args.kind, args.heading)
        notes = []
        if args.kind and args.kind != "other":
            # Its indices as that kind are those the log reaches; say so where it reads as
            # another (every turning index printed None for a zig-zag, without a word).
            found = describe_trial(log).kind
            if found != args.kind:
                notes.append(f"--kind {args.kind}, but the log reads as {found}; its "
                             f"{args.kind} indices are those it reaches (None where it never "
                             "does)")  # fmt: skip
        notes += [n for n in (turning_at_order_note(trial),) if n]
        for note in notes:
            _warn(f"{path}: {note}")
        ind = manoeuvre_indices(log, args.kind, heading_deg=args.heading, smooth_s=args.smooth,
                                trial=trial)  # fmt: skip
        # What qualifies the indices travels with them into --json.
        record = {"name": str(path), "indices": ind, **({"warnings": notes} if notes else {})}
        kind = ind.get("kind")
        print(f"{path}: {kind}" + (f" ({ind['reason']})" if kind == "other" else ""))
        for k, v in ind.items():
            if k not in ("kind", "reason"):
                print(f"  {k}: {_number(v)}" if isinstance(v, float) else f"  {k}: {v}")
        if kind == "zigzag" and trial.reversal_headings_deg:
            # Where the rudder was reversed, each time: a trial switched unevenly shows here.
            record["reversal_headings_deg"] = list(trial.reversal_headings_deg)
            print("  reversal_headings_deg: "
                  + ", ".join(f"{h:+.2f}" for h in trial.reversal_headings_deg))
        out.append(record)
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
    if len(args.logs) > 1 and Path(args.output).suffix.lower() in (".csv", ".parquet"):
        # It made a folder of that name, the logs inside it.
        raise ShipidError(f"-o {args.output}: {len(args.logs)} inputs are written to a folder, "
                          f"one log each: give -o DIR (a file takes one input)")  # fmt: skip
    if several:
        check_outputs({"-o": (args.output, "dir")}, [*args.logs, *_read_files(args)])
        targets = [Path(args.output) / (Path(p).stem + args.ext) for p in args.logs]
        check_outputs({f"-o {t.name}": (t, "log") for t in targets},
                      [*args.logs, *_read_files(args)])  # fmt: skip
        stems = [t.name for t in targets]
        dup = next((n for n in stems if stems.count(n) > 1), None)
        if dup:
            raise ShipidError(f"-o {args.output}: two inputs would both be written as {dup}")
    else:
        check_outputs({"-o": (args.output, "log")}, [*args.logs, *_read_files(args)])
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
