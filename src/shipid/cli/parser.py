"""The ``shipid`` argument parser: every command's options, and the checks argparse runs on them."""

from __future__ import annotations

import argparse
import functools
import math

from shipid import __version__
from shipid.cli.control import cmd_autopilot, cmd_export, cmd_follow, cmd_linearise
from shipid.cli.correction import cmd_correct
from shipid.cli.data import cmd_import, cmd_indices, cmd_plot
from shipid.cli.evaluation import cmd_simulate, cmd_validate
from shipid.cli.experiments import cmd_demo, cmd_study
from shipid.cli.identify import cmd_identify
from shipid.cli.mmg import cmd_mmg
from shipid.cli.rescale import cmd_rescale
from shipid.cli.selection import cmd_compare, cmd_select
from shipid.cli.targets import CONTROL_STEP, CRITERIA_STEP, MANOEUVRE_STEP, VESSEL_NAMES
from shipid.cli.trials import cmd_criteria, cmd_manoeuvre

# The choices of --format, --estimator and --kind, kept here so that --help and --version import
# no pandas (tests check each against the module it names).
FORMATS = ("canonical", "simman-marin", "simman-hsva", "osaka-frt")  # shipid.data.formats'
LINEAR_ESTIMATORS = ("lssvm", "ols", "ridge", "lasso", "svr")  # identification.estimators'
KINDS = ("zigzag", "turning", "pull-out", "other")  # shipid.trials.trial's


def _pair(text: str) -> tuple[float, float]:
    parts = text.split(",")
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 2:
        raise argparse.ArgumentTypeError(f"expected two numbers FORWARD,STARBOARD [m], got {text!r}")
    return values


def _add_log_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("log files")
    g.add_argument("--format", default="canonical", choices=FORMATS,
                   help="file format (default: %(default)s CSV/Parquet)")
    g.add_argument("--scale", type=float, metavar="LAMBDA",
                   help="simman-marin: Froude-scale the full-scale data to model scale 1/λ")
    g.add_argument("--columns", metavar="MAP", help="map file columns to canonical names, "
                   "e.g. t=time,delta=rudder_angle (lat=,lon= for a GNSS's degrees)")
    g.add_argument("--degrees", metavar="COLS", default="",
                   help="angle columns given in degrees, e.g. delta,psi,r")
    g.add_argument("--dt", type=float, help="resample to this uniform sampling time [s]")
    g.add_argument("--start", type=_time_or_auto, metavar="S|auto",
                   help="trim: first time [s], or 'auto': --lead s before the detected rudder "
                   "execute (default: the whole log; logs a model is fitted to that are zig-zags "
                   "or turns from rest are cut as --start auto --end auto, --start 0 keeps them "
                   "whole)")
    g.add_argument("--lead", type=float, default=5.0, metavar="S",
                   help="with --start auto: seconds kept before the execute (default %(default)s)")
    g.add_argument("--end", type=_end_time, metavar="S|auto|dropout",
                   help="trim: last time [s], or 'auto': the end of the manoeuvre (last large rudder, "
                   "propeller still running), or 'dropout': before the first span where the "
                   "ship gains headway with the propeller stopped (its logging dropped out)")
    g.add_argument("--fill-gaps", action="store_true",
                   help="interpolate missing values inside signals, and with --dt across gaps in "
                   "time (default: refuse the log)")
    g.add_argument("--yaw-rate-offset", type=_offset_or_auto, metavar="DEG_S|auto",
                   help="subtract a gyro's offset from r: in °/s, or 'auto': each log's own, "
                   "read off the drift of psi − ∫r dt (default: r as measured, and a warning "
                   "where that drift moves the heading)")
    g.add_argument("--rudder-positive", choices=("port", "starboard"),
                   help="where a positive rudder angle turns the ship (default: the file's "
                   "metadata, else port as in the paper)")
    g.add_argument("--velocities-from-track", action="store_true",
                   help="read u, v off the track (x, y) and psi even where the log has them "
                   "(a log with neither has them read off its track anyway; r too where absent)")
    g.add_argument("--track-window", type=float, metavar="S",
                   help="u, v off the track: the local fit's window [s] (default: chosen from the "
                   "log's noise and the track's curvature, at least 7 samples)")
    g.add_argument("--antenna", type=_pair, metavar="FORWARD,STARBOARD",
                   help="u, v off the track: the position sensor's place [m] from the log's "
                   "reference point, in the body frame (default 0,0)")
    g.add_argument("--particulars", metavar="FILE",
                   help="ship particulars (YAML or JSON: length, beam, draught, ...; the MARIN "
                   "ship_data.yml reads as is; or a model file that keeps its logs'), kept with "
                   "the logs and the model")


def _add_crossflow_option(p) -> None:
    p.add_argument("--crossflow", action=argparse.BooleanOptionalAction, default=None,
                   help="the hull's nonlinear sway and yaw damping (|v|v, |v|r, |r|r, v|r|) as "
                   "the cross-flow drag over its length, one term per equation, in whichever "
                   "structure is fitted or searched; needs the length (--particulars). Default: "
                   "where the logs' particulars give the length, identify's structure comparison "
                   "offers it beside the terms and takes it where they tie, and on one or two "
                   "logs its select searches with it too; --no-crossflow never")


def _add_rudder_normal_option(p) -> None:
    p.add_argument("--rudder-normal", action="store_true",
                   help="the rudder's force terms (δ, u²δ, uδ, δ², ...) as the normal force of one "
                   "inflow in the propeller's race and the hull's straightened flow (MMG), one "
                   "term per equation: F_N sin δ in surge, F_N cos δ in sway and yaw; its inflow "
                   "from the particulars (--particulars: length, propeller_diameter, "
                   "block_coefficient, rudder_height) and needs the logs' n [rps]. What a "
                   "zig-zag's race terms cannot say: the rudder's force in a tight turn")


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


def _finite(text: str, expected: str, least: float = -math.inf) -> float:
    """``text`` as a finite number ≥ ``least``, or argparse's error naming what was
    ``expected``."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= least):
        raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}")
    return value


def _astern_ratio(text: str) -> float | None:
    """--astern-thrust: a ratio ≥ 0, or 'none'."""
    return None if text == "none" else _finite(text, "a ratio ≥ 0 or 'none'", least=0.0)


def _time_or_auto(text: str) -> float | str:
    if text == "auto":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds or 'auto', got {text!r}") from None


def _offset_or_auto(text: str) -> float | str:
    return text if text == "auto" else math.radians(_finite(text, "°/s or 'auto'"))


def _seconds_list(text: str) -> list[float]:
    try:
        values = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        values = []
    if not values or not all(math.isfinite(v) and v > 0 for v in values):
        raise argparse.ArgumentTypeError(f"expected seconds > 0, comma-separated, got {text!r}")
    return values


def _block(text: str) -> float | str:
    if text in ("auto", "log"):
        return text
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected seconds > 0, 'log' or 'auto', got {text!r}")
    return value


def _add_written_forms_options(p) -> None:
    """The forms a fit's model is written in: carried to every rps, and astern."""
    p.add_argument("--no-rps-similarity", dest="rps_similarity", action="store_false",
                   help="logs at one propeller speed: keep the fit's terms, which answer every "
                   "other rps as that one (default: each term that does not grow with the "
                   "speeds gains the power of n it needs to scale as advance-ratio similarity "
                   "has it; the model at the logs' rps is the fit)")
    p.add_argument("--no-ahead-forms", dest="ahead_forms", action="store_false",
                   help="logs that never go astern: keep the fit's u·v, u·r, u²δ, u²δ² (default: "
                   "written |u|·v in the sway, |u|·r in the yaw, |u|·u·δ, |u|·u·δ², the same fit "
                   "ahead, whose damping damps and whose rudder reverses astern)")
    from shipid.dynamics.propeller import ASTERN_THRUST_RATIO

    p.add_argument("--astern-thrust", type=_astern_ratio, default=ASTERN_THRUST_RATIO,
                   metavar="RATIO|none",
                   help="logs that never reverse the propeller: its thrust astern over its thrust "
                   f"ahead at the same |n| (default {ASTERN_THRUST_RATIO:g}: the surge's pos(n)² "
                   "or |n|·n written propeller(k), n² ahead and −k·n² astern, the same fit "
                   "ahead; 'none' keeps the fit's, which coasts (pos(n)²) or pushes astern as "
                   "ahead (|n|·n) when reversed)")


def _add_block_option(p: argparse.ArgumentParser) -> None:
    """``--block`` of identify's and select's bootstrap (the numbers are
    ``shipid.identification.uncertainty``'s MIN_WHOLE_LOGS and BLOCK_S, not imported: the parser
    is built before every command, and that module brings NumPy)."""
    p.add_argument("--block", type=_block, default="auto", metavar="S|log|auto",
                   help="with --bootstrap: resample blocks of S seconds, or whole logs ('log': "
                   "the intervals then hold how the logs differ from one another); 'auto' "
                   "(default): whole logs from 5 logs on, else 10 s blocks")


def _end_time(text: str) -> float | str:
    return text if text == "dropout" else _time_or_auto(text)


# ---------------------------------------------------------------------------- parser
def _add_physics_options(p) -> None:
    g = p.add_argument_group("physics (increment form; lssvm or ols)")
    g.add_argument("--prior", metavar="clarke|SHIP|SHIP.yml|MODEL.json",
                   help="draw the fit toward a prior instead of zero: 'clarke' (linear sway–yaw "
                   "and rudder terms from the particulars, Clarke et al. 1983), a reference "
                   "ship (kvlcc2, mariner, tanker, cybership2, scale-ship, or a file of one: "
                   "an MMG model, shipid mmg; its trials fitted in the structure and carried "
                   "to the particulars' length at equal Froude number) or a model file "
                   "(carried to the logs' length and rudder convention where the two differ)")
    g.add_argument("--constraints", metavar="LIST",
                   help="comma list: signs (damping, resistance, thrust, its fall with the "
                   "advance and rudder terms keep their physical sign), derivatives (the "
                   "linearised damping and rudder derivatives keep theirs, whatever terms carry "
                   "them), rudder-ahead (the rudder turns the ship its way at every speed ahead "
                   "from rest to the approach, the propeller at the logs' rate and stopped), "
                   "steady-speed (u̇ = 0 on the approach), stable (straight-line stability at "
                   "the approach: the yaw equation given the sway one)")
    g.add_argument("--bound", action="append", metavar="'DOF: TERM <= X'",
                   help="a bound on one coefficient, e.g. 'r: u*r <= 0' (repeatable); "
                   "both ways at one value holds it there (given, not fitted)")
    g.add_argument("--steady-speed", action="append", metavar="U@N",
                   help="the ship holds U m/s straight ahead at N rps (repeatable; a straight "
                   "run's or sea trials' speed): u̇ = 0 there with the rudder amidships, instead "
                   "of at the logs' starts; the speed the surge balances at is what the logs "
                   "determine least")


@functools.lru_cache(maxsize=1)
def shared_parser() -> argparse.ArgumentParser:
    """``build_parser``'s parser, built once per process for ``shipid.cli.main``: parsing reads
    a parser and changes nothing in it, and building one (its 332 options, each formatted
    once by argparse to check it) took 5 ms of every call: 2 % of the test suite's CPU, which
    calls ``main`` hundreds of times, as a batch's or a study's jobs do."""
    return build_parser()


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command."""
    ap = argparse.ArgumentParser(prog="shipid", description="Semiphysical identification of ship "
                                 "manoeuvring models with LS-SVM (Moreno-Salinas et al. 2013).")
    ap.add_argument("--version", action="version", version=f"shipid {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    # Each command's arguments, in the order --help lists them.
    for add in (
            _add_demo, _add_identify, _add_select, _add_compare, _add_validate, _add_plot,
            _add_simulate, _add_manoeuvre, _add_criteria, _add_linearise, _add_export,
            _add_controllers, _add_correct, _add_mmg, _add_rescale, _add_study, _add_import,
            _add_indices):
        add(sub)
    return ap



def _add_demo(sub) -> None:
    """``shipid demo``'s arguments."""
    p = sub.add_parser("demo", help="the paper's experiment on the embedded scale ship")
    p.add_argument("--out", default="shipid-demo", help="output folder (default ./%(default)s)")
    p.add_argument("--seed", type=int, default=0, help="noise seed (default %(default)s)")
    p.set_defaults(func=cmd_demo)


def _add_identify(sub) -> None:
    """``shipid identify``'s arguments."""
    p = sub.add_parser("identify", help="identify a model from trial logs")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--model", default="auto",
                   help="structure: auto (default: the paper's blanke, unless the logs hold a "
                   "varying propeller speed or thrust or a material wind, which it cannot: then "
                   "blanke-thrust(+wind) for a thrust, else the terms select chooses from its "
                   "default library, the candidates its choice picks on resampled held-out logs "
                   "averaged; a speed that varies at constant rps: blanke, blanke-speed "
                   "and blanke-race+race-damping compared by free-run CV), blanke, blanke-thrust, "
                   "blanke-speed, blanke-race, "
                   "blanke-rps, abkowitz3, low-speed, wind, race-damping, propeller-asymmetry, "
                   "astern, rudder-drift, linear-sway-yaw, nomoto1; combine "
                   "with + (blanke-rps+wind, blanke-race+race-damping) or write terms: "
                   "'u: |u|u, v*r, 1; v: ...; r: ...'")
    p.add_argument("--form", default="increment", choices=("increment", "paper"),
                   help="regression form (default %(default)s)")
    p.add_argument("--gamma", type=_number_or_auto, default=None, metavar="G|auto",
                   help="LS-SVM regularisation γ, or 'auto': chosen by free-run cross-validation "
                   "over the logs (default 1e4, or the γ select chose with --model auto)")
    p.add_argument("--estimator", default="lssvm", choices=LINEAR_ESTIMATORS,
                   help="equation-error estimator (default %(default)s, the paper's)")
    p.add_argument("--cv", help="the free-run cross-validation of the structure's choice, "
                   "--gamma auto and --residual: logo, kfold:K (--gamma) or blocks:K (default: "
                   "logo from three logs, blocks:4 of one or two; --residual: logo from two)")
    p.add_argument("--drop", help="terms to drop, e.g. u:r^2 (the paper drops r²)")
    _add_crossflow_option(p)
    _add_rudder_normal_option(p)
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
    p.add_argument("--output-error", dest="output_error", action="store_const", const="always",
                   default="auto",
                   help="fit the coefficients by maximum-likelihood output error (free runs from "
                   "estimated initial states against the unfiltered logs; consistent under "
                   "measurement noise, unlike any equation-error fit), with standard errors, "
                   "95 %% intervals and 200 covariance draws stored for prediction bands and "
                   "index intervals; the LS-SVM model is its start and stays in the file. "
                   "Holds --constraints signs and --bound (not a prior, stable, derivatives, "
                   "rudder-ahead or "
                   "steady speed). Default: where the LS-SVM's free runs miss the logs by no "
                   "more than twice their sensor noise, and the output-error residuals come out "
                   "white (noise, not model error), without --refine, --bootstrap, --error-band "
                   "or --residual")
    p.add_argument("--no-output-error", dest="output_error", action="store_const",
                   const="never", help="keep the LS-SVM fit even where noise is all it leaves")
    p.add_argument("--segment", type=float, metavar="S",
                   help="with --refine: simulate segments of S seconds (default: whole logs)")
    p.add_argument("--refine-evals", type=int, default=200, metavar="N",
                   help="with --refine or --output-error: cap on cost evaluations (default "
                   "%(default)s)")
    p.add_argument("--bootstrap", type=int, metavar="N",
                   help="uncertainty: N bootstrap refits (≥ 10; e.g. 200; --block), stored in "
                   "the model file: coefficient intervals here, prediction bands and index "
                   "intervals in validate, manoeuvre and criteria; the first 40 replicates "
                   "run through the plausibility checks, and how many fail is said")
    _add_block_option(p)
    p.add_argument("--seed", type=int, default=0, help="with --bootstrap or --output-error: "
                   "random seed "
                   "(default %(default)s)")
    p.add_argument("--error-band", nargs="?", const="auto", metavar="CV",
                   help="the cross-validated 95 %% error band of the free runs, stored for "
                   "validate: the same fit without each log (logo) or block (blocks:K), run free "
                   "over it ('auto': logo from two logs, blocks:4 of one). Default: logo where "
                   "two or more logs are given and the file's model is the LS-SVM fit; 'none' "
                   "skips it")
    p.add_argument("--residual", choices=("rbf",),
                   help="add a kernel residual to the physical model: an RBF LS-SVM on its "
                   "one-step acceleration residual, γ and σ (or none) chosen by the free-run "
                   "error of the hybrid on each log left out (--cv); it fades out beyond the "
                   "training logs' envelope. Validate, simulate, manoeuvre and criteria run it")
    _add_written_forms_options(p)
    # --out spelled out: since --output-error, argparse no longer takes it for --output.
    p.add_argument("-o", "--output", "--out", required=True, metavar="MODEL.json")
    _add_physics_options(p)
    _add_log_options(p)
    p.set_defaults(func=cmd_identify)


def _add_select(sub) -> None:
    """``shipid select``'s arguments."""
    p = sub.add_parser("select", help="choose the structure and γ by cross-validated free-run "
                       "error over several logs")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--library",
                   help="candidate terms: a structure name, a sum (abkowitz3+blanke) or written "
                   "terms 'u: ...; v: ...; r: ...' (default low-speed+wind+propeller-asymmetry+astern, "
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
    p.add_argument("--keep", metavar="TERMS",
                   help="terms every candidate holds, whatever the cross-validation says, e.g. "
                   "'v: u*v, u*r; r: u*v, u*r' (added to the library where it lacks them)")
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
                   "refitted on a resample (--block); stored in the model file for bands "
                   "and intervals; the first 40 run through the plausibility checks")
    _add_block_option(p)
    p.add_argument("--seed", type=int, default=0, help="with --bootstrap: random seed "
                   "(default %(default)s)")
    p.add_argument("--table", metavar="OUT.csv", help="write every candidate with its scores")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    _add_crossflow_option(p)
    _add_rudder_normal_option(p)
    _add_written_forms_options(p)
    p.add_argument("-o", "--output", required=True, metavar="MODEL.json")
    _add_physics_options(p)
    _add_log_options(p)
    p.set_defaults(func=cmd_select)


def _add_compare(sub) -> None:
    """``shipid compare``'s arguments."""
    p = sub.add_parser("compare", help="methods × held-out logs: free-run cross-validation")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--model", help="structure for the semiphysical methods (default blanke, "
                   "the paper's, with a warning where the logs hold a varying propeller speed or "
                   "a wind it cannot)")
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


def _add_validate(sub) -> None:
    """``shipid validate``'s arguments."""
    p = sub.add_parser("validate", help="free-run a model (or a reference ship) against logs: "
                       "error table and indices")  # fmt: skip
    p.add_argument("model", metavar="MODEL.json|VESSEL",
                   help=f"a model file, or a reference ship ({', '.join(VESSEL_NAMES)})")
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
    p.add_argument("--horizon", type=_seconds_list, metavar="S[,S...]",
                   help="predictions over horizons: free runs restarted from the measured state "
                   "every S seconds, their error per state over the log's spread (e.g. 10,30,60: "
                   "what an autopilot or a predictive controller asks of the model)")
    p.add_argument("--resid", action="store_true",
                   help="residual analysis: autocorrelation of the errors and correlation with "
                   "the rudder (a table, and figures with --plots)")
    p.add_argument("--max-lag", type=int, default=50, metavar="N",
                   help="with --resid: largest lag [samples] (default %(default)s)")
    p.add_argument("--report", metavar="DIR", help="write a self-contained HTML report")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    _add_log_options(p)
    p.set_defaults(func=cmd_validate)


def _add_plot(sub) -> None:
    """``shipid plot``'s arguments."""
    p = sub.add_parser("plot", help="figure of any logs: u, v, r, rudder, heading, track")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("-o", "--output", required=True, metavar="FIG.png|.svg|.pdf")
    p.add_argument("--title", help="figure title (default: the file names)")
    _add_log_options(p)
    p.set_defaults(func=cmd_plot)


def _add_simulate(sub) -> None:
    """``shipid simulate``'s arguments."""
    p = sub.add_parser("simulate", help="drive a model or vessel with a logged rudder")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("log", metavar="LOG", help="log whose rudder and inputs drive it")
    p.add_argument("--method", default="rk4", choices=("euler", "rk4"),
                   help="integration scheme (default %(default)s)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.csv")
    _add_log_options(p)
    p.set_defaults(func=cmd_simulate)


def _add_manoeuvre(sub) -> None:
    """``shipid manoeuvre``'s arguments."""
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
    p.add_argument("--dt", "--step", dest="step", type=float, default=MANOEUVRE_STEP,
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


def _add_criteria(sub) -> None:
    """``shipid criteria``'s arguments."""
    p = sub.add_parser("criteria", help="IMO MSC.137(76) criteria: run the standard manoeuvres "
                       "on a model or vessel and judge them")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("--particulars", metavar="FILE", help="ship particulars (default: the model "
                   "file's)")
    p.add_argument("--length", type=float, help="Lpp [m] (default: the particulars')")
    p.add_argument("--speed", type=float, help="test speed [m/s] (default: the training approach)")
    p.add_argument("--scale", type=float, metavar="LAMBDA",
                   help="model scale λ, for the full-scale L/V and rudder rate (default: the "
                   "particulars', else the training logs', else 1)")
    p.add_argument("--rps", type=float, help="propeller speed for models with n terms (default: "
                   "the training approach)")
    p.add_argument("--astern-rps", type=float, help="stopping test order (default −rps)")
    p.add_argument("--rudder-rate", type=float, metavar="DEG/S",
                   help="steering machine rate (default: the training logs' rudder rate, else "
                   "SOLAS 2.32 °/s at full scale, × √λ)")
    p.add_argument("--dt", type=float, default=CRITERIA_STEP,
                   help="integration step [s] (default %(default)s)")
    p.add_argument("--json", metavar="OUT.json")
    p.add_argument("--no-bands", action="store_true",
                   help="skip the intervals from the model file's bootstrap ensemble")
    p.set_defaults(func=cmd_criteria)


def _add_linearise(sub) -> None:
    """``shipid linearise``'s arguments."""
    p = sub.add_parser("linearise", help="state-space A, B and Nomoto K, T of a model or vessel")
    p.add_argument("model", metavar="MODEL.json|VESSEL")
    p.add_argument("--speed", type=float, help="straight-running speed [m/s] (default: training)")
    p.add_argument("--rps", type=float, help="propeller speed for models with n terms")
    p.set_defaults(func=cmd_linearise)


def _add_export(sub) -> None:
    """``shipid export``'s arguments."""
    p = sub.add_parser("export", help="a model, or an MMG ship (kvlcc2, an MMG file, one "
                       "corrected), as a standalone NumPy module (no shipid needed)")  # fmt: skip
    p.add_argument("model", metavar="MODEL.json|SHIP")
    p.add_argument("-o", "--output", required=True, metavar="MODEL.py")
    p.set_defaults(func=cmd_export)


def _add_controllers(sub) -> None:
    """``shipid autopilot`` and ``shipid follow``: a controller tuned on a model."""
    for name, helptext in (("autopilot", "PID heading autopilot tuned on a model: a heading step "
                            "on the model and on a true ship"),
                           ("follow", "line-of-sight path following along waypoints with a PID "
                            "tuned on a model, on the model and on a true ship")):  # fmt: skip
        p = sub.add_parser(name, help=helptext)
        p.add_argument("model", metavar="MODEL.json|VESSEL")
        p.add_argument("--truth", metavar="VESSEL", help="reference ship to test the controller "
                       "on (scale-ship, mariner, kvlcc2, cybership2, tanker)")
        p.add_argument("--speed", type=float, help="approach speed [m/s] (default: training)")
        p.add_argument("--rps", type=float, help="propeller speed for models with n terms")
        p.add_argument("--rudder-rate", type=float, metavar="DEG/S",
                       help="the model's steering machine rate (default: its training logs' "
                       "rudder rate; a reference ship: its own gear)")
        p.add_argument("--omega", type=float, help="closed-loop natural frequency [rad/s] "
                       "(default max(1/|T|, √|K/T|): Kp at least 1)")
        p.add_argument("--dt", type=float, default=CONTROL_STEP,
                       help="step [s] (default %(default)s)")
        if name == "autopilot":
            p.add_argument("--heading", type=float, default=20.0, metavar="DEG",
                           dest="heading_step", help="heading step, within ±180° (default "
                           "%(default)s; positive to starboard, negative to port)")
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


def _add_correct(sub) -> None:
    """``shipid correct``'s arguments."""
    p = sub.add_parser("correct", help="a reference ship's model kept whole, an LS-SVM "
                       "correction fitted to logs of the same ship (the corrected ship a file "
                       "the commands run as a reference ship)")  # fmt: skip
    p.add_argument("reference", metavar="VESSEL|MMG.yml",
                   help=f"the reference ship ({', '.join(VESSEL_NAMES)}) or a ship's own MMG "
                   "model file (format: shipid-mmg; see shipid.vessels.mmg_file)")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--model", metavar="STRUCTURE",
                   help="the correction's terms, in u, v, r, δ and the relative wind (default "
                   "blanke-race, blanke-race+wind where the logs measure the relative wind)")
    p.add_argument("--gamma", type=_number_or_auto, default=1e4, metavar="G|auto",
                   help="LS-SVM γ: smaller keeps the correction smaller; 'auto': by the free runs "
                   "of held-out logs (each left out from three, else blocks) (default %(default)g)")
    p.add_argument("--filter", type=float, metavar="HZ",
                   help="zero-phase low-pass of u, v, r before the fit [Hz] (default: none)")
    p.add_argument("--bootstrap", type=int, metavar="N",
                   help="N replicates of the correction on resampled equations (10 s blocks, "
                   "whole logs from five): 95 %% intervals on its turns and zig-zags")
    p.add_argument("--seed", type=int, default=0, help="the bootstrap's seed")
    p.add_argument("-o", "--output", required=True, metavar="SHIP.json")
    _add_log_options(p)
    p.set_defaults(func=cmd_correct)


def _add_mmg(sub) -> None:
    """``shipid mmg``'s arguments."""
    p = sub.add_parser("mmg", help="an MMG model file of a ship without one: a similar "
                       "ship's prime coefficients with this ship's particulars")  # fmt: skip
    p.add_argument("source", metavar="VESSEL|MMG.yml",
                   help="the similar ship: a built-in MMG ship (kvlcc2) or an MMG model file")
    p.add_argument("--particulars", required=True, metavar="FILE",
                   help="this ship's particulars (length, beam, draught, mass; propeller "
                   "diameter, rudder area and height, xg, rho where known), or a model file "
                   "of it that keeps them")
    p.add_argument("--speed", type=float, metavar="U",
                   help="approach speed [m/s] (default: the particulars' design speed, else the "
                   "source's at equal Froude number)")
    p.add_argument("--rps", metavar="N|logs",
                   help="the propeller's rate: a number, or 'logs': each log's measured rate "
                   "(and a manoeuvre's --rps) (default: trimmed for the approach speed)")
    p.add_argument("--rudder-rate", type=float, metavar="DEG/S",
                   help="rudder rate (default: the source's at equal Froude number)")
    p.add_argument("--name", help="the ship's name (default: the output's)")
    p.add_argument("-o", "--output", required=True, metavar="SHIP.yml")
    p.set_defaults(func=cmd_mmg)


def _add_rescale(sub) -> None:
    """``shipid rescale``'s arguments."""
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


def _add_study(sub) -> None:
    """``shipid study``'s arguments."""
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


def _add_import(sub) -> None:
    """``shipid import``'s arguments."""
    p = sub.add_parser("import", help="convert trial files to canonical logs")
    p.add_argument("logs", nargs="+", metavar="FILE")
    p.add_argument("-o", "--output", required=True, metavar="LOG.csv|LOG.parquet|DIR",
                   help="the canonical log; with several files, or into an existing folder, a "
                   "folder (each file keeps its name)")
    p.add_argument("--ext", default=".csv", choices=(".csv", ".parquet"),
                   help="into a folder: the output format (default %(default)s)")
    _add_log_options(p)
    p.set_defaults(func=cmd_import)


def _add_indices(sub) -> None:
    """``shipid indices``'s arguments."""
    p = sub.add_parser("indices", help="IMO indices of measured logs")
    p.add_argument("logs", nargs="+", metavar="LOG")
    p.add_argument("--kind", choices=KINDS, help="default: detected")
    p.add_argument("--heading", type=float, help="zig-zag switch heading [deg] (default: inferred)")
    p.add_argument("--smooth", type=float, default=0.0,
                   help="heading smoothing window [s] (default 0)")
    p.add_argument("--json", metavar="OUT.json")
    _add_log_options(p)
    p.set_defaults(func=cmd_indices)
