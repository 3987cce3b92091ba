"""``shipid validate`` and ``simulate``: a model run free against logs."""

from __future__ import annotations

import io
import math
import sys
from functools import partial
from pathlib import Path
from types import SimpleNamespace

from shipid.cli.notes import (
    _model_notes,
    _reference_speed_notes,
    _sampling_notes,
    _scale_notes,
    _ship_notes,
    _simulated_metadata,
    _warn_beyond_training,
    _yaw_rate_notes,
)
from shipid.cli.printing import _json_text, _markdown_dashed, _pd, _warn
from shipid.cli.reading import (
    _particulars,
    _print_yaw_rate_offsets,
    _read_files,
    _read_options,
    _warn_cut,
)
from shipid.cli.targets import (
    VESSEL_NAMES,
    _check_length,
    _check_scale,
    _reference_ship,
    _ship_or_model,
    _vessel_conditions,
)
from shipid.errors import ShipidError


def _unique_figure_names(names: list[str]) -> list[str]:
    """File stems for figures of logs that may share a file name: a, a-2, a-3, ..."""
    out, used = [], {}
    for n in names:
        stem = Path(n).stem or "log"
        used[stem] = used.get(stem, 0) + 1
        out.append(stem if used[stem] == 1 else f"{stem}-{used[stem]}")
    return out


def cmd_validate(args) -> int:
    """``shipid validate``: free runs on logs, metrics, indices, figures, report. The steps: the
    model (or reference ship) and what its file keeps, the logs read as its training logs were,
    each log validated, the tables printed, the residual analysis and IMO criteria, then the
    outputs (written only where some log validated)."""
    from shipid.evaluation.envelope import outside_envelope, unseen_kind_note
    from shipid.evaluation.validate import validate
    from shipid.outputs import check_outputs
    from shipid.progress import progress

    check_outputs({"--json": (args.json, "json"), "--plots": (args.plots, "dir"),
                   "--report": (args.report, "dir")},
                  [*([] if args.model in VESSEL_NAMES else [args.model]), *args.logs,
                   *_read_files(args)])  # fmt: skip
    subject = _validated_model(args)
    model, cond, band = subject.model, subject.cond, subject.band
    given = _particulars(args)  # checked before the runs: the criteria of the logs need it
    if given is not None:
        _check_length(args.model, model, cond, given.length, f"--particulars {args.particulars}")
        _check_scale(args.model, cond, given.scale, f"--particulars {args.particulars}")
    # The model's own, whatever the logs (those that start from rest or slow down meet them, as
    # the Esso's random runs do): said now, and in --json beside each log's.
    model_notes = _model_notes(model, cond["speed"], cond["rps"])
    for note in model_notes:
        _warn(note)
    logs, names, failed = _logs_to_validate(args, subject)
    vals = [validate(model, log, [name], method=args.method, kind=args.kind,
                     smooth_s=args.smooth, ensemble=subject.ensemble, error_band=band)[0]
            for log, name in progress(zip(logs, names, strict=True), "logs", "log",
                                      shown=not (args.quiet or len(logs) < 3))]  # fmt: skip
    for v, log in zip(vals, logs, strict=True):
        if v.error is None:
            unseen = unseen_kind_note(cond.get("manoeuvres"), v.kind)
            v.warnings.extend(outside_envelope(cond["envelope"], log)
                              + _reversed_propeller_notes(model, cond, log)
                              + ([unseen] if unseen else []))  # fmt: skip
    if subject.doc is not None:
        _mark_training_logs(subject.doc, vals)
    good = [v for v in vals if v.error is None]
    if good:
        _print_validations(good, band)
    if args.horizon and good:
        _print_horizons(model, vals, logs, args, cond["envelope"])
    tied, tied_table, tied_runs = ({}, None, {}) if args.lssvm or not good or subject.doc is None \
        else _tied_validations(subject.doc, args, vals, logs)  # fmt: skip
    residuals = _residual_analysis(args, vals, logs)
    particulars = given or cond["particulars"]
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
    _write_validation(args, subject, vals, logs, failed, model_notes,
                      SimpleNamespace(table=tied_table, runs=tied_runs, record=tied),
                      residuals, crit)  # fmt: skip
    return 1 if errors else 0


def _validated_model(args) -> SimpleNamespace:
    """What ``validate`` runs: a reference ship (the published KVLCC2 MMG model, ``shipid
    correct``'s corrected ship, a ship's own MMG model), or a model file's model (``--lssvm``:
    its LS-SVM fit) with its ensemble and error band (``--no-bands``: none), and the conditions
    it was fitted in. Returns ``model``, ``doc`` (None for a ship), ``ensemble``, ``band``,
    ``cond`` and ``reference``."""
    from shipid.identification.correction import ship_ensemble
    from shipid.reporting.modelfile import (
        ensemble_from_document,
        error_band_from_document,
        has_refinement,
        load_document,
        model_from_document,
        training_conditions,
    )

    ship = _reference_ship(args.model)
    if ship is not None:
        # A reference ship against the logs (the published KVLCC2 MMG model against MARIN's
        # runs): no fit of its own, so no training logs, error band or tied structures; a
        # corrected one's bootstrap replicates give bands and intervals.
        if args.lssvm:
            raise ShipidError(f"--lssvm: {args.model} is a reference ship, not an identified "
                              "model with an LS-SVM fit of its own")  # fmt: skip
        # The logs are turned to the ship's own rudder convention.
        return SimpleNamespace(
            model=ship, doc=None, band=None, reference=True,
            ensemble=None if args.no_bands else ship_ensemble(ship),
            cond={**_vessel_conditions(), "rudder_positive": ship.rudder_positive})
    doc = load_document(args.model)
    if args.lssvm and not has_refinement(doc):
        _warn(f"{args.model} has no refinement: its model is the LS-SVM one, which --lssvm "
              "validates")  # fmt: skip
    model = model_from_document(doc, args.model, "lssvm" if args.lssvm else "model",
                                hybrid=True)  # fmt: skip
    return SimpleNamespace(
        model=model, doc=doc, reference=False,
        ensemble=None if args.no_bands else ensemble_from_document(doc, args.model, model),
        band=None if args.no_bands or args.lssvm else error_band_from_document(doc, args.model),
        cond=training_conditions(doc))


def _logs_to_validate(args, subject) -> tuple[list, list[str], list[str]]:
    """The logs as the logs a model is fitted to are read (a zig-zag or turn from rest cut to
    its manoeuvre, a run ended before a propulsion dropout, unless --start or --end is given),
    turned to the model's rudder convention, with the notes on what they share with its
    training logs (scale, ship, sampling, yaw rate). Returns (logs, names, the errors of those
    that could not be read)."""
    from shipid.data.log import common_rudder_convention
    from shipid.trials.reading import read_trial_log

    cond = subject.cond
    options = _read_options(args)
    logs, names, failed = [], [], []
    for p in args.logs:
        try:
            logs.append(read_trial_log(p, options))
            names.append(str(p))
        except ShipidError as exc:
            failed.append(str(exc))
    _warn_cut(names, logs, options.lead, judged=True)
    _print_yaw_rate_offsets(args, names, logs)
    if cond["rudder_positive"]:  # a file that does not say its convention: no guess
        logs, notes = common_rudder_convention(logs, cond["rudder_positive"])
        for note in notes:
            _warn(note)
    for note in (_scale_notes(cond, logs, names) + _ship_notes(cond, logs, names)
                 + _sampling_notes(cond, logs, names)
                 + _yaw_rate_notes(cond, logs, names)
                 + (_reference_speed_notes(subject.model, logs, names) if subject.reference
                    else [])):  # fmt: skip
        _warn(note)
    return logs, names, failed


def _print_validations(good, band) -> None:
    """The validated logs' error band shares, metrics and indices (measured, replayed, closed
    loop), with the notes on the switch headings and the closed loop's start."""
    from shipid.reporting.report import (
        indices_frame,
        metrics_frame,
        no_manoeuvre_note,
        start_spread_note,
        switch_heading_note,
    )

    if band is not None:
        runs = band.runs_summary()
        print(f"The model's {band.describe()}: a log like those is inside it for about "
              f"{100 * band.level:g} % of its samples (columns 'in CV band')"
              + (f"; {runs}." if runs else "."))  # fmt: skip
    print(metrics_frame(good).to_markdown(index=False, floatfmt=".4g"))
    table = indices_frame(good)
    if len(table):
        print()
        print(_markdown_dashed(table, ".4g"))
        note = switch_heading_note(good)
        if note:
            print(note)
        spread = start_spread_note(good)
        if spread:
            print(spread)
    unjudged = no_manoeuvre_note(good)
    if unjudged:
        print(unjudged)


def _residual_analysis(args, vals, logs) -> dict:
    """``--resid`` or ``--report``: each validated log's free-run error, its autocorrelation and
    its correlation with the rudder ({name: {state: ...}}); printed with ``--resid``."""
    residuals: dict = {}
    if not (args.resid or args.report):
        return residuals
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
    return residuals


def _write_validation(args, subject, vals, logs, failed, model_notes, tied, residuals,
                      crit) -> None:  # fmt: skip
    """``--json``, ``--plots`` and ``--report``, written together (``OutputSet``): every log,
    failed ones with their error; the figures drawn once where the report shows them too."""
    from shipid.outputs import OutputSet

    good = [v for v in vals if v.error is None]
    with OutputSet() as out:
        if args.json:
            records = [v.to_dict() for v in vals] + [{"name": None, "error": e} for e in failed]
            body = {"logs": records, **({"tied_structures": tied.record} if tied.record else {}),
                    **({"model_warnings": model_notes} if model_notes else {})}
            out.write(args.json, lambda p: p.write_text(_json_text(body), "utf-8"))
        figures: dict[str, dict[str, bytes]] = {}
        if args.plots:
            figures = _write_figures(args, vals, logs, tied.runs, residuals, out)
        if args.report:
            from shipid.reporting.html import validation_report

            se, se_label = (None, "") if subject.doc is None else \
                _coefficient_errors(subject.doc, subject.model, args.lssvm)  # fmt: skip
            text = validation_report(subject.model, vals, logs,
                                     f"Validation of {Path(args.model).name}", std_errors=se,
                                     std_errors_label=se_label, criteria=crit,
                                     warnings=[w for v in good for w in v.warnings],
                                     residuals=residuals, figures=figures,
                                     tied=tied.table, tied_runs=tied.runs)  # fmt: skip
            out.write(Path(args.report) / "report.html",
                      lambda p: p.write_text(text, encoding="utf-8"))


def _write_figures(args, vals, logs, tied_runs, residuals, out) -> dict[str, dict[str, bytes]]:
    """Each validated log's figure (and ``--resid``'s) into ``--plots``, staged in ``out``;
    the PNGs drawn, by log, where the report shows them too ({} otherwise)."""
    from shipid.reporting import plots

    good = [v for v in vals if v.error is None]
    stems = _unique_figure_names([v.name for v in good])
    pairs = [(v, log) for v, log in zip(vals, logs, strict=True) if v.error is None]
    ext = "." + args.plot_format
    # PNGs drawn once serve the folder and the report alike.
    share = args.report is not None and args.plot_format == "png"
    figures: dict[str, dict[str, bytes]] = {}
    for (v, log), stem in zip(pairs, stems, strict=True):
        title = Path(v.name).name
        jobs = [("fit", stem + ext, partial(plots.measured_vs_simulated, log, v.simulation.log,
                                            title=title, bands=v.bands,
                                            error_band=v.error_band,
                                            tied=tied_runs.get(v.name)))]  # fmt: skip
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
    return figures


def _mark_training_logs(doc, vals) -> None:
    """Name the logs that are files the model was fitted to (by content: a copy or a renamed
    file is one too): their errors measure the fit, not a prediction."""
    from shipid.reporting.modelfile import sha256, training_files

    fitted = training_files(doc)
    if not fitted:
        return
    for v in vals:
        if v.error is not None or not Path(v.name).is_file():
            continue
        was = fitted.get(sha256(v.name))
        if was is not None:
            v.fitted_to = True
            v.warnings.append(f"the model was fitted to this log (the same file as its "
                              f"training log {was}): its errors measure the fit, not a "
                              "prediction; judge the model on logs it was not fitted to")  # fmt: skip


# Indices of the tied structures' closed loops shown beside their free-run errors.
TIED_INDICES = ("first_overshoot_deg", "second_overshoot_deg", "tactical_diameter",
                "steady_yaw_rate")  # fmt: skip


def _tied_validations(doc, args, vals, logs) -> tuple[dict, object, dict]:
    """``validate`` of a model whose structure tied with others in ``identify``'s inflow
    comparison: the same logs run on each tied fit (``structure_choice.alternatives``), their
    free-run error std and closed-loop indices in one table, so that logs none of them was
    fitted to can tell them apart. ({}, None, {}) where the file keeps none; else the record for
    ``--json``, the table and each log's tied free runs {log: {structure: simulated log}} for
    its figure."""
    from shipid.evaluation.validate import validate
    from shipid.reporting.modelfile import alternatives_fit, alternatives_from_document

    alternatives = alternatives_from_document(doc, args.model)
    if not alternatives:
        return {}, None, {}
    rows, out, runs = [], {}, {}
    pairs = [(v, log) for v, log in zip(vals, logs, strict=True) if v.error is None]
    for structure, alt in {"(the model)": None, **alternatives}.items():
        for v, log in pairs:
            # The tied fits' spread with the start is not shown: not drawn.
            w = v if alt is None else validate(alt, log, [v.name], method=args.method,
                                               kind=args.kind, smooth_s=args.smooth,
                                               start_draws=False)[0]  # fmt: skip
            closed = (w.indices or {}).get("closed_loop") or {}
            row = {"structure": structure, "log": Path(v.name).name,
                   **{f"std {s}": w.metrics[s]["std"] for s in ("u", "v", "r")},
                   **{f"{k} (closed loop)": closed.get(k) for k in TIED_INDICES
                      if k in ((v.indices or {}).get("measured") or {})}}  # fmt: skip
            rows.append(row)
            if alt is not None:
                runs.setdefault(v.name, {})[structure] = w.simulation.log
                out.setdefault(structure, []).append(
                    {"log": v.name, "metrics": w.metrics, "closed_loop": closed,
                     "diverged": w.simulation.diverged})  # fmt: skip
    table = _pd().DataFrame(rows)
    table = table.astype(object).where(table.notna(), "–")
    print("\nThe structures identify's comparison could not tell apart from this one, on the same "
          f"logs ({alternatives_fit(doc)}; judge them on logs none was fitted to):")
    print(table.to_markdown(index=False, floatfmt=".4g"))
    return out, table, runs


def _reversed_propeller_notes(model, cond: dict, log) -> list[str]:
    """A note where ``log`` reverses the propeller and the model's astern thrust is not what
    logs showed (``shipid.trials.manoeuvres.astern_thrust_note``, at the training approach):
    what the log's spans astern are predicted with."""
    from shipid.trials.manoeuvres import astern_thrust_note

    if "n" not in log.columns or not cond.get("speed") or not cond.get("rps"):
        return []
    share = float((log["n"].to_numpy() < 0).mean())
    astern = astern_thrust_note(model, cond["speed"], cond["rps"]) if share > 0 else None
    return [f"the log reverses the propeller for {100 * share:.0f} % of its samples and "
            f"{astern.note}"] if astern else []  # fmt: skip


def _print_horizons(model, vals, logs, args, envelope) -> None:
    """``validate --horizon``: each log's free runs restarted every H seconds (kept with its
    validation: ``--json``, the report), and a table of their errors over the log's spread,
    also within the model's training ``envelope`` and beyond it."""
    from shipid.evaluation.horizon import ENVELOPE_COLUMNS_NOTE, horizon_errors
    from shipid.reporting.report import horizons_frame

    for v, log in zip(vals, logs, strict=True):
        if v.error is not None:
            continue
        for h in args.horizon:
            try:
                v.horizons.append(horizon_errors(model, log, h, args.method, v.name,
                                                 envelope).to_dict())
            except ShipidError as exc:  # printed after the log's name, which it starts with
                v.warnings.append(str(exc).removeprefix(f"{v.name}: "))
    table = horizons_frame(vals)
    if len(table):
        print("\nPredictions over a horizon: free runs restarted from the measured state every "
              "H s, their rms error over the log's spread (1 ≈ predicting its mean)"
              + (f"; {ENVELOPE_COLUMNS_NOTE}" if "in envelope" in table.columns else "") + ":")
        print(_markdown_dashed(table, ".3g"))


def _coefficient_errors(doc, model, lssvm: bool) -> tuple[dict | None, str]:
    """The standard errors of the model validated, and whose: the LS-SVM fit's (its
    diagnostics) where the model is the LS-SVM one, output error's where the file's model is
    the output-error fit. Bug: a report of an output-error model printed its coefficients with
    the LS-SVM fit's standard errors, labelled as such (5.6 times too small for ṙ u·r)."""
    ident = doc.get("identification") or {}
    ref = ident.get("refinement") or {}
    dofs = getattr(model, "physical", model).structure.dofs
    refined = bool(ref) and doc.get("model") == ref.get("refined_model")
    if refined and not lssvm:
        se = (ref.get("statistics") or {}).get("standard_errors")
        return (se, "maximum-likelihood output error, Gauss–Newton") if se else (None, "")
    se = {d: ((ident.get("diagnostics") or {}).get(d) or {}).get("std_errors") for d in dofs}
    # A model file without the fit's diagnostics (written by hand, say) has none to show.
    return (se, "LS-SVM linear fit") if any(se.values()) else (None, "")


def _criteria_of_logs(good, logs, vals, particulars):
    """Measured and predicted criteria rows of 35° turns and 10/10, 20/20 zig-zags."""
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
        pred = v.indices.get("closed_loop") or v.indices.get("simulated")
        # The log's own scale where the particulars give none (a 7 m model judged at λ = 1 meets
        # the 10/10 limits of a ship with a √λ times shorter L/V).
        lam = particulars.scale or log.attrs.get("scale") or 1.0
        args = (rudder, meas.get("switch_heading_deg"), particulars.length, speed, lam)
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


def cmd_simulate(args) -> int:
    """``shipid simulate``: drive a model or vessel with a log's inputs."""
    from shipid.data.io import read_log, write_log
    from shipid.dynamics.simulate import simulate_log
    from shipid.outputs import check_outputs

    log_path = args.log
    check_outputs({"-o": (args.output, "log")}, [args.model, log_path, *_read_files(args)])
    from shipid.data.log import in_rudder_convention

    target, cond = _ship_or_model(args.model, hybrid=True)
    dynamics = getattr(target, "dynamics", target)
    log, note = in_rudder_convention(read_log(log_path, _read_options(args)),
                                     getattr(target, "rudder_positive", None)
                                     or cond.get("rudder_positive"))  # fmt: skip
    if note:
        _warn(note)
    for note in (_scale_notes(cond, [log], [str(log_path)])
                 + _ship_notes(cond, [log], [str(log_path)])
                 + _sampling_notes(cond, [log], [str(log_path)])):
        _warn(note)
    res = simulate_log(dynamics, log, method=args.method)
    # The driving log's times and rudder convention; the rest is the simulated ship's.
    kept = {k: log.attrs[k] for k in ("rudder_positive", "time_origin") if k in log.attrs}
    res.log.attrs = {**_simulated_metadata(args.model, target, cond), **kept,
                     "source": f"simulated: {args.model}, driven by the inputs of {log_path}"}
    write_log(res.log, args.output)
    if res.diverged:
        print(res.reason, file=sys.stderr)
    _warn_beyond_training(cond, str(log_path), res.log)  # the log's inputs and the run alike
    print(f"{len(res.log)} samples written to {args.output}")
    return 0
