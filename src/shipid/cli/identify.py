"""``shipid identify``: a model from logs, the structure, prefilter, γ and fit chosen for them
(LS-SVM, output error, a kernel residual), checked for plausibility, with its bootstrap."""

from __future__ import annotations

import json
import sys
from types import SimpleNamespace

from shipid.cli.common import (
    VESSEL_NAMES,
    _ahead,
    _approach,
    _fmt_speed,
    _json_text,
    _log_particulars,
    _log_record,
    _one_rps,
    _parse_bounds,
    _parse_drop,
    _pd,
    _physics,
    _read_files,
    _reference_speed_notes,
    _rudder_drag_note,
    _std_errors,
    _structure,
    _structure_edit,
    _term_display,
    _training_logs,
    _warn,
    _warn_approach,
)
from shipid.errors import ShipidError

# γ grid of --gamma auto with a reference ship's prior (select's default starts at 1e2).
REFERENCE_PRIOR_GAMMAS = (0.1, 1.0, 10.0, 1e2, 1e3, 1e4, 1e5, 1e6)
# The name of the model `identify` fits where select's candidates are averaged.
AVERAGED = "average of the candidates select's choice picks"


def _paper_out_filtered(choice, table) -> str | None:
    """Why the paper's structure, chosen for the logs (its unfiltered fit passed the checks), is
    out after all, or None: none of its fits through the prefilters the logs cannot tell apart
    passes them, so the one chosen does not either. The tanker's two 10°/10° zig-zags, its checks
    at its gear's 10°: the paper's fit unfiltered passed, through 0.25 and 0.125 Hz it ended its
    held turns going astern, and the model written all but stopped in its steady 10° turn
    (the yaw rate 87 % off) where the race structure, compared, came within 16–22 %."""
    from shipid.identification.auto_structure import PAPER

    if choice is None or choice.how != "paper" or "implausible" not in table.columns:
        return None
    row = table[table["chosen"]].iloc[0]
    why = row["implausible"]
    if not isinstance(why, str) or not why:
        return None
    shown = "none" if row["cutoff_hz"] is None or row["cutoff_hz"] != row["cutoff_hz"] \
        else f"{row['cutoff_hz']:.4g} Hz"  # fmt: skip
    return (f"the paper's {PAPER}, fitted through the prefilters the logs cannot tell apart, is "
            f"implausible ({shown}: {why.split('; ')[0]}), so the rudder's inflow is compared")


def _members(choice, physics, gamma_given: bool) -> list:
    """Select's candidates the model averages (``select --average``'s): where the terms were
    chosen by select and no γ or physics (a prior, constraints: per structure) is given."""
    return choice.members if choice is not None and physics is None and not gamma_given else []


def _chosen_prefilter(logs, fit):
    """The prefilter's cut-off chosen for the fits ``fit`` makes (``choose_prefilter``, the
    plausibility checks breaking the logs' ties) and its table; printed."""
    from shipid.identification.plausibility import disqualifying_at_approach
    from shipid.identification.prefilter import choose_prefilter

    cutoff, table = choose_prefilter(logs, fit, implausible=disqualifying_at_approach(logs))
    shown = "none" if cutoff is None else f"{cutoff:.4g} Hz"
    print(f"prefilter of u, v, r: {shown} (chosen by the free-run error on the logs"
          f"{_ruled_out(table)}; --filter HZ|none to set it)")  # fmt: skip
    return cutoff, table


def _ruled_out(table) -> str:
    """The fits the prefilter's choice checked and found implausible, 'none (its reason), 2.5 Hz
    (...)': passed over, or chosen where none tied on the logs was plausible."""
    if "implausible" not in table.columns:
        return ""
    out = [f"{'none' if c is None or c != c else f'{c:.4g} Hz'} ({why.split('; ')[0]})"
           for c, why in zip(table["cutoff_hz"], table["implausible"], strict=True)
           if isinstance(why, str) and why]  # fmt: skip
    return f"; implausible fits: {', '.join(out)}" if out else ""


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


def _refuse_no_headway(log, name: str) -> None:
    """One line where the first training log, whose approach the plausibility checks and the
    manoeuvres start from, has none ahead (a log run astern throughout was fitted in full
    before, and refused only then, its speed printed to 17 digits)."""
    speed = _approach(log, "u")
    if speed is None or not speed > 0:
        how = "goes astern" if speed is not None and speed < 0 else "starts without headway"
        shown = "no u" if speed is None else f"u = {speed:.3g} m/s"
        raise ShipidError(f"{name}: the first training log {how} at its approach ({shown}); the "
                          "checks and manoeuvres start from its approach ahead: trim it to the "
                          "manoeuvre (--start), or give a log that runs ahead first")


def cmd_identify(args) -> int:
    """``shipid identify``: a model from logs (LS-SVM, optional refinement, checks)."""
    from shipid.data.preprocess import lowpass
    from shipid.identification.identify import averaged_model, identify
    from shipid.identification.plausibility import (
        new_failures,
        plausibility_at_approach,
        sharpest_curvature,
        slow_mode_note,
    )
    from shipid.outputs import atomic_write_text, check_outputs
    from shipid.reporting.modelfile import model_text

    check_outputs({"-o": (args.output, "json")}, [*args.logs, *_read_files(args)])
    if args.bootstrap is not None and args.refine:
        raise ShipidError("--bootstrap describes the LS-SVM fit; it does not go with --refine")
    asked = args.output_error == "always"
    if asked and (args.refine or args.bootstrap is not None):
        raise ShipidError("--output-error is its own fit with its own intervals; it does not go "
                          "with --refine or --bootstrap")  # fmt: skip
    from shipid.identification.physics import ROW_CONSTRAINTS, parse_constraints, unboxed

    # Output error holds sign constraints and bounds (box bounds on its coefficients), not the
    # conditions on the equation-error regression: said before the logs are read and the
    # structure chosen (select's search, seconds).
    flags = parse_constraints(args.constraints)
    given_physics = unboxed(SimpleNamespace(
        prior=args.prior, steady_speed=bool(args.steady_speed) or flags["steady_speed"],
        stable=flags["stable"], derivatives=flags["derivatives"],
        rudder_ahead=flags["rudder_ahead"]))
    if asked and given_physics:
        raise ShipidError(f"--output-error holds --constraints signs and --bound; it does not hold "
                          f"{given_physics[0]} (the LS-SVM fit does: leave out --output-error)")
    if args.refine and given_physics:  # its free runs went past them without a word
        raise ShipidError(f"--refine holds --constraints signs and --bound; it does not hold "
                          f"{given_physics[0]} (the LS-SVM fit does: leave out --refine)")
    explicit_band = args.error_band not in (None, "none")
    if explicit_band and (args.refine or asked):
        raise ShipidError("--error-band describes the LS-SVM fit; it does not go with --refine "
                          "or --output-error")  # fmt: skip
    if args.residual and (args.refine or asked or args.bootstrap is not None):
        raise ShipidError("--residual adds a kernel residual to the LS-SVM fit; it does not go "
                          "with --refine, --output-error or --bootstrap")  # fmt: skip
    if args.cv is not None:
        from shipid.identification.cross_validation import parse_cv

        parse_cv(args.cv)  # before the logs are read; 'foo' went unnoticed without --gamma auto
    logs = _training_logs(args)
    raw_logs = logs  # the output-error fit needs the noise as measured, not prefiltered
    one_rps = _one_rps(logs, args)
    names = [str(p) for p in args.logs]
    _refuse_no_headway(logs[0], names[0])  # before the fit: the checks start from it
    _edit_into_model(args, logs)
    gamma_given = args.gamma is not None
    drop_given = args.drop
    bounds_given = list(args.bound or [])  # the choice may add its own
    choice = _choose_structure(args, logs, names)
    physics = _physics(args, logs, _structure(args), chosen=choice is not None)
    if physics is not None and physics.prior_source:
        print(f"prior: {physics.prior_source}" + (
            "; the bootstrap resamples the logs, not the reference: its intervals do not hold "
            "how far the reference is from the ship" if args.bootstrap is not None else ""))
    # Terms chosen by select: the model is the average of the candidates its choice rule picks
    # on resampled held-out logs (each at its own γ), as `select --average` writes it, where no
    # γ or physics (a prior, constraints: per structure) is given.
    members = _members(choice, physics, gamma_given)

    def fit_model(fit_logs, fit_gamma, fit_names=None):
        """The model of ``fit_logs`` fitted as the file's is: the structure, or the average
        of select's candidates."""
        if members:
            return averaged_model(fit_logs, members, first=args.model, name=AVERAGED,
                                  form=args.form, names=fit_names, estimator=args.estimator)
        return identify(fit_logs, model=args.model, form=args.form, gamma=fit_gamma,
                        drop=_parse_drop(args.drop), names=fit_names, force=True,
                        estimator=args.estimator, physics=physics).model  # fmt: skip

    cutoff, filter_by = args.filter, "given"
    if cutoff == "auto":

        def fit(candidate_logs):
            return fit_model(candidate_logs, 1e4 if args.gamma == "auto" else args.gamma, names)

        cutoff, table = _chosen_prefilter(logs, fit)
        filter_by = "free-run error, one-standard-error rule"
        paper_out = _paper_out_filtered(choice, table)
        if paper_out and not args.force:
            try:  # a fit the logs cannot determine: identify's own refusal says why, as before
                identify([lowpass(log, cutoff) for log in logs] if cutoff is not None else logs,
                         model=args.model, gamma=1e4 if args.gamma == "auto" else args.gamma,
                         names=names, force=False,
                         estimator=args.estimator, physics=physics)  # fmt: skip
            except ShipidError:
                paper_out = None
        if paper_out:
            # The paper's structure as identify fits it fails the checks its unfiltered fit
            # passed: the rudder's inflow is compared after all, each candidate through its own
            # prefilter, and the choice's prefilter is chosen again.
            from shipid.identification.auto_structure import AUTO

            args.model, args.drop = AUTO, drop_given
            args.gamma = args.gamma if gamma_given else None
            choice = _choose_structure(args, logs, names, paper_out)
            physics = _physics(args, logs, _structure(args), chosen=choice is not None)
            members = _members(choice, physics, gamma_given)
            cutoff, table = _chosen_prefilter(logs, fit)
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
    if choice is not None:
        _bounds_holding_nothing(bounds_given, ident.model)
        for line in choice.nothing_dropped:
            _warn(line)
    if members:
        averaged = fit_model(logs, gamma, names)
        worse = _average_fails(averaged, ident.model, logs)
        if worse:
            # As select --average: never an average that fails checks the chosen one passes.
            members = choice.members = []
            ident.warnings.append(f"structure: the average of select's candidates is implausible "
                                  f"({'; '.join(worse[:2])}); the model is the chosen candidate")
        else:
            ident.model = averaged
    if choice is not None and choice.alternatives:
        choice.alternatives, refitted = _refit_alternatives(choice, args, logs, names, gamma)
        choice.alternatives_fit = "model" if refitted else "comparison"
    speed, rps = _approach(logs[0], "u"), _approach(logs[0], "n")
    _warn_approach(logs, names)
    # An average has no standard errors of its own (its candidates' are each fit's).
    drag = _rudder_drag_note(ident.model, logs, speed, rps,
                             None if members else _std_errors(ident).get("u"))  # fmt: skip
    if drag:
        ident.warnings.append(drag)
    prep = {**_log_record(args, logs), "filter_hz": cutoff,
            "filter_by": filter_by if cutoff is not None else None}
    refinement = None
    if members:
        print(ident.model.equations())
        hint = "" if args.bootstrap is not None else "; --bootstrap N intervals of the " \
            "coefficients and predictions"  # fmt: skip
        print(f"(the average of {len(members)} candidates, each at its own γ{hint})")
    else:
        print(ident.model.equations(std_errors=_std_errors(ident)))
        print("(± standard errors of the equation-error fit: they hold the scatter of the fitted "
              "accelerations, not the bias that noise in u, v, r leaves in the coefficients; "
              "--output-error gives intervals that hold the true values, --bootstrap N "
              "intervals of the predictions)")  # fmt: skip
    for dof, d in ident.diagnostics.items():
        print(f"{dof}: condition number {d['condition_number']:.3g}, one-step R² "
              f"{d['one_step_r2']:.4f}, bias b = {ident.discrete[dof]['bias']:.4g}")
    residual, hybrid = None, None
    if args.residual:  # no refinement goes with it: the model is the LS-SVM one
        residual, hybrid = _kernel_residual(args, ident.model, logs, cutoff, fit_model, gamma,
                                            raw_logs, names, ident.warnings)  # fmt: skip
    def cv_band(cv):
        """The cross-validated error band of this fit: the same prefilter, structure, γ,
        physics and residual without each log (or block)."""
        from shipid.evaluation.error_band import cross_validated_band

        def refit_without(train):
            fitted_on = [lowpass(x, cutoff) for x in train] if cutoff is not None else train
            return _with_residual(fit_model(fitted_on, gamma), fitted_on, residual)

        found = cross_validated_band(refit_without, raw_logs, names, cv)
        chosen = "γ, the prefilter and the kernel residual's γ and σ" if residual and \
            residual["residual"] else "γ and the prefilter"
        return found, f"{found.describe()} ({chosen} as chosen on all logs); stored for validate"

    def print_runs(found) -> None:
        """How each held-out log (or block) of the band fared: what the fit predicts of a log
        it was not fitted to."""
        print(f"each held-out {found.held_out[:-1]}, run free on the model fitted without it "
              "(rms error over its spread, bias included; 1: no better than the log's own "
              "mean):")  # fmt: skip
        print(_pd().DataFrame(found.run_rows()).to_markdown(index=False, floatfmt=".3g"))

    band = None
    if explicit_band:
        band, said = cv_band(args.error_band)
        print(said)
        print_runs(band)
    ensemble = None
    if args.bootstrap is not None:
        from shipid.identification.identify import weighted_refit
        from shipid.identification.uncertainty import bootstrap

        if members:
            refit = _averaged_refit(logs, members, args, names)
        else:
            refit = weighted_refit(logs, model=args.model, form=args.form, gamma=gamma,
                                   drop=_parse_drop(args.drop), names=names,
                                   estimator=args.estimator, physics=physics)  # fmt: skip
        ensemble = bootstrap(logs, refit, args.bootstrap, args.block, args.seed, progress=True)
        table = ensemble.coefficient_table()
        table["term"] = [_term_display(t) for t in table["term"]]
        print(f"\n95 % intervals of the coefficients ({ensemble.replicates} replicates: "
              f"{ensemble.resampling}):")
        print(table.to_markdown(index=False, floatfmt=".4g"))
    if args.refine:
        from shipid.identification.physics import coefficient_bounds
        from shipid.identification.refine import refine  # scipy.optimize: only when asked

        bounds, reasons, _ = coefficient_bounds(physics, ident.model, logs)  # noted by the fit
        how = "whole logs" if args.segment is None else f"{args.segment:g} s segments"
        print(f"refining by output error ({how})…", file=sys.stderr)
        refinement = refine(ident.model, logs, segment_s=args.segment, gamma=gamma,
                            max_nfev=args.refine_evals, names=names, progress=True,
                            bounds=bounds, reasons=reasons)  # fmt: skip
        print()
        print("refined by output error:")
        print(refinement.model.equations())
        print(f"cost {refinement.cost_initial:.4g} → {refinement.cost_final:.4g} in "
              f"{refinement.nfev} evaluations ({refinement.message})")
        print(_free_run_table(refinement))
    if asked:
        refinement, ensemble = _output_error(ident, raw_logs, names, args, physics)
    elif args.output_error == "auto" and not (args.refine or args.bootstrap is not None
                                             or explicit_band or args.residual):
        prep["output_error"] = {"fit": "LS-SVM"}
        rows_only = [flag for _, flag in ROW_CONSTRAINTS if flag in given_physics]
        if given_physics and len(rows_only) < len(given_physics):  # it would fit them away
            prep["output_error"]["why"] = f"it would not hold {given_physics[0]}"
            print(f"output error: not fitted, since {prep['output_error']['why']}; the LS-SVM "
                  "fit does")  # fmt: skip
        else:
            from shipid.identification.physics import without_rows

            refinement, ensemble = _output_error_where_noise_is_left(
                ident, raw_logs, names, args, prep["output_error"],
                without_rows(physics) if rows_only else physics)  # fmt: skip
            if refinement is not None and rows_only:
                refinement, ensemble = _output_error_holding_rows(
                    refinement, ensemble, physics, logs, rows_only, prep["output_error"])
    elif args.output_error == "auto" and not (args.refine or given_physics):
        prep["output_error"] = _output_error_passed_over(ident, raw_logs, args, explicit_band)
    final = ident.model
    if speed is None or not speed > 0:  # the prefilter moved it (checked before the fit)
        _refuse_no_headway(logs[0], names[0])
    # A hybrid is checked whole: its stability, steady speed and held-rudder turns.
    curvature = sharpest_curvature(logs, speed)
    if residual is not None:
        one_rps = None  # its kernel residual is the fit's at that one rps

    # A hybrid is written as fitted: its kernel residual is the fit's, at the fit's terms.
    ahead = _ahead(logs, args) if residual is None else None

    def as_written(model):
        """The model as the file will have it: carried to every rps where the logs run at one
        (checked from the approach its manoeuvres will start from), in its ahead forms where
        they never go astern."""
        return _as_written(model, one_rps, ahead)

    plausibility, notes = plausibility_at_approach(hybrid or as_written(ident.model), speed, rps,
                                                   curvature=curvature, astern=True)  # fmt: skip
    if refinement:
        refined_report, refined_notes = plausibility_at_approach(
            as_written(refinement.model), speed, rps, curvature=curvature,
            astern=True)  # fmt: skip
        worse = new_failures(plausibility, refined_report, ident.model)
        apart = _turns_apart(plausibility, refined_report)
        # Checks the LS-SVM fit fails and output error's passes: its turn is then no reference
        # to doubt output error's by. On the paper's ship (seed 107 of the demo's trials) the
        # LS-SVM's 35° turns never settled, output error's came within 2 % of the truth's, and
        # the default had handed out the LS-SVM fit.
        lssvm_fails = new_failures(refined_report, plausibility, ident.model)
        from shipid.data.log import rudder_reach_deg
        from shipid.identification.predictions_apart import beyond_the_logs_rudder

        reach = rudder_reach_deg(raw_logs)
        held_beyond = bool(apart) and beyond_the_logs_rudder(plausibility["rudder_deg"], reach)
        default_fit = (prep.get("output_error") or {}).get("fit") == "output error"
        if worse:
            # Never hand out a model that fails checks the LS-SVM model passes, or fails worse.
            ident.warnings.append(
                "refinement: the refined model fails plausibility checks the LS-SVM model passes ("
                + "; ".join(worse[:2]) + "); the model file's model is the LS-SVM one, the "
                "refined one is kept under identification.refinement.refined_model")
            if not args.refine:  # an output-error fit
                ensemble = None  # its draws describe the output-error model, not this one
                if "output_error" in prep:
                    prep["output_error"].update(fit="LS-SVM", why="the output-error model fails "
                                                "plausibility checks the LS-SVM model passes")
        elif asked and apart:
            final, plausibility, notes = refinement.model, refined_report, refined_notes
            ident.warnings.append(f"output error: {apart} (kept, as --output-error asks; "
                                  "--no-output-error for the LS-SVM fit)")  # fmt: skip
        elif default_fit and apart and not lssvm_fails and held_beyond:
            # The default's output-error fit, where it and the LS-SVM fit turn far apart beyond
            # the logs' rudder: where the structure holds the two agree (the paper's ship);
            # through a structure that is not the truth (the KVLCC2's MMG model,
            # `blanke-race+race-damping`, from 20°/20° zig-zags) output error's 35° tactical
            # diameters came 100–140 % long, the LS-SVM's within 4 %
            # (``benchmarks/study_uncertainty.py``, ``default_command_mismatch``). Inside the
            # logs' rudder output error is kept: the tanker's 10°/10° zig-zags, its gear's 10°
            # held, output error's steady 10° turns came 3–10 % off where the LS-SVM's came
            # 15–25 % (``benchmarks/study_esso_sister_mmg.py``, ``tanker_truth_from_logs``).
            ensemble = None
            prep["output_error"].update(fit="LS-SVM", why=apart)
            print(f"output error: {apart}; the model file keeps the LS-SVM fit (--output-error "
                  "to keep output error's)")  # fmt: skip
        else:
            if default_fit and apart:
                why = (f"the LS-SVM fit fails checks it passes ({lssvm_fails[0]})" if lssvm_fails
                       else f"a turn the logs' rudder reached (their largest {reach:.3g}°), "
                            "where output error's consistent fit holds")  # fmt: skip
                prep["output_error"]["turns"] = f"{apart.split(' (')[0]}, but {why}"
                print(f"output error: kept; {prep['output_error']['turns']}")
            final, plausibility, notes = refinement.model, refined_report, refined_notes
    if ensemble is not None and args.bootstrap is not None and hybrid is None:
        _report_replicates(ensemble, _replicates_checked(
            ensemble, plausibility, final, as_written, speed, rps, curvature), ident)
    if args.error_band is None and final is ident.model and len(raw_logs) >= 2:
        # By default, from two logs on: how far the free runs stray from a log left out.
        band, said = cv_band("logo")
        print(f"{said} (--error-band none to skip)")
        print_runs(band)
    elif args.error_band is None and len(raw_logs) == 1:
        print("one log: none was held out, so nothing here says how the model predicts another; "
              "judge it on a log it was not fitted to (shipid validate MODEL.json LOG), or on "
              "quarters of this one (--error-band blocks:4)")  # fmt: skip
    sl = plausibility["straight_line"]
    if sl:
        slow = slow_mode_note(sl["eigenvalues"])
        print(f"straight-line {'stable' if sl['stable'] else 'UNSTABLE'} (largest sway–yaw "
              f"eigenvalue real part {sl['max_real_part']:.3g} 1/s{'; ' + slow if slow else ''}); "
              "surge equilibrium "
              f"{_fmt_speed(plausibility['surge_equilibrium'])}; checked from the "
              f"{plausibility['approach']}"
              + (", with its kernel residual" if hybrid else ""))  # fmt: skip
    ident.warnings.extend(f"plausibility: {n}" for n in notes)
    from shipid.identification.beyond_the_logs import (
        above_the_logs_rps,
        approach_beyond_logs,
        at_the_logs_other_rps,
        below_the_logs_rps,
        given_steady_speeds,
        missed_steady_speed,
        rudder_reversed_warning,
    )

    beyond = approach_beyond_logs(plausibility, ident.envelope)
    if beyond and not given_steady_speeds(physics):  # a speed given is no extrapolation
        ident.warnings.append(beyond)
    for beyond_rps in (below_the_logs_rps, above_the_logs_rps):
        said = beyond_rps(hybrid or as_written(final), plausibility, logs)
        if said:
            ident.warnings.append(said)
    ident.warnings.extend(at_the_logs_other_rps(hybrid or as_written(final), plausibility, logs))
    reversed_rudder = rudder_reversed_warning(hybrid or as_written(final),
                                              plausibility["approach_speed"], plausibility["rps"])
    if reversed_rudder:
        ident.warnings.append(f"plausibility: {reversed_rudder}")

    for u, n in given_steady_speeds(physics):  # where the user says the ship runs steady
        at = plausibility_at_approach(hybrid or as_written(final), u, n, u, n)[1]
        ident.warnings.extend(f"plausibility at {u:.4g} m/s, {n:.4g} rps (--steady-speed): {w}"
                              for w in at)  # fmt: skip
        missed = missed_steady_speed(hybrid or as_written(final), u, n)
        if missed:
            ident.warnings.append(missed)
    if refinement:
        ident.warnings.extend(f"refinement: {n}" for n in refinement.warnings)
    text = model_text(ident, args.logs, preprocessing=prep, refinement=refinement,
                      plausibility=plausibility, model=final, selection=gamma_report,
                      particulars=_log_particulars(logs),
                      uncertainty=ensemble.to_dict() if ensemble else None,
                      error_band=band.to_dict() if band else None, residual=residual,
                      structure_choice=choice.to_dict() if choice else None)  # fmt: skip
    from shipid.reporting.modelfile import prime_record

    prime = prime_record(final, _log_particulars(logs), speed)
    text, written_prime = _written_text(text, one_rps, ahead, args.output)
    _print_prime(written_prime or prime)
    atomic_write_text(args.output, text)
    for w in ident.warnings:
        _warn(w)
    print(f"model written to {args.output}")
    note = _published_model_note(logs) or _sister_ship_note(logs, args.output, speed)
    if note:
        print(note)
    return 0


def _published_model_note(logs) -> str | None:
    """Where the logs say their ship is one whose published model is built in (the KVLCC2's
    MMG model): the commands that use it, and what it did on that ship's real runs."""
    from shipid.vessels import get_vessel

    ships = {str(log.attrs.get("ship", "")).strip().lower() for log in logs}
    known = sorted(ships & set(VESSEL_NAMES) - {"scale-ship"})
    if not known:
        return None
    name = known[0]
    # Not where the logs run at another scale than the built-in ship (MARIN's files read
    # without --scale: the full-scale ship, the MMG model's 7 m one).
    if _reference_speed_notes(get_vessel(name), logs, [""] * len(logs)):
        return None
    return (f"{name}: its published model is built in: shipid validate {name} LOG... judges it "
            f"on your logs, and shipid correct {name} LOG... -o SHIP.json keeps it whole and "
            "fits only what it misses (on the KVLCC2's real runs, closer to the runs left out "
            "than a model identified from scratch: docs/kvlcc2.md)")  # fmt: skip


# The KVLCC2's block coefficient is 0.81; the sister's evidence is the Esso Osaka's (0.83). A
# finer hull (a container ship's 0.6) is not the KVLCC2's sister.
FULL_FORM_CB = 0.75


def _sister_ship_note(logs, model_path, speed: float | None) -> str | None:
    """One log of a full-form hull whose particulars ``shipid mmg`` can take and which has no
    built-in model: the sister ship's MMG model (the KVLCC2's prime coefficients with these
    particulars), fitted to no log, predicted the Esso Osaka's other logs better than a fit to
    one of its zig-zag files (``benchmarks/study_esso_sister_mmg.py``); from two files on the
    fits do about as well, so it is said for one log only. The command it gives takes the
    particulars from the model file just written (``model_path``) and the log's approach
    ``speed``."""
    from shipid.data.particulars import logs_particulars

    if len(logs) != 1:
        return None
    found = logs_particulars(logs)
    if found is None or None in (found.beam, found.draught, found.mass) \
            or found.block_coefficient is None or found.block_coefficient < FULL_FORM_CB:
        return None
    approach = f"{speed:.3g}" if speed else "U"
    return (f"one log of a full-form hull (Cb {found.block_coefficient:.2f}, the KVLCC2's 0.81): a "
            "sister ship's model may predict its other manoeuvres better than a fit to one log. "
            f"shipid mmg kvlcc2 --particulars {model_path} --rps logs --speed {approach} -o "
            "SHIP.yml writes the KVLCC2's MMG model with this ship's particulars (as this model "
            "file keeps them), fitted to no log (shipid validate SHIP.yml LOG... judges it), and "
            "identify --model blanke-speed+wind --crossflow --prior SHIP.yml --gamma 1 "
            "(blanke-speed where the log has no wind) draws a fit toward it: from one Esso Osaka "
            "zig-zag file at a time, the other zig-zags' yaw rate came 0.21 of its spread with "
            "the sister, 0.30 drawn toward it and 0.34 with the default, the 35° turns' tactical "
            "diameters 19 %, 13 % and 22 % off in the median, 23 %, 26 % and 69 % at worst "
            "(docs/esso.md)")  # fmt: skip


def _replicates_checked(ensemble, report: dict, model, as_written, speed, rps, curvature,
                        given: tuple = (None, None)) -> dict:  # fmt: skip
    """``members_plausibility`` of the bootstrap ``ensemble``: each replicate, as the model file
    will have it, through the checks that rule a model out (from the approach ``model``'s were:
    ``speed``, ``rps``, or the ``given`` speed and rps), counting those it fails where ``model``
    (its check ``report``) does not, by reason."""
    from shipid.identification.plausibility import disqualifying_checks, plausibility_at_approach
    from shipid.identification.uncertainty import members_plausibility

    passed = disqualifying_checks(report, model)

    def reasons(member) -> list[str]:
        written = as_written(member)
        found = disqualifying_checks(plausibility_at_approach(
            written, speed, rps, *given, curvature=curvature)[0], written)  # fmt: skip
        return [note for check, (severity, note) in found.items()
                if severity > passed.get(check, (0, ""))[0]]  # fmt: skip

    return members_plausibility(ensemble, reasons)


def _report_replicates(ensemble, record: dict, ident) -> None:
    """Keep ``record`` (``_replicates_checked``) with ``ensemble``, print it, and warn where
    many replicates fail the checks."""
    from shipid.identification.uncertainty import implausible_members_note

    ensemble.plausibility = record
    print(f"plausibility of {record['checked']} of the {ensemble.replicates} replicates: "
          f"{record['implausible']} fail checks the model passes" + "".join(
              f"; {why}: {count}" for why, count in list(record["reasons"].items())[:3]))
    weak = implausible_members_note(record, ensemble.members_label)
    if weak:
        ident.warnings.append(f"bootstrap: {weak}")


def _as_written(model, rps: float | None, ahead=None):
    """``model`` as the model file will have it: carried to every propeller speed from ``rps``
    (None: as it is), then in the forms ``ahead`` (``shipid.dynamics.astern.AsternForms``;
    None: none); ``model`` itself where nothing changes."""
    from shipid.dynamics.similarity import rps_similar, similarity_map

    if rps is not None and similarity_map(model.structure, rps).changes:
        model = rps_similar(model, rps)
    return ahead.written(model) if ahead else model


def _written_text(text: str, rps: float | None, ahead, path) -> tuple[str, dict | None]:
    """The model file ``text`` as it is written (``_rps_similar``, then ``_ahead_forms``), and
    its prime record where either changed it (else None)."""
    prime = None
    for step in (lambda t: _rps_similar(t, rps, path), lambda t: _ahead_forms(t, ahead, path)):
        doc = step(text)
        if doc is not None:
            text, prime = _json_text(doc), doc.get("prime")
    return text, prime


def _ahead_forms(text: str, ahead, path) -> dict | None:
    """The model file ``text`` with its terms in the forms ``ahead``
    (``shipid.dynamics.astern.AsternForms``), said on the command line; None where there are
    none, or no term changes."""
    from shipid.reporting.modelfile import ahead_forms_document, model_from_document

    if not ahead:
        return None
    fitted = json.loads(text)
    doc = ahead_forms_document(fitted, path, ahead)
    if doc is not None:
        record = doc["identification"]["ahead_forms"]
        ratio = record.get("astern_thrust_ratio")
        model = model_from_document(fitted, path)
        hull = ahead.for_model(model).parts(model.structure)[0]
        pushes = (f"its propeller pushes astern {ratio:g} times what it pushes ahead"
                  if ratio is not None else "")  # fmt: skip
        if hull:
            never = "the logs never do" + (", nor reverse the propeller," if pushes else ",")
            does = ("its damping damps, its rudder reverses astern and " + pushes if pushes
                    else "its damping damps and its rudder reverses astern")  # fmt: skip
            keeps = ("--no-ahead-forms keeps the fit's hull and rudder terms, --astern-thrust "
                     "none its thrust" if pushes else "--no-ahead-forms keeps the fit's")
        else:
            never, does, keeps = ("the logs never reverse the propeller,", pushes,
                                  "--astern-thrust RATIO|none to set or keep it")  # fmt: skip
        print(f"going astern: {never} and cannot tell these forms from the fitted ones; "
              f"written as the physics carries them astern ({record['terms']}): the same fit "
              f"ahead, {does} ({keeps})")  # fmt: skip
    return doc


def _rps_similar(text: str, rps: float | None, path) -> dict | None:
    """The model file ``text`` with its model carried to every propeller speed from the one its
    logs run at (``_one_rps``), said on the command line; None where there is none, or no term
    changes. The Esso Osaka's one-file models predicted the held-out logs at another rps with a
    yaw rate error of 0.37 of their spread instead of 0.48 (median of 70;
    ``benchmarks/study_esso_single_logs.py``)."""
    from shipid.reporting.modelfile import rps_similar_document

    if rps is None:
        return None
    doc = rps_similar_document(json.loads(text), rps, path)
    if doc is not None:
        print(f"propeller speed: the logs run at one {rps:.4g} rps, which cannot show how the "
              f"forces depend on it; each term written to scale with it as advance-ratio "
              f"similarity has it ({doc['identification']['rps_similarity']['terms']}): at "
              f"{rps:.4g} rps the model is the fit, at other rps its forces scale with n² and "
              "its manoeuvres start from the logs' approach speed times n/n₀, where it holds "
              "that speed (--no-rps-similarity keeps the fit's terms)")  # fmt: skip
    return doc


def _choose_structure(args, logs, names, paper_out: str | None = None):
    """``--model auto``: the structure for the logs (``shipid.identification.auto_structure``),
    put into ``args.model``, and γ into ``args.gamma`` where none was given (select's, else
    1e4). Returns the choice (None for a given structure). ``paper_out``: why the paper's
    structure is out (``_paper_out_filtered``)."""
    from shipid.identification.auto_structure import AUTO

    choice = None
    if args.model == AUTO:
        from shipid.identification.auto_structure import auto_structure
        from shipid.identification.select import default_library

        # The search fits with the same physics, as select does: a prior over its library.
        physics = _physics(args, logs, default_library(logs)[0], searched=True, chosen=True)
        choice = auto_structure(logs, names, physics, args.cv, args.estimator,
                                _structure_edit(args, logs),
                                announce=lambda m: print(m, file=sys.stderr),
                                paper_out=paper_out)  # fmt: skip
        print(choice.describe())
        # Once each: where the paper's structure gives way after the prefilter's choice, the
        # structure is chosen a second time, and its warnings (a drop of nothing) came twice.
        said = vars(args).setdefault("_structure_warnings_said", set())
        for w in choice.warnings:
            if w not in said:
                said.add(w)
                _warn(f"structure: {w}")
        args.model, args.drop = choice.structure, None  # the drop is in the structure
        if choice.bounds:  # the search held them: the fit of its choice holds them too
            args.bound = [*(args.bound or []), *choice.bounds]
    if args.gamma is None:
        args.gamma = choice.gamma if choice is not None and choice.gamma else 1e4
    return choice


def _bounds_holding_nothing(specs, model) -> None:
    """A warning per ``--bound`` whose term the structure chosen for the logs lacks: such a
    bound applies where a structure has the term (each candidate of the search), and held
    nothing in the model written without a word. With an explicit ``--model`` it is refused.
    (A bound is physics: the model is fitted, not averaged over select's candidates.)"""
    for dof, term in model.structure.lacking(_parse_bounds(specs)):
        _warn(f"--bound {dof}: {term}: the {dof} equation of the structure chosen "
              f"({model.structure.name}) has no {term}: its absence (a coefficient of 0) meets "
              "the bound, which fits nothing (--model with the term fits it)")


def _edit_into_model(args, logs) -> None:
    """--crossflow or --rudder-normal with a given structure: the structure (less --drop) with
    the hull's cross-flow drag or the rudder's normal force, put into ``args.model`` (``auto``
    takes them into every candidate)."""
    from shipid.identification.auto_structure import AUTO

    if not (args.crossflow or args.rudder_normal) or args.model == AUTO:
        return
    edit = _structure_edit(args, logs)
    given = _structure(args)
    args.model, args.drop = edit.apply(given), None
    if args.crossflow and given.with_crossflow_hull(edit.crossflow_length) == given:
        _warn(f"--crossflow: {given.name} has none of the hull's nonlinear damping terms "
              "(|v|v, |v|r, |r|r, v|r|) in sway or yaw; fitted as it is")  # fmt: skip
    if args.rudder_normal and given.with_rudder_normal(edit.rudder) == given:
        _warn(f"--rudder-normal: {given.name} has none of the rudder's force terms (δ, u²δ, "
              "δ², ...); fitted as it is")  # fmt: skip


def _refit_alternatives(choice, args, logs, names, gamma) -> tuple[dict, bool]:
    """The structures that tied with the chosen one, refitted as the file's LS-SVM fit is (the
    model's, unless output error replaces it): the same (prefiltered) logs, γ and physics. The
    comparison fitted each at γ = 1e4 on the unfiltered logs; its fits set against a
    prefiltered, tuned model would show the fitting's difference as the structure's. A structure
    the fit refuses keeps the comparison's fit. Returns the fits and whether every one was
    refitted."""
    from shipid.identification.identify import identify

    out, refitted = {}, True
    for name, compared in choice.alternatives.items():
        try:
            out[name] = identify(logs, model=compared.structure, form=args.form, gamma=gamma,
                                 names=names, force=True, estimator=args.estimator,
                                 physics=_physics(args, logs, compared.structure,
                                                  chosen=True)).model
        except ShipidError as exc:
            _warn(f"structure: {name}, which tied, keeps the comparison's fit ({exc})")
            out[name], refitted = compared, False
    return out, refitted


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


def _print_prime(record: dict | None) -> None:
    """The prime (non-dimensional) coefficients next to the dimensional ones."""
    if not record:
        return
    print(f"\nPrime form (L = {record['length']:g} m, U = {record['speed']:.4g} m/s, the "
          f"{record['speed_basis']}; ρ = {record['rho']:g} kg/m³; u̇′ = u̇ L/U², ṙ′ = ṙ L²/U²):")
    rows = [{"equation": f"{dof}̇′", "term": _term_display(t), "prime": c}
            for dof, terms in record["coefficients"].items() for t, c in terms.items()]
    print(_pd().DataFrame(rows).to_markdown(index=False, floatfmt=".5g"))


def _kernel_residual(args, physical, logs, cutoff, fit_model, gamma, raw_logs, names, warnings):
    """``identify --residual``: the residual's γ and σ (or none) by free-run cross-validation of
    the hybrid, each fold's physical model fitted as this one (``fit_model``: structure, γ,
    physics; the prefilter here); then the residual of ``physical`` on all logs. Returns the
    model file's record (the residual, None when none won, and the search) and the hybrid (None
    likewise)."""
    from shipid.data.preprocess import lowpass
    from shipid.dynamics.hybrid import HybridModel
    from shipid.identification.residual import choose_residual, fit_residual

    def fit(train):
        fitted_on = [lowpass(x, cutoff) for x in train] if cutoff is not None else list(train)
        return fit_model(fitted_on, gamma), fitted_on

    print("choosing the kernel residual by free-run cross-validation…", file=sys.stderr)
    choice = choose_residual(fit, raw_logs, names, cv=args.cv or "auto")
    print(choice.describe())
    warnings.extend(choice.notes)
    record = {"residual": None, "selection": choice.to_dict()}
    if choice.gamma is None:
        return record, None
    residual = fit_residual(physical, logs, choice.gamma, choice.sigma, choice.features)
    hybrid = HybridModel(physical, residual)
    print(hybrid.equations().splitlines()[-1])
    record["residual"] = residual.to_dict()
    return record, hybrid


def _average_fails(averaged, chosen, logs) -> list[str]:
    """The checks that rule a candidate out of select's choice (``disqualifying``: the rudder
    held diverges, turns the wrong way, ends astern...) the average of select's candidates
    fails and the chosen candidate passes, from the first log's approach: as ``select
    --average`` falls back to the chosen candidate. Compared check by check, by severity: a
    chosen candidate that turns the wrong way where the average ends astern is no better (the
    reasons' words differ, and the chosen one was handed out), one that does where the average
    diverges is."""
    from shipid.identification.plausibility import (
        disqualifying_checks,
        plausibility_at_approach,
        sharpest_curvature,
    )

    speed, rps = _approach(logs[0], "u"), _approach(logs[0], "n")
    if speed is None or not speed > 0:
        return []
    curvature = sharpest_curvature(logs, speed)
    chosen_fails, averaged_fails = (
        disqualifying_checks(plausibility_at_approach(m, speed, rps, curvature=curvature)[0], m)
        for m in (chosen, averaged))  # fmt: skip
    return [reason for check, (severity, reason) in averaged_fails.items()
            if severity > chosen_fails.get(check, (0, ""))[0]]


def _averaged_refit(logs, members, args, names):
    """The bootstrap's ``fit(weights)`` of the average of select's candidates: each
    candidate's weighted refit, averaged as the model is (the point refit equals it)."""
    from shipid.identification.identify import average_models, weighted_refit

    refits = [(weighted_refit(logs, model=s, form=args.form, gamma=g, names=names,
                              estimator=args.estimator), w) for s, g, w in members]  # fmt: skip
    total = float(sum(w for _, w in refits))

    def fit(weights):
        return average_models([(f(weights), w / total) for f, w in refits], args.model, AVERAGED)

    return fit


def _with_residual(model, logs, record):
    """``model`` with a residual of the chosen γ and σ fitted on ``logs`` (a fold's refit for
    the error band), or ``model`` where no residual was chosen."""
    if not record or not record["residual"]:
        return model
    from shipid.dynamics.hybrid import HybridModel
    from shipid.identification.residual import fit_residual

    chosen = record["residual"]
    return HybridModel(model, fit_residual(model, logs, chosen["gamma"], chosen["sigma"],
                                           chosen["features"]))  # fmt: skip


def _auto_gamma(args, logs, names, physics=None) -> tuple[float, dict]:
    """γ for the given structure: exact LOO of the LS-SVM pre-screens the grid, free-run
    cross-validation over the logs decides (``shipid.identification.select``)."""
    from shipid.identification.cross_validation import choice_cv
    from shipid.identification.select import select

    structure = _structure(args)
    cv = args.cv or choice_cv(logs)
    # A reference ship's prior covers the terms it can: the grid goes down to where it leads.
    grid = REFERENCE_PRIOR_GAMMAS if physics is not None and physics.prior_source else None
    sel = select(logs, library=structure, search="none", names=names, cv=cv,
                 estimator=args.estimator, plausibility=False, physics=physics,
                 **({"gammas": grid} if grid else {}))  # fmt: skip
    table = sel.candidates[["gamma", "score", "score_se", "folds_diverged"]]
    print(f"γ chosen by free-run cross-validation ({cv}): {sel.gamma:g}")
    print(table.to_markdown(index=False, floatfmt=".4g"))
    print()
    return sel.gamma, {"gamma_by": "free-run CV", **sel.to_dict()}
