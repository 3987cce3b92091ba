"""Tables of an identification and its validation (pandas, for Markdown and HTML)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from shipid.evaluation.validate import Validation

INDEX_KEYS = ("approach_speed", "first_overshoot_deg", "second_overshoot_deg", "initial_turning_time",
              "advance", "transfer", "tactical_diameter", "steady_turning_diameter",
              "steady_yaw_rate", "steady_speed", "yaw_rate_at_release", "residual_yaw_rate")  # fmt: skip


def error_table(validations: Sequence[Validation], paper: dict | None = None) -> str:
    """Markdown table of the error std per state (the paper's metric), with divergence."""
    head = ("| log | surge u std (m/s) | sway v std (m/s) | yaw r std (rad/s) | rmse u / v / r "
            "| diverged |")
    if paper:
        head += " paper u / v / r |"
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for v in validations:
        m = v.metrics
        div = f"at {v.simulation.diverged_at:.1f} s" if v.simulation.diverged else "no"
        row = (f"| {v.name} | {m['u']['std']:.4f} | {m['v']['std']:.4f} | {m['r']['std']:.4f} | "
               f"{m['u']['rmse']:.4f} / {m['v']['rmse']:.4f} / {m['r']['rmse']:.4f} | {div} |")
        if paper:
            p = paper.get(v.name)
            row += " " + (" / ".join(f"{x:.4f}" for x in p) if p else "–") + " |"
        lines.append(row)
    return "\n".join(lines)


def _fmt(x) -> str:
    return "–" if x is None else (f"{x:.3f}" if isinstance(x, float) else str(x))


def indices_table(validations: Sequence[Validation]) -> str:
    """Indices measured, from the open-loop replay ("simulated") and from the manoeuvre run
    closed loop on the model ("closed loop", see ``validate.trial_replica``)."""
    lines = ["| log | index | measured | simulated (replay) | closed loop |", "|---|---|---|---|---|"]
    for v in validations:
        meas, sim = v.indices.get("measured", {}), v.indices.get("simulated", {})
        closed = v.indices.get("closed_loop")
        for k in INDEX_KEYS:
            if k in meas or k in sim:
                loop = "n/a" if closed is None else _fmt(closed.get(k))
                lines.append(f"| {v.name} | {k} | {_fmt(meas.get(k))} | {_fmt(sim.get(k))} | "
                             f"{loop} |")  # fmt: skip
    return "\n".join(lines)


STATES = ("u", "v", "r")
UNITS = {"u": "m/s", "v": "m/s", "r": "rad/s"}


def horizons_frame(validations: Sequence[Validation]) -> pd.DataFrame:
    """One row per log and horizon (``validate --horizon``): windows, diverged, and the rms
    error of u, v, r over the log's spread; where the model keeps its training envelope, the
    windows within it and the yaw rate's error over them and over the rest."""
    rows = []
    for v in validations:
        if v.error is not None:
            continue
        for h in v.horizons:
            row = {"log": Path(v.name).name, "horizon [s]": h["horizon_s"],
                   "windows": h["windows"], "diverged": h["diverged"],
                   **{f"{s} error / spread": h["over_spread"][s] for s in ("u", "v", "r")}}
            if h.get("inside_envelope") is not None:
                row.update({"in envelope": h["inside_envelope"],
                            "r error / spread in it": h["over_spread_inside"]["r"],
                            "beyond it": h["over_spread_outside"]["r"]})  # fmt: skip
            rows.append(row)
    return pd.DataFrame(rows)


def metrics_frame(validations: Sequence[Validation]) -> pd.DataFrame:
    """One row per log: rmse and fit % of u, v, r first, then bias and std, and divergence."""
    rows = []
    for v in validations:
        if v.error is not None:
            continue
        m = v.metrics
        row = {"log": Path(v.name).name}
        row.update({f"rmse {s} [{UNITS[s]}]": m[s]["rmse"] for s in STATES})
        row.update({f"fit {s} [%]": m[s]["fit_percent"] for s in STATES})
        row.update({f"bias {s}": m[s]["mean"] for s in STATES})
        row.update({f"std {s}": m[s]["std"] for s in STATES})
        if v.band_shares is not None:
            row.update({f"in CV band {s} [%]": 100 * v.band_shares[s] for s in STATES})
        row["diverged"] = (f"at {v.simulation.diverged_at:.1f} s" if v.simulation.diverged
                           else "no")  # fmt: skip
        rows.append(row)
    if any(v.fitted_to for v in validations if v.error is None):
        # Beside a prediction's errors, a training log's only measure the fit.
        fitted = [v.fitted_to for v in validations if v.error is None]
        for row, f in zip(rows, fitted, strict=True):
            row["fitted to"] = "yes" if f else "no"
    return pd.DataFrame(rows)


def indices_frame(validations: Sequence[Validation]) -> pd.DataFrame:
    """Long form: log, index, measured, simulated (replay), closed loop; with a bootstrap
    ensemble also the 95 % intervals of the two predictions ("[lower, upper]")."""
    rows = []
    with_intervals = any(v.intervals for v in validations)
    for v in validations:
        meas, sim = v.indices.get("measured", {}), v.indices.get("simulated", {})
        closed = v.indices.get("closed_loop")
        for k in INDEX_KEYS:
            if k in meas or k in sim:
                row = {"log": Path(v.name).name, "index": k, "measured": meas.get(k),
                       "simulated (replay)": sim.get(k),
                       "closed loop": None if closed is None else closed.get(k)}  # fmt: skip
                if with_intervals:
                    row["replay 95 %"] = _bracket(v.intervals.get("simulated", {}).get(k))
                    row["closed loop 95 %"] = _bracket(v.intervals.get("closed_loop", {}).get(k))
                rows.append(row)
    columns = ["log", "index", "measured", "simulated (replay)", "closed loop"]
    if with_intervals:
        columns += ["replay 95 %", "closed loop 95 %"]
    return pd.DataFrame(rows, columns=columns)


def start_spread_note(validations: Sequence[Validation]) -> str | None:
    """How far each log's closed-loop indices move with the noise of the replica's start
    (``shipid.evaluation.validate.start_spread``), or None where none was drawn."""
    from shipid.evaluation.validate import START_DRAWS, START_SHOWN

    lines = []
    for v in validations:
        shown = [(k, v.start_spread[k]) for k in START_SHOWN if k in v.start_spread]
        if shown:
            lines.append(f"  {Path(v.name).name}: "
                         + ", ".join(f"{k} ±{x:.2g}" for k, x in shown))  # fmt: skip
    if not lines:
        return None
    return ("closed loop: how far its indices move with the noise of its start (the log's first "
            f"u, v, r; standard deviation over {START_DRAWS} starts drawn with each state's white "
            "noise): a miss within about twice this may be the start's, not the model's\n"
            + "\n".join(lines))


def no_manoeuvre_note(validations: Sequence[Validation]) -> str | None:
    """The logs read as no standard manoeuvre, so given no indices, each with the reason its
    reading gave (``Trial.reason``; not those ``--kind other`` asked for); None where every log
    is one. A zig-zag whose rudder or
    switch heading wanders reads as none; without this line it only lacked rows in the table."""
    shown = [f"{Path(v.name).name} ({v.kind_reason})" for v in validations
             if v.kind == "other" and v.kind_reason not in ("", "given")]  # fmt: skip
    if not shown:
        return None
    return ("No manoeuvre indices (read as no zig-zag, turning circle or pull-out; --kind "
            "zigzag|turning|pull-out judges a log as one): " + "; ".join(shown) + ".")


def switch_heading_note(validations: Sequence[Validation]) -> str | None:
    """Which switch heading each zig-zag's overshoots are measured from (None without a
    zig-zag). A trial's rudder is reversed a little past its nominal switch heading (the MARIN
    KVLCC2 20/20 runs at 20.1°–21.0°); its overshoots are measured from the median heading
    change at its reversals, and the closed loop reverses there too (or where the trial did,
    reversal by reversal, if unevenly), so that both are measured alike. Measured from the
    nominal 20° instead, the MARIN run's second overshoot reads about one degree more, as
    published tables give it."""
    shown = [f"{Path(v.name).name} {v.indices['measured']['switch_heading_deg']:.4g}°"
             for v in validations
             if v.kind == "zigzag" and (v.indices.get("measured") or {}).get("switch_heading_deg")]
    if not shown:
        return None
    return ("Zig-zag overshoots, in every column, are measured from the switch heading at which "
            "the log's rudder was reversed (the median heading change from the approach heading "
            "at its reversals), not from a nominal one, and the closed loop reverses there (at "
            "each reversal's own heading where the trial reversed unevenly): "
            + ", ".join(shown) + ".")


def _bracket(bounds) -> str | None:
    """"[lower, upper]"; "not bounded" where too many replicates diverged or lack the index."""
    if bounds is None or any(math.isnan(b) for b in bounds):
        return None
    if any(math.isinf(b) for b in bounds):
        return "not bounded"
    return f"[{bounds[0]:.4g}, {bounds[1]:.4g}]"
