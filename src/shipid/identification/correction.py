"""A reference ship's model as the base, the logs fitting only what it misses (issue #10).

Where a model of the same ship is published (the KVLCC2's MMG model, a fit to captive tests),
its accelerations are kept whole, nonlinear form and all (the flow straightening that differs to
port and starboard, the propeller's wake in drift), and the LS-SVM fits a correction in the
terms of a structure to what they leave of the logs::

    ν̇ = f_ref(ν, δ) + Σⱼ θⱼ φⱼ(ν, δ) + b,

the increment form of the paper's eqs. (11)–(12) with f_ref moved to the target side: each
equation regresses (ξ(k+1) − ξ(k))/Δk − f_ref(ν(k), δ(k)) on the structure's terms, so at a
large γ a perfect reference leaves θ = 0. The corrected ship is a ``Vessel``, its steering and
trim the reference's: the Python API (``validate``, ``zigzag``, ``turning_circle``) runs it as
any reference ship, and ``shipid correct`` writes it to a file (``correction_document``) that
the commands taking a reference ship load (``reference_file``). The reference's propeller
stays at its own trim, or at each log's rate where it follows it (an MMG file's ``rps: logs``);
a correction has no propeller or thrust terms (the reference keeps its own), but may have the
relative wind's, a force no reference ship models (``blanke-race+wind``, the default where the
logs measure it). Every reference ship corrected runs compiled, its formula and the
correction's terms in one state derivative (``shipid.dynamics.kernel.corrected_rhs``), and
meets the wind; a term model run at similar rps steps in Python, without it, and refuses them.

On the Esso Osaka, which has no published model, the KVLCC2's MMG model with the Esso's
particulars (``shipid mmg``) predicts the zig-zags and turns better than the default fitted to
one of its files; corrected by the logs with the wind's terms, its held-out zig-zags and steady
turns closer still, its tactical diameters not (``benchmarks/study_esso_sister_mmg.py``).

On the KVLCC2's three real zig-zags (``benchmarks/study_kvlcc2_mmg_baseline.py``) the MMG model
with a correction fitted to one or two of them predicts the others' yaw rate and closed-loop
overshoots closer than the MMG model alone and than the models identified from the same runs.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence

import numpy as np
import pandas as pd

from shipid.data.log import column_values, in_rudder_convention, require_states
from shipid.data.preprocess import lowpass
from shipid.dynamics.model import ManoeuvringModel, ModelStructure, get_structure
from shipid.dynamics.terms import INPUT_SIGNALS, parse_term
from shipid.errors import ShipidError
from shipid.identification.estimators import fit_linear
from shipid.identification.physics import dof_physics
from shipid.identification.regression import regression_problem
from shipid.identification.uncertainty import Ensemble
from shipid.vessels.vessel import Vessel

DOFS = ("u", "v", "r")
# Terms the correction may hold: states, rudder and the relative wind (a force no reference
# ship models). Not the propeller's: the reference keeps its own.
ALLOWED_SIGNALS = {"u", "v", "r", "delta", "U", "beta", "wind_speed", "wind_angle"}
WIND = ("wind_speed", "wind_angle")
# The default structure; with the wind's terms where the logs measure the relative wind.
DEFAULT, DEFAULT_WIND = "blanke-race", "blanke-race+wind"


class CorrectedDynamics:
    """The reference ship's accelerations plus a ``ManoeuvringModel`` correction, as
    ``derivatives`` (the simulator's and the manoeuvres' generic path, stepped in Python: a
    model at similar rps corrected, and the reference the compiled runs are tested against)."""

    uses_thrust = False

    def __init__(self, reference, correction: ManoeuvringModel) -> None:
        self.reference = reference
        self.correction = correction

    @property
    def uses_rps(self) -> bool:
        """The reference's: an MMG ship whose propeller follows the runs' rps."""
        return getattr(self.reference, "uses_rps", False)

    @property
    def uses_wind(self) -> bool:
        """Whether the correction has wind terms (the runs then give the relative wind)."""
        return self.correction.uses_wind

    @property
    def inputs(self) -> tuple[str, ...]:
        """The input series a run takes: the rudder, the propeller's rate where the reference
        follows it, the relative wind where the correction has its terms."""
        return ("delta", *(("n",) if self.uses_rps else ()),
                *(c for c in self.correction.inputs if c in WIND))  # fmt: skip

    def derivatives(self, nu, delta, thrust=None, rps=None, **wind):
        """(B, 3) body accelerations at states nu (B, 3) and rudder delta (B,) (and the
        propeller's ``rps`` where the reference follows it, the relative ``wind_speed`` and
        ``wind_angle`` where the correction has wind terms). The correction through the
        compiled term kernel (a twentieth of the NumPy terms' time: the manoeuvres step this
        once per sample, in Python)."""
        nu = np.ascontiguousarray(nu, dtype=float)
        inputs = np.zeros((nu.shape[0], len(INPUT_SIGNALS)))
        rudder = INPUT_SIGNALS.index("delta")
        inputs[:, rudder] = delta
        for name, series in wind.items():
            inputs[:, INPUT_SIGNALS.index(name)] = series
        if isinstance(self.reference, ManoeuvringModel):
            own = self.reference.compiled_accelerations(nu, inputs)
        elif self.uses_rps:
            own = self.reference.derivatives(nu, inputs[:, rudder], None, rps)
        else:
            own = self.reference.derivatives(nu, inputs[:, rudder])
        return own + self.correction.compiled_accelerations(nu, inputs)


class CorrectedCompiledDynamics(CorrectedDynamics):
    """A reference ship with compiled entries for a correction (an MMG model, the tanker,
    CyberShip II, the Mariner: their ``corrected_kernels``) plus its correction, run in the
    compiled integrators: the correction's accelerations added to the ship's own at every
    evaluation (``shipid.dynamics.kernel.corrected_rhs``). Stepped in Python instead, a
    corrected tanker's 10° turns and zig-zags took ``shipid correct`` 16 s."""

    def __init__(self, reference, correction: ManoeuvringModel) -> None:
        super().__init__(reference, correction)
        code = correction.code
        self._terms = (np.ascontiguousarray(correction.theta, dtype=float), *code.arrays(),
                       code.uses_derived)  # fmt: skip

    def integrate_open(self, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
        """Free runs driven by (B, N, 5) inputs, the reference's propeller as it runs its own."""
        entry, _, lead = self.reference.corrected_kernels()
        entry(*lead, self._terms, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid)

    def integrate_closed(self, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder,
                         n_valid):  # fmt: skip
        """Closed-loop manoeuvres of parameter rows ``params``."""
        _, entry, lead = self.reference.corrected_kernels()
        entry(*lead, self._terms, self.correction.uses_wind, dt, n_steps, s0, params, rk4,
              speed_lim, yaw_lim, states, rudder, n_valid)  # fmt: skip


class CorrectedMMGDynamics(CorrectedCompiledDynamics):
    """An MMG reference (the built-in KVLCC2, a ship's MMG file) plus its correction: the
    runs it refuses are the MMG model's (a propeller not ahead, a ship not under way)."""

    propeller_ahead_only = True  # the MMG model's propeller

    def integrate_open(self, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
        """Free runs driven by (B, N, 5) inputs, the propeller at the reference's trim (or the
        inputs' rate, where it follows it)."""
        from shipid.vessels import mmg

        mmg.under_way(s0)
        if self.reference.follow_rps:
            mmg.ahead_only(inputs[:, :-1, 1], t)
        super().integrate_open(t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid)

    def integrate_closed(self, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder,
                         n_valid):  # fmt: skip
        """Closed-loop manoeuvres of parameter rows ``params``."""
        from shipid.vessels import mmg

        mmg.under_way(s0)
        if self.reference.follow_rps:
            mmg.ahead_orders(params)
        super().integrate_closed(dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states,
                                 rudder, n_valid)  # fmt: skip


def corrected_dynamics(reference, correction: ManoeuvringModel):
    """The reference's dynamics plus ``correction``: where the reference is itself a term model
    (the paper's scale ship), one term model of the two summed, which the compiled simulator
    runs (the same accelerations: the terms' union, each coefficient the sum); where it is an
    MMG model, a ``CorrectedMMGDynamics``, and another reference ship with compiled entries, a
    ``CorrectedCompiledDynamics``, compiled too; else (a model at similar rps) a
    ``CorrectedDynamics`` the simulator steps in Python. Each keeps ``correction``."""
    from shipid.vessels.mmg import MMGDynamics

    if isinstance(reference, MMGDynamics):
        return CorrectedMMGDynamics(reference, correction)
    if getattr(reference, "corrected_kernels", None) is not None:
        return CorrectedCompiledDynamics(reference, correction)
    if type(reference) is not ManoeuvringModel or reference.similar_at_rps is not None:
        return CorrectedDynamics(reference, correction)
    from shipid.identification.identify import average_models

    # Weights 1 and 1: each coefficient the sum of the two, a term one lacks counting 0.
    merged = average_models([(reference, 1.0), (correction, 1.0)], reference.structure,
                            f"{reference.name} + correction")  # fmt: skip
    merged.correction = correction  # what validate's report shows
    return merged


@dataclasses.dataclass(frozen=True)
class CorrectedEnsemble:
    """A correction's bootstrap replicates as corrected ships: the members whose runs give
    ``validate``'s bands and ``manoeuvre``'s and ``criteria``'s intervals, as a model file's
    ``Ensemble`` gives an identified model's. ``ensemble``: the correction's replicates;
    ``vessel``: the corrected ship; ``reference``: the ship corrected."""

    ensemble: Ensemble
    vessel: Vessel
    reference: Vessel
    members_label = "bootstrap replicates of the correction"

    @property
    def replicates(self) -> int:
        """Number of replicates."""
        return self.ensemble.replicates

    def members(self) -> list[Vessel]:
        """The corrected ship of each replicate's correction."""
        return [dataclasses.replace(self.vessel, dynamics=corrected_dynamics(
            self.reference.dynamics, c)) for c in self.ensemble.members()]  # fmt: skip


def ship_ensemble(ship) -> CorrectedEnsemble | None:
    """The bootstrap replicates a corrected ship carries (``identify_correction(...,
    bootstrap=N)``, or its file's ``uncertainty``), or None."""
    return getattr(getattr(ship, "dynamics", None), "correction_ensemble", None)


def _corrected_vessel(reference: Vessel, correction: ManoeuvringModel, by: str,
                      ensemble: Ensemble | None = None) -> Vessel:  # fmt: skip
    """The reference ship with ``correction`` added (``corrected_dynamics``), named for it and
    carrying the correction's bootstrap ``ensemble`` where there is one (``ship_ensemble``)."""
    vessel = dataclasses.replace(
        reference, name=f"{reference.name} + correction",
        dynamics=corrected_dynamics(reference.dynamics, correction),
        source=f"{reference.source}, corrected by {by}")  # fmt: skip
    if ensemble is not None:
        vessel.dynamics.correction_ensemble = CorrectedEnsemble(ensemble, vessel, reference)
    return vessel


@dataclasses.dataclass(frozen=True)
class Correction:
    """The corrected ship (``vessel``), the fitted ``correction`` and the reference's share of
    each equation: ``explained`` [dof] = 1 − var(target left after the reference) / var(the
    increments' own), over the training logs (1: the reference alone fits the logs); with
    γ "auto", each γ's cross-validated free-run score (``gamma_scores``, the lowest chosen);
    with a bootstrap, the corrections' ``ensemble`` (resampled equations, as ``identify
    --bootstrap`` resamples them), which the corrected ship carries (``ship_ensemble``)."""

    vessel: Vessel
    correction: ManoeuvringModel
    explained: dict[str, float]
    gamma: float
    gamma_scores: dict[float, float] = dataclasses.field(default_factory=dict)  # γ "auto"
    ensemble: Ensemble | None = None  # bootstrap
    reference: Vessel | None = None  # the ship corrected

    @property
    def replicates(self) -> list[ManoeuvringModel]:
        """The bootstrap replicates' corrections ([] without a bootstrap)."""
        return [] if self.ensemble is None else self.ensemble.members()

    def replicate_vessels(self) -> list[Vessel]:
        """The corrected ship of each bootstrap replicate's correction."""
        found = ship_ensemble(self.vessel)
        return [] if found is None else found.members()


def default_structure(logs: Sequence[pd.DataFrame], reference: Vessel | None = None) -> str:
    """The correction's structure where none is given: ``blanke-race``, with the wind's terms
    where every log measures the relative wind (the reference ships have no wind force) and
    the corrected ship can run them (``reference``: an MMG model or a term model)."""
    windy = logs and all(set(WIND) <= set(log.columns) for log in logs)
    return DEFAULT_WIND if windy and (reference is None or _runs_wind(reference)) else DEFAULT


def _runs_wind(reference: Vessel) -> bool:
    """Whether the corrected ``reference`` meets the wind in its closed loops: the compiled
    reference ships' runs and a term model's do; another (a model at similar rps) steps in
    Python, without."""
    dyn = reference.dynamics
    return getattr(dyn, "corrected_kernels", None) is not None or (
        type(dyn) is ManoeuvringModel and dyn.similar_at_rps is None)


def _check_wind(structure: ModelStructure, reference: Vessel, where: str = "") -> None:
    windy = sorted({t for terms in structure.terms.values() for t in terms
                    if set(parse_term(t).signals) & set(WIND)})  # fmt: skip
    if windy and not _runs_wind(reference):
        raise ShipidError(f"{where}the correction's wind terms ({', '.join(windy)}) are not run "
                          f"in {reference.name}'s manoeuvres (only a reference ship's and a "
                          "term model's meet the wind): give a structure without them")  # fmt: skip


def _structure(model) -> ModelStructure:
    structure = get_structure(model) if isinstance(model, str) else model
    bad = sorted({t for terms in structure.terms.values() for t in terms
                  if not set(parse_term(t).signals) <= ALLOWED_SIGNALS})  # fmt: skip
    if bad:
        raise ShipidError(f"a correction of a reference ship holds terms in u, v, r, δ and the "
                          f"relative wind only (the reference keeps its own propeller): "
                          f"{', '.join(bad)}")  # fmt: skip
    missing = [d for d in structure.dofs if d not in DOFS]
    if missing:
        raise ShipidError(f"unknown equation(s) {missing} in the correction's structure")
    return structure


# γ searched by ``gamma="auto"``: from a correction drawn hard toward zero (the reference
# trusted) to the paper's 1e4 and beyond; the free runs of held-out logs choose.
GAMMAS = (1.0, 10.0, 1e2, 1e3, 1e4, 1e5)
DIVERGENCE_PENALTY = 2.0  # normalised error of each held-out sample after a run diverged


def identify_correction(
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    reference: Vessel,
    model: str | ModelStructure | None = None,
    gamma: float | str = 1e4,
    filter_hz: float | None = None,
    names: Sequence[str] | None = None,
    bootstrap: int | None = None,
    seed: int = 0,
) -> Correction:
    """Fit a correction to ``reference``'s accelerations on ``logs`` (see the module's note).

    Parameters
    ----------
    logs : canonical logs of the ship, one uniform Δk; turned to the reference's rudder
        convention where they state theirs.
    reference : the reference ship (``shipid.vessels.get_vessel``) whose dynamics give
        ``derivatives(nu, delta)``.
    model : the correction's structure (terms in u, v, r, δ and the relative wind; "1" a
        constant); None: ``default_structure`` (``blanke-race``, ``+wind`` where every log
        measures the relative wind).
    gamma : the LS-SVM's regularisation (a small γ keeps the correction small), or "auto":
        the one of ``GAMMAS`` whose corrections run free closest to held-out logs (each log
        left out in turn from three logs, else four blocks of each; ``Correction.gamma_scores``).
    filter_hz : zero-phase low-pass of u, v, r before the increments (``identify``'s prefilter),
        or None. Held-out logs are run against as measured.
    bootstrap : replicates of the correction, refitted on the logs' equations resampled
        (moving 10 s blocks, whole logs from five logs: ``uncertainty.resampler``), ``seed``.
    """
    if not isinstance(reference, Vessel) or not hasattr(reference.dynamics, "derivatives"):
        raise ShipidError("the reference must be a reference ship (shipid.vessels.get_vessel)")
    if gamma != "auto" and not (isinstance(gamma, int | float) and np.isfinite(gamma)
                                and gamma > 0):  # fmt: skip
        raise ShipidError(f"gamma must be > 0 or 'auto', got {gamma!r}")
    logs = [logs] if isinstance(logs, pd.DataFrame) else list(logs)
    if not logs:
        raise ShipidError("no training logs given")
    structure = _structure(default_structure(logs, reference) if model is None else model)
    _check_wind(structure, reference)
    names = list(names) if names else [log.attrs.get("name", f"log {i + 1}")
                                       for i, log in enumerate(logs)]  # fmt: skip
    require_states(logs, names, "training log")
    if getattr(reference.dynamics, "uses_rps", False):
        for log, name in zip(logs, names, strict=True):
            if "n" not in log.columns:
                raise ShipidError(f"{name}: no propeller speed (column n), which the reference "
                                  f"{reference.name} runs at (its propeller follows the logs')")
            from shipid.vessels.mmg import ahead_only

            ahead_only(column_values(log, "n", float), column_values(log, "t", float), name)
    logs = [in_rudder_convention(log, reference.rudder_positive)[0] for log in logs]
    scores = {}
    if gamma == "auto":
        scores = _gamma_scores(logs, names, reference, structure, filter_hz)
        gamma = min(scores, key=scores.get)
    fitted = [lowpass(log, filter_hz) for log in logs] if filter_hz is not None else logs
    point: dict = {}

    def refit(weights: np.ndarray | None) -> ManoeuvringModel:
        correction, explained = _fit(fitted, names, reference, structure, float(gamma), weights)
        if weights is None:  # the point fit: its shares are the ones reported
            point["explained"] = explained
        return correction

    if bootstrap is None:
        ensemble, correction = None, refit(None)
    else:
        # identify --bootstrap's resampling of the equations, the point fit its first call.
        from shipid.identification.uncertainty import bootstrap as resampled

        ensemble = resampled(fitted, refit, bootstrap, "auto", seed)
        correction = ensemble.model
    vessel = _corrected_vessel(reference, correction, f"an LS-SVM fit to {len(logs)} log(s)",
                               ensemble)  # fmt: skip
    return Correction(vessel, correction, point["explained"], float(gamma), scores, ensemble,
                      reference)  # fmt: skip


def _reference_accelerations(reference: Vessel, log: pd.DataFrame) -> np.ndarray:
    """The reference's accelerations at the log's samples but the last (at the log's propeller
    speed where the reference follows it)."""
    nu = log[list(DOFS)].to_numpy(dtype=float)[:-1]
    delta = column_values(log, "delta", float)[:-1]
    if not getattr(reference.dynamics, "uses_rps", False):
        return reference.dynamics.derivatives(nu, delta)
    return reference.dynamics.derivatives(nu, delta, None, column_values(log, "n", float)[:-1])


def _fit(logs, names, reference: Vessel, structure: ModelStructure, gamma: float,
         weights: np.ndarray | None = None) -> tuple[ManoeuvringModel, dict[str, float]]:
    """The correction of ``reference`` on ``logs`` (filtered already) and the reference's
    share of each equation's increments; ``weights``: each equation's multiplicity (the logs'
    samples but the last of each, in order: a bootstrap replicate). Each equation is
    ``regression_problem``'s with the reference's accelerations as the known part of the
    target, computed once per log for the three."""
    own = {id(log): _reference_accelerations(reference, log) for log in logs}
    coefficients, terms, explained = {}, {}, {}
    for dof in structure.dofs:
        j = DOFS.index(dof)
        p = regression_problem(logs, structure, dof, names=names,
                               known=lambda log, j=j: own[id(log)][:, j])  # fmt: skip
        # Without "1" in the equation the fit has no bias either (b = 0), as identify's.
        physics = dof_physics(None, dof, p.names, p.has_constant, {}, logs)
        theta, bias = fit_linear(p.X, p.y, "lssvm", gamma, weights, physics=physics)
        coefficients[dof] = dict(zip(p.names, theta.tolist(), strict=True))
        terms[dof] = tuple(p.names) + (("1",) if p.has_constant else ())
        if p.has_constant:
            coefficients[dof]["1"] = float(bias)
        increments = p.y + np.concatenate([own[id(log)][:, j] for log in logs])
        spread = float(np.var(increments))
        explained[dof] = 1.0 - float(np.var(p.y)) / spread if spread > 0 else float("nan")
    correction = ManoeuvringModel(ModelStructure(f"correction ({structure.name})", terms),
                                  coefficients, name=f"correction of {reference.name}")  # fmt: skip
    return correction, explained


def _gamma_scores(logs, names, reference: Vessel, structure: ModelStructure,
                  filter_hz: float | None) -> dict[float, float]:  # fmt: skip
    """Per γ of ``GAMMAS``: the mean over folds of the held-out logs' free-run error (each
    state's rms over its spread, ``normalised_error``, averaged over u, v, r), the correction
    fitted on the other logs (filtered) and run from each held-out log's first sample."""
    from shipid.dynamics.simulate import simulate_log
    from shipid.identification.cross_validation import (
        choice_cv,
        folds,
        normalised_error,
        parse_cv,
        split_blocks,
    )

    cv = choice_cv(logs)
    if cv.startswith("blocks"):
        logs, names = split_blocks(logs, names, parse_cv(cv)[1])
        cv = "logo"
    fitted = [lowpass(log, filter_hz) for log in logs] if filter_hz is not None else logs
    scores = {}
    for gamma in GAMMAS:
        fold_scores = []
        for held in folds(len(logs), cv):
            train = [i for i in range(len(logs)) if i not in held]
            correction, _ = _fit([fitted[i] for i in train], [names[i] for i in train],
                                 reference, structure, gamma)  # fmt: skip
            dynamics = corrected_dynamics(reference.dynamics, correction)
            for i in held:
                measured = logs[i][list(DOFS)].to_numpy(dtype=float)
                sim = simulate_log(dynamics, logs[i], method="euler")
                simulated = sim.log[list(DOFS)].to_numpy(dtype=float)
                fold_scores.append(float(np.mean(normalised_error(measured, simulated,
                                                                  DIVERGENCE_PENALTY))))
        scores[gamma] = float(np.mean(fold_scores))
    return scores


# The file of a corrected reference ship (``shipid correct``): another format than a model
# file's, so that the commands that need an identified model refuse it by name.
CORRECTED_FORMAT = "shipid-corrected-ship"
CORRECTED_VERSION = 1


def correction_document(fit: Correction, reference: str | dict, training_files: Sequence[str] = (),
                        filter_hz: float | None = None) -> dict:  # fmt: skip
    """The JSON document of a corrected reference ship: the reference (a reference ship's name,
    or {"mmg": an MMG document} kept whole), the correction (a model's dict), how it was fitted
    and from which files (SHA-256); with a bootstrap, its replicates (``uncertainty``, a model
    file's record of them)."""
    from shipid import __version__
    from shipid.reporting.modelfile import sha256

    return {"format": CORRECTED_FORMAT, "version": CORRECTED_VERSION, "shipid": __version__,
            "reference": reference, "correction": fit.correction.to_dict(),
            "gamma": fit.gamma, "filter_hz": filter_hz, "explained": fit.explained,
            "gamma_scores": {f"{g:g}": v for g, v in fit.gamma_scores.items()},
            "training_files": [{"path": str(p), "sha256": sha256(p)} for p in training_files],
            "uncertainty": None if fit.ensemble is None else fit.ensemble.to_dict()}


def reference_file(path) -> Vessel | None:
    """The ship of a file that holds one: a corrected reference ship (``shipid correct``) or a
    ship's own MMG model (``shipid.vessels.mmg_file``); None for any other file (a model file,
    which its own reader reads). Read once per process while the file is unchanged: a command
    asks for it where it tells a ship's file from a model's and again where it runs it (the
    prior's trials, the report)."""
    from pathlib import Path

    p = Path(str(path))
    if not p.is_file() or p.suffix.lower() not in (".json", ".yml", ".yaml"):
        return None
    stat = p.stat()
    return _read_reference_file(str(p.resolve()), stat.st_mtime_ns, stat.st_size, str(path))


@functools.lru_cache(maxsize=16)
def _read_reference_file(resolved: str, mtime_ns: int, size: int, given: str) -> Vessel | None:
    from pathlib import Path

    from shipid.vessels.mmg_file import FORMAT as MMG_FORMAT
    from shipid.vessels.mmg_file import mmg_vessel, read_document

    p = Path(given)
    try:
        doc = read_document(p)
    except ShipidError:
        return None
    kind = doc.get("format") if isinstance(doc, dict) else None
    if kind == CORRECTED_FORMAT:
        return corrected_from_document(doc, p)
    if kind == MMG_FORMAT:
        return mmg_vessel(doc, str(p))
    return None


def corrected_from_document(doc: dict, path) -> Vessel:
    """The corrected reference ship of a parsed ``shipid correct`` file (one-line errors naming
    it)."""
    from pathlib import Path

    from shipid.vessels import VESSELS

    p = Path(str(path))
    if doc.get("version") != CORRECTED_VERSION:
        raise ShipidError(f"{path}: corrected ship file version {doc.get('version')!r} is not "
                          f"supported (this shipid reads {CORRECTED_VERSION})")  # fmt: skip
    name = doc.get("reference")
    if isinstance(name, dict) and "mmg" in name:
        from shipid.vessels.mmg_file import mmg_vessel

        reference = mmg_vessel(name["mmg"], f"{path}: reference.mmg")
    elif not isinstance(name, str) or name not in VESSELS:
        raise ShipidError(f"{path}: reference {name!r} is not a reference ship of this shipid "
                          f"({', '.join(VESSELS)}) nor an MMG model (reference.mmg)")  # fmt: skip
    else:
        reference = VESSELS[name]()
    try:
        correction = ManoeuvringModel.from_dict(doc.get("correction"))
    except ShipidError as exc:
        raise ShipidError(f"{path}: correction: {exc}") from None
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise ShipidError(f"{path}: malformed correction ({exc})") from None
    _structure(correction.structure)  # states, rudder and wind only, as fitted
    _check_wind(correction.structure, reference, f"{path}: ")
    data = doc.get("uncertainty")
    if data is not None and not isinstance(data, dict):
        raise ShipidError(f"{path}: uncertainty must be a mapping")
    ensemble = None if not data else Ensemble.from_dict(data, correction, f"{path}: uncertainty")
    return _corrected_vessel(reference, correction, p.name, ensemble)
