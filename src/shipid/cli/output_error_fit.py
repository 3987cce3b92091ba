"""``identify``'s output-error fit beside its LS-SVM fit: when the default fits it (where the
LS-SVM's free runs leave only the sensors' noise), how it is printed, and which of the two fits,
or ``--refine``'s, the model file keeps once both are checked beyond the logs."""

from __future__ import annotations

import sys

from shipid.cli.printing import _term_display


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


def _turns_apart(lssvm: dict, refined: dict) -> str | None:
    """Why two fits' held-rudder turns (plausibility reports) disagree
    (``predictions_apart.rates_apart``), or None; a turn that diverges or never settles has no
    steady yaw rate, and sides where neither turns steadily are left to the plausibility
    checks."""
    from shipid.identification.predictions_apart import rates_apart, settled_yaw_rates

    shown = []
    for side in ("starboard", "port"):
        rates = settled_yaw_rates((lssvm, refined), side)
        if all(r is None for r in rates):
            continue
        shown.append(f"{side} " + " against ".join(
            "no steady turn" if r is None else f"{abs(r):.3g}" for r in rates[::-1]) + " rad/s")
        if rates_apart(rates):
            return (f"its {lssvm.get('rudder_deg', 35):g}° held-rudder turns and the LS-SVM "
                    f"fit's are far apart (steady yaw rates {', '.join(shown)}): the logs, which "
                    "both fit, do not say which extrapolation holds")  # fmt: skip
    return None


def _output_error_where_noise_is_left(ident, logs, names, args, record: dict, physics=None):
    """The default: output error where the LS-SVM's free runs leave only the sensors' noise
    (``output_error.noise_dominates``) and its own residuals come out white; else the LS-SVM
    fit, and one line saying why (both into ``record``, kept in the model file). Returns
    (refinement, ensemble), (None, None) for the LS-SVM."""
    from shipid.identification.output_error import (
        INFLATION_WARNING,
        NOISE_DOMINATES,
        noise_dominates,
        noise_ratios,
    )

    ratios = noise_ratios(ident.model, logs)
    worst = ratios.max(axis=0)
    record["noise_ratios"] = {str(s): float(x) for s, x in worst.items()}
    if not noise_dominates(ratios):
        state = str(worst.idxmax())
        record["why"] = (f"the LS-SVM's free runs miss the logs by up to {worst[state]:.3g} times "
                         f"their sensor noise in {state} (more than {NOISE_DOMINATES:g}): model "
                         "error, not noise, is what is left")  # fmt: skip
        print(f"output error: not fitted; {record['why']} (--output-error fits it anyway)")
        return None, None
    print(f"output error: the LS-SVM's free runs miss the logs by at most {worst.max():.3g} "
          "times their sensor noise, so noise is what it leaves: fitting by maximum-likelihood "
          "output error (--no-output-error to keep the LS-SVM fit)")  # fmt: skip
    fit, ensemble = _output_error(ident, logs, names, args, physics)
    inflation = fit.statistics["covariance_inflation"]
    if not inflation < INFLATION_WARNING:
        record["why"] = (f"its residuals are correlated (standard errors ×{inflation:.3g}): model "
                         "error after all")  # fmt: skip
        print(f"output error: {record['why']}; the model file keeps the LS-SVM fit")
        return None, None
    record.update(fit="output error", why="noise is what the LS-SVM leaves")
    return fit, ensemble


def _output_error_holding_rows(refinement, ensemble, physics, logs, flags, record: dict):
    """Output error does not hold ``--constraints derivatives`` or ``rudder-ahead`` (rows on its
    coefficients), but its fit can be checked against them: kept where it meets every row (said),
    else the LS-SVM fit that holds them, and the first row it goes past. Returns (refinement,
    ensemble), (None, None) for the LS-SVM."""
    from shipid.identification.physics import rows_unmet

    unmet = rows_unmet(physics, refinement.model, logs)
    if unmet:
        record.update(fit="LS-SVM", why=f"its fit goes past {' and '.join(flags)} ({unmet[0]}"
                      + (f", and {len(unmet) - 1} more" if len(unmet) > 1 else "") + ")")
        print(f"output error: {record['why']}; the model file keeps the LS-SVM fit, which holds "
              "it")  # fmt: skip
        return None, None
    print(f"output error: its fit holds {' and '.join(flags)} too (checked on its coefficients)")
    return refinement, ensemble


def _output_error_passed_over(ident, logs, args, explicit_band: bool) -> dict:
    """Where ``--bootstrap``, ``--error-band`` or ``--residual`` keep the LS-SVM fit that the
    default would have replaced by output error (its free runs leave only the sensors' noise),
    one line saying so: on the paper's ship the LS-SVM bootstrap's intervals held the true
    coefficients in 36 % of cases, output error's own in 95 %, and a user adding --bootstrap for
    intervals got the other fit without a word. Returns the model file's record."""
    from shipid.identification.output_error import noise_dominates, noise_ratios

    flag = ("--bootstrap" if args.bootstrap is not None
            else "--error-band" if explicit_band else "--residual")  # fmt: skip
    ratios = noise_ratios(ident.model, logs)
    worst = ratios.max(axis=0)
    record = {"fit": "LS-SVM", "why": f"{flag} describes the LS-SVM fit",
              "noise_ratios": {str(s): float(x) for s, x in worst.items()}}
    if noise_dominates(ratios):
        print(f"output error: not fitted, since {flag} describes the LS-SVM fit; its free runs "
              f"miss the logs by at most {worst.max():.3g} times their sensor noise, where a "
              "plain identify fits by output error, with intervals of its own (on the paper's "
              "ship they held the true coefficients in 95 % of cases, the LS-SVM bootstrap's "
              f"in 36 %; leave out {flag} for that fit)")  # fmt: skip
    return record


def _output_error(ident, logs, names, args, physics=None):
    """``identify --output-error``: the maximum-likelihood output-error fit from the LS-SVM model
    (holding the sign constraints and bounds of ``physics``), printed with its standard errors
    and intervals; returns the fit and its ensemble."""
    from shipid.identification.output_error import coefficient_intervals, output_error
    from shipid.identification.physics import coefficient_bounds

    bounds, reasons, bound_notes = coefficient_bounds(physics, ident.model, logs)
    pairs = [b for terms in bounds.values() for b in terms.values()]
    held = sum(lo == hi for lo, hi in pairs)
    counts = [f"{n} coefficient{'s' * (n != 1)} {what}"
              for n, what in ((len(pairs) - held, "bounded"), (held, "given")) if n]
    print("fitting by maximum-likelihood output error (unfiltered logs"
          + "".join(f"; {c}" for c in counts) + ")…", file=sys.stderr)  # fmt: skip
    fit, ensemble = output_error(ident.model, logs, max_nfev=args.refine_evals, names=names,
                                 seed=args.seed, bounds=bounds, reasons=reasons)  # fmt: skip
    fit.warnings[:0] = [n for n in bound_notes if n not in fit.warnings]
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
