"""``identify``'s choices before its fit: the structure (``--model auto``, the paper's giving
way where its prefiltered fit fails the checks), the prefilter, γ (``--gamma auto``), select's
candidates the model averages and the structures that tied, refitted."""

from __future__ import annotations

import sys

from shipid.cli.physics_options import _parse_bounds, _physics, _structure, _structure_edit
from shipid.cli.printing import _warn
from shipid.cli.reading import _approach
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
