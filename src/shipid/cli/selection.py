"""``shipid select`` and ``shipid compare``: terms and γ chosen, and structures ranked, by their
free-run errors on logs left out."""

from __future__ import annotations

import functools
import sys
from pathlib import Path
from types import SimpleNamespace

from shipid.cli.as_written import (
    _as_written,
    _replicates_checked,
    _report_replicates,
    _written_text,
)
from shipid.cli.notes import _rudder_drag_note, _std_errors
from shipid.cli.physics_options import _parse_gammas, _physics, _structure_edit
from shipid.cli.printing import _json_text, _pd, _term_display, _warn
from shipid.cli.reading import (
    _ahead,
    _approach,
    _log_particulars,
    _log_record,
    _one_rps,
    _read_files,
    _training_logs,
    _warn_approach,
)
from shipid.errors import ShipidError


def _check_replicates(ensemble, report: dict, model, one_rps, ahead, logs, args, ident
                      ) -> None:  # fmt: skip
    """``_report_replicates`` of select's ensemble, each replicate checked from the approach
    its model was (``report``), as the model file will have it."""
    from shipid.identification.plausibility import sharpest_curvature

    speed = _approach(logs[0], "u")
    rps = one_rps or _approach(logs[0], "n")
    if speed is None or not speed > 0:
        return
    curvature = sharpest_curvature(logs, speed)
    _report_replicates(ensemble, _replicates_checked(
        ensemble, report, model, lambda member: _as_written(member, one_rps, ahead), speed, rps,
        curvature, (args.speed, args.rps)), ident)  # fmt: skip


def cmd_select(args) -> int:
    """``shipid select``: structure and γ by cross-validated free-run error. The steps: the
    search (widened as ``identify``'s default is where its best is ruled out or nothing similar
    is plausible), the choice printed, the model as its file will have it checked, the
    bootstrap of the choice, the file."""
    from shipid.identification.select import RESAMPLES
    from shipid.outputs import OutputSet, check_outputs
    from shipid.reporting.modelfile import model_text

    check_outputs({"-o": (args.output, "json"), "--table": (args.table, "log")},
                  [*args.logs, *_read_files(args)])  # fmt: skip
    search = _searched(args)
    sel, logs, names = search.selection, search.logs, search.names
    ident = sel.identification
    _print_selection(sel, search.options.cv, args.show)
    _warn_approach(logs, names)
    checked = _checked_as_written(args, search)
    others = len(sel.shares) - (sel.chosen_share > 0)
    print(f"\nThe choice on {RESAMPLES} resamples of the held-out logs: this candidate "
          f"{100 * sel.chosen_share:.0f} %, {others} other(s) the rest (column share)")
    ensemble = None
    if args.bootstrap is not None:
        ensemble = _selection_bootstrap(args, search, checked)
    text = model_text(ident, args.logs, preprocessing=_log_record(args, logs),
                      plausibility=checked.plausibility, model=sel.model,
                      selection=sel.to_dict(), particulars=_log_particulars(logs),
                      uncertainty=ensemble.to_dict() if ensemble else None)  # fmt: skip
    text = _written_text(text, checked.one_rps, checked.ahead, args.output)[0]
    with OutputSet() as out:
        out.write(args.output, lambda p: p.write_text(text, encoding="utf-8"))
        if args.table:
            from shipid.data.io import write_table

            write_table(sel.candidates, args.table, out)
    # And those added here (the model as the file has it, the replicates, the speeds given):
    # sel.warnings is the list select made.
    for w in [*sel.warnings, *(w for w in ident.warnings if w not in sel.warnings)]:
        _warn(w)
    print(f"model written to {args.output}")
    return 0


def _searched(args) -> SimpleNamespace:
    """The options checked (before the logs are read), the logs read and the search: the
    library (given, or the default trimmed to the logs, with the hull's cross-flow drag or the
    rudder's normal force), then as ``identify``'s default, where the best is ruled out by the
    checks the library widened by the rudder's lift at the hull's drift, and where nothing
    similar is plausible the constant, or the thrust held to its fall with the advance.
    Returns ``selection``, ``logs``, ``names``, ``options`` and ``physics``."""
    from shipid.dynamics.model import get_structure
    from shipid.identification.auto_structure import unusable, widened_selection
    from shipid.identification.cross_validation import parse_cv
    from shipid.identification.select import SelectOptions, default_library, select

    parse_cv(args.cv)
    gammas = _parse_gammas(args.gammas)
    try:
        given = get_structure(args.library) if args.library is not None else None
        if args.keep is not None:
            get_structure(args.keep)
    except ValueError as exc:
        raise ShipidError(str(exc)) from None
    logs = _training_logs(args)
    names = [str(p) for p in args.logs]
    library = given if given is not None else default_library(logs)[0]
    edit = _structure_edit(args, logs)
    if edit.crossflow_length is not None or edit.rudder is not None:
        # The default library passed as given: the trimmed one, with the hull's cross-flow drag
        # or the rudder's normal force.
        given = library = edit.apply(library)
    # The default library is passed as None: select trims it to the logs and says so.
    physics = _physics(args, logs, library, searched=True)
    options = SelectOptions(library=library if given is not None else None,
                            search=args.search, cv=args.cv,
                            estimator=args.estimator, method=args.method,
                            max_evaluations=args.max_evaluations,
                            plausibility=not args.no_plausibility, speed=args.speed,
                            rps=args.rps, one_standard_error=not args.best,
                            progress=not args.quiet, physics=physics,
                            average=args.average, keep=args.keep,
                            **({"gammas": gammas} if gammas else {}))
    sel = select(logs, options, names=names)
    say = functools.partial(print, file=sys.stderr)
    if args.library is None and sel.best_ruled_out:
        # As identify's default: where the logs' best fit from the default library is ruled out
        # by the checks, the search again with the rudder's lift at the hull's drift.
        wider, said, apart = widened_selection(sel, logs, names, options, edit, announce=say)
        if wider is not None:
            sel = wider[0]
        if apart:
            sel.identification.warnings.append(f"library: {apart}")
        for note in said:  # the model file's selection record names the library searched
            print(f"library: {note}")
    why = unusable(sel) if args.library is None and "1" not in library.all_terms else None
    if why:  # as identify's default: the library with its constant where nothing similar is
        from shipid.identification.auto_structure import searched_with_the_constant

        constant = searched_with_the_constant(logs, names, options, edit, say, why,
                                              crossflow=False)  # fmt: skip
        if constant is None:
            # As identify's default: every form once more with the thrust held to its fall
            # with the advance, the selection's own fits holding it.
            from shipid.identification.auto_structure import searched_with_the_advance_held

            constant = searched_with_the_advance_held(logs, names, options, edit, say, why,
                                                      crossflow=False)  # fmt: skip
        if constant is not None:
            sel = constant.selection
            for note in constant.widening:
                print(f"library: {note}")
    return SimpleNamespace(selection=sel, logs=logs, names=names, options=options,
                           physics=physics)


def _print_selection(sel, cv: str, show: int) -> None:
    """The model (and the chosen candidate where it is an average), γ and the score, the best
    ``show`` candidates (and the chosen one), the held-out logs and the error band."""
    if sel.model is not sel.chosen_model:
        print(f"The chosen candidate:\n{sel.chosen_model.equations()}\n\nThe model written, "
              f"the average of {len(sel.shares)} candidates weighted by how often the choice "
              "rule picks them on resampled held-out logs (--average):")  # fmt: skip
    print(sel.model.equations())
    whose = " of the chosen candidate" if sel.model is not sel.chosen_model else ""
    print(f"\nγ = {sel.gamma:g}; free-run CV score{whose} {sel.score:.4f} ({cv}; 1 ≈ "
          f"predicting the mean); {len(sel.candidates)} candidates")
    cols = ["chosen", "score", "score_se", "score_u", "score_v", "score_r", "gamma", "n_terms",
            "folds_diverged", "plausible", "share", "stage", "note"]
    shown = sel.candidates.head(show)
    if not shown["chosen"].any():
        shown = _pd().concat([shown, sel.candidates[sel.candidates["chosen"]]])
    print(shown[cols].to_markdown(index=False, floatfmt=".4g"))
    fitted = "the average" if sel.model is not sel.chosen_model else "the chosen structure"
    print(f"\nHeld-out logs ({fitted} fitted without each):")
    print(_fold_table(sel.folds))
    if sel.error_band is not None:
        print(f"Their {sel.error_band.describe()}; stored in the model file, validate reports "
              "each log's share of samples inside it.")  # fmt: skip


def _checked_as_written(args, search) -> SimpleNamespace:
    """The model as its file will have it (carried to every rps, in its ahead forms), checked
    from the approach select's own check of the fit took (the logs' first, or --speed and
    --rps): the checks' notes, the rudder reversed, turns far from the default's, a given
    steady speed missed and the rudder's drag, into the selection's warnings. Returns
    ``plausibility``, ``one_rps`` and ``ahead``."""
    from shipid.identification.auto_structure import turns_apart_from_the_default
    from shipid.identification.beyond_the_logs import (
        given_steady_speeds,
        missed_steady_speed,
        rudder_reversed_warning,
    )
    sel, logs, names = search.selection, search.logs, search.names
    ident = sel.identification
    plausibility, notes = sel.plausibility, sel.plausibility_notes
    one_rps = _one_rps(logs, args)
    ahead = _ahead(logs, args)
    written = _as_written(sel.model, one_rps, ahead)
    speed = args.speed if args.speed is not None else _approach(logs[0], "u")
    rps = args.rps if args.rps is not None else (one_rps or _approach(logs[0], "n"))
    if written is not sel.model:
        # Checked as the file will have it, with the crash stop select's check had.
        from shipid.identification.plausibility import (
            plausibility_at_approach,
            sharpest_curvature,
        )

        plausibility, notes = plausibility_at_approach(
            written, speed, rps, args.speed, args.rps,
            curvature=sharpest_curvature(logs, speed), astern=True)  # fmt: skip
    ident.warnings.extend(f"plausibility: {n}" for n in notes)
    reversed_rudder = rudder_reversed_warning(written, speed, rps)
    if reversed_rudder:
        ident.warnings.append(f"plausibility: {reversed_rudder}")
    apart = turns_apart_from_the_default(plausibility, logs, names, speed, rps, selection=sel)
    if apart:
        ident.warnings.append(f"library: {apart}")
    for u, n in given_steady_speeds(search.physics):
        missed = missed_steady_speed(written, u, n)
        if missed:
            ident.warnings.append(missed)
    drag = _rudder_drag_note(sel.model, logs,
                             args.speed if args.speed is not None else _approach(logs[0], "u"),
                             args.rps if args.rps is not None else _approach(logs[0], "n"),
                             _std_errors(ident).get("u") if sel.model is sel.chosen_model else None)
    if drag:
        ident.warnings.append(drag)
    return SimpleNamespace(plausibility=plausibility, one_rps=one_rps, ahead=ahead)


def _selection_bootstrap(args, search, checked):
    """``--bootstrap N``: each replicate a candidate drawn by its share, refitted on a
    resample; the coefficients' intervals printed, the replicates checked as written."""
    from shipid.identification.selection_ensemble import selection_ensemble

    sel, logs = search.selection, search.logs
    ensemble = selection_ensemble(logs, sel, args.bootstrap, args.block, args.seed,
                                  names=search.names, progress=not args.quiet)  # fmt: skip
    table = ensemble.coefficient_table()
    table["term"] = [_term_display(t) for t in table["term"]]
    print(f"\n95 % intervals of the coefficients ({ensemble.replicates} replicates: "
          f"{ensemble.resampling}; a term outside the model "
          "has value 0, inclusion the share of replicates that hold it):")  # fmt: skip
    print(table.to_markdown(index=False, floatfmt=".4g"))
    _check_replicates(ensemble, checked.plausibility, sel.model, checked.one_rps, checked.ahead,
                      logs, args, sel.identification)  # fmt: skip
    return ensemble


def _fold_table(folds) -> str:
    from shipid.trials.trial import TURN_KINDS

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
        key = "tactical_diameter" if f.get("kind") in TURN_KINDS else "first_overshoot_deg"
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
    from shipid.identification.auto_structure import PAPER, beyond_the_paper
    from shipid.identification.estimators import BLACK_BOX_ESTIMATORS
    from shipid.outputs import OutputSet, check_outputs

    check_outputs({"--json": (args.json, "json")}, [*args.logs, *_read_files(args)])
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    logs = _training_logs(args)
    names = [Path(p).name for p in args.logs]
    structure = args.model or PAPER
    semiphysical = [m for m in methods if not m.startswith("select:")
                    and m not in BLACK_BOX_ESTIMATORS]  # fmt: skip
    if args.model is None and semiphysical:
        reasons = beyond_the_paper(logs)[0]
        if reasons:
            # Scored through a structure that cannot hold the logs, every method looks bad and
            # the table ranks them by luck (the Esso's zig-zags: scores 0.9–5.7, worse than
            # the logs' means).
            _warn(f"{'; '.join(reasons)}: the paper's blanke cannot hold that, so these scores "
                  "judge the structure, not the methods; give --model (e.g. blanke-rps+wind, "
                  "or the structure identify chooses) or a term search (--methods "
                  "select:low-speed+wind)")  # fmt: skip
    table = compare(logs, structure, methods, names, gamma=args.gamma, cv=args.cv,
                    method=args.method, progress=not args.quiet)  # fmt: skip
    print(f"Free-run score per held-out log ({args.cv}; error RMS over the log's spread, mean of "
          "u, v, r; 1 ≈ predicting the mean), model structure " + structure + ":")
    print(summary(table).to_markdown(floatfmt=".3f"))
    with OutputSet() as out:
        if args.json:
            doc = {"structure": structure, "cv": args.cv, "gamma": args.gamma,
                   "rows": table.to_dict(orient="records")}  # fmt: skip
            out.write(args.json, lambda p: p.write_text(_json_text(doc), "utf-8"))
    return 0
