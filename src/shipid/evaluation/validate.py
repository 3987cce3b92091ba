"""Validation of a model against logs: free-run simulation from the measured initial state driven by
the measured rudder (paper section 4), error metrics per state and IMO indices measured vs simulated.

The facts of each log (its kind, execute, switch heading, rudder amplitude and rate) are read once
(``shipid.trials.trial.describe_trial``) and used for the measured indices, the simulated ones and
the closed-loop replica, so all three speak of the same manoeuvre.

Zig-zag and turning-circle indices are predicted twice. "simulated" reads them off the open-loop
replay (the measured rudder, switched when the *ship* reached the switch heading), so a small
heading drift of the model shifts its second overshoot by the whole drift. "closed_loop" runs the
manoeuvre itself on the model with the trial's rudder angle, rate, execute and (zig-zag) switch
heading: the model's own prediction of the manoeuvre, the one to compare overshoot angles with. It
starts from the trial's initial state, or, where the log approaches steady and the model's surge
answers the propeller, as ``shipid manoeuvre`` starts: straight, at the model's own steady speed at
the log's propeller speed, which a replay from the measured state never tests (``approach_speed``,
measured and closed loop, and a warning beyond 10 %). Trained on the Esso Osaka's zig-zags and
random runs at the logs' Δk of 0.1 s, a surge damped by u·|n| alone balanced at 0.52 m/s at 10 rps,
where the ship's 35° turns approach at 0.35 m/s; the replay's tactical diameter was 11 % and 5 %
long, the closed loop's 30 % and 17 % (``benchmarks/study_sampling.py``, before the hull's
resistance led the surge's ranking in ``select``).

A log that cannot be validated (a missing input column, a run that starts astern for a closed-loop
replica) does not stop the others: its ``Validation`` carries the error.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from shipid.data.log import (
    column_array,
    column_values,
    in_rudder_convention,
    mean_true_wind,
    require_frames,
    require_states,
    rudder_positive,
    starboard_sign,
    steady_start,
)
from shipid.data.trim import DEFAULT_LEAD_S
from shipid.dynamics.equilibrium import surge_equilibrium
from shipid.dynamics.hybrid import HybridModel
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.simulate import SimulationResult, require_dynamics, simulate_log
from shipid.dynamics.steering import SteeringMachine
from shipid.errors import ShipidError
from shipid.evaluation.error_band import ErrorBand
from shipid.evaluation.metrics import error_metrics
from shipid.identification.uncertainty import (
    Ensemble,
    ensemble_runs,
    free_run_bands,
    index_intervals,
)
from shipid.trials.indices import BOOKKEEPING, manoeuvre_indices, zigzag_indices
from shipid.trials.manoeuvres import ManoeuvreResult, turning_circle, zigzag
from shipid.trials.trial import TURN_KINDS, Trial, describe_trial, turning_at_order_note
from shipid.vessels.vessel import Vessel

STATES = ("u", "v", "r")


@dataclass
class Validation:
    """The validation of one log: its free run, errors per state and indices, or its error."""

    name: str
    simulation: SimulationResult | None
    metrics: dict[str, dict[str, float]]
    indices: dict[str, dict] = field(default_factory=dict)
    kind: str | None = None
    error: str | None = None
    warnings: list[str] = field(default_factory=list)
    # Why the log was read as the kind it was (``Trial.reason``): for "other", why no indices.
    kind_reason: str = ""
    # With a bootstrap ensemble: 95 % bands of the free run per state, how many replicates
    # diverged, and {"simulated"/"closed_loop": {index: (lower, upper)}}.
    bands: dict | None = None
    ensemble_diverged: int = 0
    intervals: dict[str, dict] = field(default_factory=dict)
    # With a cross-validated error band: the band and, per state, the share of samples in it.
    error_band: ErrorBand | None = None
    band_shares: dict[str, float] | None = None
    # Free runs restarted every H seconds (``shipid.evaluation.horizon``), one per horizon asked.
    horizons: list[dict] = field(default_factory=list)
    # How far the closed-loop indices move with the noise of the replica's start (``start_spread``).
    start_spread: dict[str, float] = field(default_factory=dict)
    # The log is one the model was fitted to (a file of its training logs): not a prediction.
    fitted_to: bool = False

    def to_frame(self):
        """The metrics as a DataFrame: one row per state (u, v, r), one column per metric."""
        import pandas as pd

        return pd.DataFrame.from_dict(self.metrics, orient="index").rename_axis("state")

    def to_dict(self) -> dict:
        """The validation as JSON-ready data (``validate --json``)."""
        sim = self.simulation
        return {"name": self.name, "error": self.error,
                "diverged": sim.diverged if sim else None,
                "diverged_at": sim.diverged_at if sim else None,
                "reason": sim.reason if sim else "", "manoeuvre": self.kind,
                "manoeuvre_reason": self.kind_reason,
                "metrics": self.metrics, "indices": self.indices,
                "index_intervals": {k: {i: list(b) for i, b in v.items()}
                                    for k, v in self.intervals.items()},
                "ensemble_diverged": self.ensemble_diverged if self.bands else None,
                "within_error_band": self.band_shares, "horizons": self.horizons,
                "closed_loop_start_spread": self.start_spread or None,
                "fitted_to": self.fitted_to, "warnings": self.warnings}  # fmt: skip


def free_run(model, log: pd.DataFrame, method: str = "euler") -> tuple[SimulationResult, dict]:
    """The free run of ``model`` on ``log`` and its error metrics per state (over the part
    simulated before any divergence); a reference ship (``Vessel``) runs its dynamics."""
    sim = simulate_log(model.dynamics if isinstance(model, Vessel) else model, log,
                       method=method)  # fmt: skip
    n = len(sim.log)
    return sim, {s: error_metrics(column_values(log, s)[:n], column_values(sim.log, s)) for s in STATES}


FADED_SHARE = 0.1  # a hybrid's run beyond its residual's envelope for more than this is named


def faded_residual_notes(model, log: pd.DataFrame) -> list[str]:
    """A note when a hybrid's run (``log``) left its kernel residual's envelope for more than
    ``FADED_SHARE`` of its samples; nothing for other models."""
    if not isinstance(model, HybridModel):
        return []
    faded = model.faded_share(log)
    if faded <= FADED_SHARE:
        return []
    return [f"the kernel residual is faded out over {100 * faded:.0f} % of the run (beyond its "
            "training envelope): there the physical model alone predicts"]


def validate_log(model, log: pd.DataFrame, name: str, method: str = "euler",
                 kind: str | None = None, smooth_s: float = 0.0,
                 ensemble: Ensemble | None = None,
                 error_band: ErrorBand | None = None,
                 start_draws: bool = True) -> Validation:  # fmt: skip
    """Validate ``model`` on one log (raises ``ShipidError`` when it cannot). With a bootstrap
    ``ensemble`` of the model: prediction bands and intervals on the predicted indices; with a
    cross-validated ``error_band``: the share of the log's samples within it."""
    require_states(log, [name], "log to validate against")
    convention = None
    if isinstance(model, Vessel):  # it says its rudder's convention: the log is turned to it
        log, convention = in_rudder_convention(log, model.rudder_positive)
    sim, metrics = free_run(model, log, method)
    trial = describe_trial(log, kind)
    # The indices come from the manoeuvre's approach; the errors from the whole log's free run.
    whole = log
    order_note = turning_at_order_note(trial, replica=True)
    log, trial = from_a_turning_order(whole, trial)
    notes, sim_indices = [], sim
    if log is whole:
        log, trial = manoeuvre_from_approach(whole, trial)
        if log is not whole:
            notes.append(_from_approach_note(whole, log))
    if log is not whole:
        sim_indices = free_run(model, log, method)[0]
    indices: dict[str, dict] = {}
    if trial.kind != "other":
        measured = manoeuvre_indices(log, smooth_s=smooth_s, trial=trial)
        steady = steady_log_approach(log, trial)
        measured["approach_speed"] = steady if steady else float(log["u"].iloc[0])
        indices = {"measured": measured, "simulated": _replay_indices(sim_indices, trial)}
        if getattr(model, "uses_thrust", False):
            # Replayed with the log's thrust; a closed loop of its own has none to run on.
            notes.append("no closed-loop replica: the model is driven by the log's thrust, "
                         "which a manoeuvre of its own does not have; the replay's indices are "
                         "its prediction")  # fmt: skip
        elif isinstance(model, ManoeuvringModel | HybridModel | Vessel):
            indices["closed_loop"] = _replica_indices(model, log, method, trial)
    out = Validation(name, sim, metrics, indices, trial.kind,
                     warnings=[convention] * bool(convention) + notes,
                     kind_reason=trial.reason)  # fmt: skip
    if indices.get("closed_loop") and start_draws:
        out.start_spread = start_spread(model, log, method, trial, indices["closed_loop"])
    out.warnings += [order_note] * bool(order_note and indices)
    out.warnings += _approach_notes(indices)
    out.warnings += _turn_notes(indices)
    if trial.kind == "zigzag" and "closed_loop" in indices:
        out.warnings += _reversal_notes(trial)
    out.warnings += faded_residual_notes(model, sim.log)
    if error_band is not None:
        out.error_band = error_band
        out.band_shares = error_band.shares_within(column_array(whole, STATES),
                                                   column_array(sim.log, STATES))  # fmt: skip
    if ensemble is not None:
        runs = ensemble_runs(ensemble, whole, method)
        out.bands, out.ensemble_diverged = free_run_bands(runs, len(whole))
        if trial.kind != "other":
            if log is not whole:
                runs = ensemble_runs(ensemble, log, method)
            replays = [_replay_indices(r, trial) for r in runs]
            out.intervals["simulated"] = index_intervals(replays)
            out.warnings += _unbounded_notes("replay", out.intervals["simulated"], replays,
                                             runs, ensemble.members_label)
            if "closed_loop" in indices:
                # Each replicate from a start drawn with the noise of the log's first sample:
                # the trial's own start is known only to that noise (``start_spread``).
                members = ensemble.members()
                starts = drawn_starts(model, log, trial, len(members), seed=1) or \
                    [None] * len(members)  # fmt: skip
                replicas = [trial_replica(m, log, method, trial, start, indices=False)
                            for m, start in zip(members, starts, strict=True)]  # fmt: skip
                samples = [_indices_of(r, trial, log) for r in replicas]
                _say_why_values_lack(replicas, samples, members, starts, log, method, trial)
                out.intervals["closed_loop"] = index_intervals(samples)
                out.warnings += _unbounded_notes("closed loop", out.intervals["closed_loop"],
                                                 samples, replicas, ensemble.members_label)
    return out


# Seconds of the approach kept before the execute where a log's approach is not a steady one
# (``manoeuvre_from_approach``): ``--start auto``'s default lead.
APPROACH_LEAD_S = DEFAULT_LEAD_S


def manoeuvre_from_approach(log: pd.DataFrame, trial: Trial) -> tuple[pd.DataFrame, Trial]:
    """``log`` and its ``trial`` from ``APPROACH_LEAD_S`` before the execute where the ship does
    not run steady and straight up to it (it gathers speed from rest, or starts without
    headway, or turns), as ``--start auto`` trims; else both as they are.

    A manoeuvre's indices are counted from its execute, but its replay and its closed-loop
    replica run from the log's first sample. The Esso Osaka's turning logs start at rest and
    gather speed for 120 s: from there the replay of a model fitted to the zig-zags put the
    +35° turn's tactical diameter at 4.1 m, from the approach 9.9 m (measured 7.3 m), and the
    −35° turn, which starts at −0.014 m/s, had no closed loop at all."""
    t = column_values(log, "t", float)
    if trial.kind == "other" or trial.execute_time - t[0] <= APPROACH_LEAD_S + (t[1] - t[0]):
        return log, trial
    if float(log["u"].iloc[0]) > 0 and steady_start(log, trial.execute_index).steady:
        return log, trial
    part = log.loc[t >= trial.execute_time - APPROACH_LEAD_S].reset_index(drop=True)
    part.attrs = dict(log.attrs)
    return part, describe_trial(part, trial.kind)


def from_a_turning_order(log: pd.DataFrame, trial: Trial) -> tuple[pd.DataFrame, Trial]:
    """``log`` and its ``trial`` from the execute on, where the ship turns on its approach
    (``Trial.turning_at_order``); else both as they are.

    The closed-loop replica runs to the execute with one rudder held (``approach_rudder``), not
    the approach's: after 4 s of −20° rudder, the scale ship's own replica of its 35° turn put
    the advance 31 % short of the log's and the tactical diameter 16 % long with the rudder of
    the log's first sample, 3 % and 1 % with the approach's mean (ad hoc), and ``validate``
    laid the log's approach on the model. From the execute, measured, replayed and replica
    start from the state the ship was in there, and agree (``turning_at_order_note`` says
    so)."""
    if trial.kind == "other" or trial.turning_at_order is None or trial.execute_index == 0:
        return log, trial
    part = log.iloc[trial.execute_index :].reset_index(drop=True)
    part.attrs = dict(log.attrs)
    return part, describe_trial(part, trial.kind)


def _from_approach_note(whole: pd.DataFrame, part: pd.DataFrame) -> str:
    t0, u0 = float(whole["t"].iloc[0]), float(whole["u"].iloc[0])
    t1, u1 = float(part["t"].iloc[0]), float(part["u"].iloc[0])
    return (f"its approach is not steady (u {u0:.3g} m/s at t = {t0:g} s, {u1:.3g} m/s at "
            f"t = {t1:g} s, {APPROACH_LEAD_S:g} s before the execute): its indices, measured, "
            "replayed and run closed loop, are taken from there, as --start auto trims (the "
            "errors are of the whole log)")


def _say_why_values_lack(replicas: list, samples: Sequence[dict], members: Sequence,
                         starts: Sequence, log: pd.DataFrame, method: str, trial: Trial) -> None:
    """Each replica in ``replicas`` that runs without diverging but lacks an index the others
    have, run again with the manoeuvre's own indices, whose ``incomplete`` says why (the counter
    rudder has not checked the yaw, the turn is not steady). Computed for every replica, those
    indices, which ``validate`` never reads (it reads the values as the log's are,
    ``_indices_of``), were about a third of a 100-replicate ensemble's closed loops (profiled,
    ad hoc)."""
    keys = {k for sample in samples for k, x in sample.items()
            if isinstance(x, float) and math.isfinite(x)}  # fmt: skip
    for i, (replica, sample) in enumerate(zip(replicas, samples, strict=True)):
        if replica is None or replica.diverged:
            continue
        if any(not (isinstance(sample.get(k), float) and math.isfinite(sample[k])) for k in keys):
            replicas[i] = trial_replica(members[i], log, method, trial, starts[i])


def _unbounded_notes(label: str, intervals: dict, samples: Sequence[dict], runs: Sequence,
                     members: str) -> list[str]:  # fmt: skip
    """Why an index's interval is not bounded: how many replicates have no value, and why
    (``shipid.trials.manoeuvres.without_value``)."""
    from shipid.trials.manoeuvres import without_value

    notes = []
    for k, (lo, hi) in intervals.items():
        if math.isinf(lo) or math.isinf(hi):
            missing, why = without_value(runs, [s.get(k) for s in samples],
                                         "never reach it within the log")  # fmt: skip
            notes.append(f"{k} ({label}) is not bounded: {missing} of {len(samples)} {members} "
                         f"have none ({why})")  # fmt: skip
    return notes


def _read_as_logged(run: pd.DataFrame, trial: Trial, t_exec: float) -> dict:
    """The indices of a simulated ``run`` read as the log's are: its kind and switch heading,
    from the execute at ``t_exec`` (the log's, on the run's time axis)."""
    return manoeuvre_indices(run, trial=describe_trial(run, trial.kind, trial.switch_heading_deg,
                                                       t_exec, indices_only=True))  # fmt: skip


def _replay_indices(sim: SimulationResult, trial: Trial) -> dict:
    return {} if sim.diverged else _read_as_logged(sim.log, trial, trial.execute_time)


# Indices whose spread with the replica's start ``validate`` shows (all are kept).
START_SHOWN = ("first_overshoot_deg", "second_overshoot_deg", "advance", "tactical_diameter",
               "steady_yaw_rate")  # fmt: skip
# Starts drawn for ``start_spread``, and the longest log it draws them for (each draw is one
# more closed-loop run and its indices).
START_DRAWS = 10
START_MAX_SAMPLES = 20_000


def start_spread(model, log: pd.DataFrame, method: str, trial: Trial, point: dict
                 ) -> dict[str, float]:  # fmt: skip
    """How far the closed-loop replica's indices (``point``) move with the noise of its start,
    the log's first measured u, v, r (one sample each): their standard deviation over
    ``START_DRAWS`` replicas started from that state plus each state's white noise
    (``white_noise_variance``, from second differences; a seeded draw). {} where the replica
    starts from the model's own steady approach, not from the log's state, or the log is longer
    than ``START_MAX_SAMPLES``.

    On the demo's noisy trials the true model's replica misses the measured 10°/10°
    overshoots by 0.43° and 0.46° (standard deviation over 60 seeds), and by 0.05° from the
    noise-free start: the noise of one sample, not the model. (The delta method, each state
    moved by its noise alone, read twice that: a reversal falls on one sample or the next.)"""
    starts = drawn_starts(model, log, trial, START_DRAWS) if point and \
        len(log) <= START_MAX_SAMPLES else None  # fmt: skip
    if starts is None:
        return {}
    draws = [_indices_of(trial_replica(model, log, method, trial, start, indices=False), trial,
                         log) for start in starts]  # fmt: skip
    out = {}
    for k, x in point.items():
        if k in BOOKKEEPING or k == "approach_speed" or not isinstance(x, float):
            continue
        values = [d.get(k) for d in draws]
        values = [v for v in values if isinstance(v, float) and math.isfinite(v)]
        if len(values) == START_DRAWS:  # a start that loses the index: no spread to give
            out[k] = float(np.std(values, ddof=1))
    return out


def drawn_starts(model, log: pd.DataFrame, trial: Trial, n: int, seed: int = 0
                 ) -> list[dict] | None:  # fmt: skip
    """``n`` starts for closed-loop replicas of ``log``: its first measured u, v, r plus each
    state's white noise (``white_noise_variance``), seeded. None where the replica starts from
    ``model``'s own steady approach instead, or the log shows no noise."""
    from shipid.data.preprocess import white_noise_variance

    if isinstance(model, ManoeuvringModel | HybridModel) and \
            _own_approach(model, log, trial, _log_wind(model, log)) is not None:  # fmt: skip
        return None
    first = log.iloc[0]
    sigma = {s: math.sqrt(white_noise_variance(column_values(log, s, float))) for s in STATES}
    if not any(x > 0 for x in sigma.values()):
        return None
    rng = np.random.default_rng(seed)
    return [{s: float(first[s]) + sigma[s] * float(rng.standard_normal()) for s in STATES}
            for _ in range(n)]  # fmt: skip


def _replica_indices(model, log: pd.DataFrame, method: str, trial: Trial) -> dict:
    return _indices_of(trial_replica(model, log, method, trial, indices=False), trial, log)


def _indices_of(replica: ManoeuvreResult | None, trial: Trial, log: pd.DataFrame) -> dict:
    """A closed-loop replica's indices ({} when there is none or it diverged), read as the
    log's are: from the execute ``describe_trial`` found in the log (the last sample before the
    rudder swings), with the speed it approached at.

    The replica's rudder moves at the log's samples, but the manoeuvre's own indices count from
    its order time, one sample later (the compiled step that gives the order moves the rudder
    in it). Read from there, the true model's replica of its own noise-free trial had the
    advance 0.39 m (2.5 %) short and the initial turning time 0.2 s short (Δt 0.2 s).

    A replica stepped finer than the log (``replica_step``) is read at the log's sampling, as
    the log is: every sample of it that falls on one of the log's times (its switches stay
    where its finer steps put them). Read at every step, a 100-replicate ensemble's two Esso
    turns spent most of the time the finer steps added to ``validate`` reading them (profiled,
    ad hoc); what they cost now: ``benchmarks/bench_validate_replicas.py``."""
    if replica is None or replica.diverged:
        return {}
    run = _at_the_logs_sampling(replica.log, log)
    t_exec = float(run["t"].iloc[0]) + trial.execute_time - float(log["t"].iloc[0])
    read = _read_as_logged(run, trial, t_exec)
    read.pop("kind", None)
    return {**read, "approach_speed": float(run["u"].iloc[0])}


def _at_the_logs_sampling(run: pd.DataFrame, log: pd.DataFrame) -> pd.DataFrame:
    """``run`` (a replica of ``log``) at ``log``'s sampling where it steps a whole fraction of
    it; else as it is."""
    t, step = column_values(log, "t"), column_values(run, "t")
    if len(t) < 2 or len(step) < 2:
        return run
    sampling, dt = float(np.median(np.diff(t))), float(step[1] - step[0])
    every = int(round(sampling / dt))
    if every < 2 or abs(every * dt - sampling) > 1e-9 * sampling:
        return run
    out = run.iloc[::every].reset_index(drop=True)
    out.attrs = dict(run.attrs)
    return out


def steady_log_approach(log: pd.DataFrame, trial: Trial) -> float | None:
    """The mean speed over the approach of ``log`` (up to the rudder execute) when the ship runs
    steady and straight there (``shipid.data.log.steady_start``); else None."""
    start = steady_start(log, trial.execute_index)
    return start.speed if start.steady else None


def _log_wind(model, log: pd.DataFrame) -> tuple[float, float] | None:
    """The true wind a replica of ``log`` meets: the log's mean (``mean_true_wind``) for a model
    with wind terms (it met still air before: on the Esso Osaka's +35° turn, 1.1 m/s at three
    times the ship's speed, its tactical diameter came 8.47 m instead of 8.02 m, measured 7.27
    m), else None."""
    uses = getattr(model.dynamics if isinstance(model, Vessel) else model, "uses_wind", False)
    return mean_true_wind(log) if uses else None


def _own_approach(model, log: pd.DataFrame, trial: Trial, wind: tuple[float, float] | None
                  ) -> tuple[float, float | None] | None:  # fmt: skip
    """(speed, rps) of ``model``'s own steady straight approach at the log's propeller speed in
    the true ``wind`` on the log's approach heading, when the log's approach is steady and the
    model's surge answers the propeller (the approach ``shipid manoeuvre`` and ``criteria``
    start from); else None."""
    if not getattr(model, "uses_rps", False) or "n" not in log.columns:
        return None
    if getattr(model, "similar_at_rps", None):
        # Its n terms come from similarity, not from logs at several rps: it starts where the
        # log does, as the model without them did (``shipid.dynamics.similarity``).
        return None
    measured = steady_log_approach(log, trial)
    if measured is None:
        return None
    rps = float(log["n"].iloc[: trial.execute_index + 1].mean())
    # At the log's own rps, near its measured speed: three times it is far enough (a model that
    # balances further off has no steady approach there worth the name).
    steady = surge_equilibrium(model, measured, rps, wind=wind, psi=trial.psi0)
    return (steady, rps) if steady is not None and steady > 0 else None


def _replica_start(model, log: pd.DataFrame, trial: Trial, start: dict | None = None
                   ) -> tuple[dict, float | None, tuple[float, float] | None]:  # fmt: skip
    """(initial state, propeller speed, true wind) of a closed-loop replica: the log's first
    state (or ``start``'s states in its place), its rudder held at ``approach_rudder`` up to
    the execute, at its median rps from the execute on; where the log approaches steady and
    ``model``'s surge answers the propeller, straight at the model's own steady speed at the
    log's approach rps instead (the approach ``shipid manoeuvre`` starts from); the wind
    ``_log_wind`` gives."""
    row = log.iloc[0]
    initial = {k: float(row[k]) for k in ("u", "v", "r", "psi") if k in log.columns}
    initial.update(start or {})
    initial["delta"] = approach_rudder(log, trial)
    # The propeller speed the manoeuvre ran at: a log read whole ends with the propeller
    # stopped (the Esso Osaka's zig-zags for 2–8 s), which its mean counted (13_14_21: 15.6
    # rps for 16.7).
    rps = float(np.median(column_values(log, "n")[trial.execute_index :])) \
        if "n" in log.columns else None  # fmt: skip
    wind = _log_wind(model, log)
    own = _own_approach(model, log, trial, wind) \
        if isinstance(model, ManoeuvringModel | HybridModel) else None  # fmt: skip
    if own is not None:
        initial.update(u=own[0], v=0.0, r=0.0)
        rps = own[1]
    return initial, rps, wind


def approach_rudder(log: pd.DataFrame, trial: Trial) -> float:
    """The rudder a closed-loop replica holds from the log's first sample up to the execute:
    the mean of the log's over that approach, the helm the ship held its course with. The
    rudder of the first sample alone was a helm correction's on the Esso Osaka's approaches
    (13_14_21: −2.8° against 6.6° on average over its 5 s, 14_03_39: −6.7° against −1.5°), which
    the replica held for 5 s before its order: over the nine zig-zags each held out at Δk
    0.5 s, their first overshoots' mean miss came down from 1.44° to 0.96° and the second's
    from 2.23° to 1.77° (``benchmarks/study_replica_step.py``)."""
    delta = column_values(log, "delta", float)
    return float(np.mean(delta[: trial.execute_index + 1]))


def _approach_notes(indices: dict) -> list[str]:
    """A warning when a model's own steady approach is far from the log's measured one."""
    measured = (indices.get("measured") or {}).get("approach_speed")
    own = (indices.get("closed_loop") or {}).get("approach_speed")
    if not measured or not own or abs(own / measured - 1) <= APPROACH_TOLERANCE:
        return []
    return [f"the model's steady straight speed at the log's propeller speed is {own:.4g} m/s, "
            f"the log's steady approach {measured:.4g} m/s ({100 * (own / measured - 1):+.0f} %): "
            "manoeuvres run on the model from its own approach (shipid manoeuvre, criteria, the "
            "closed-loop column) start at the wrong speed; give them --speed, or identify with "
            "--steady-speed U@N (a straight run's speed) and validate again"]


APPROACH_TOLERANCE = 0.10
# A closed-loop steady turning diameter further than this from the measured one is taken apart
# into its speed and its yaw rate (``_turn_notes``).
TURN_TOLERANCE = 0.10


def _turn_notes(indices: dict) -> list[str]:
    """Where the closed loop's steady turn is wider or tighter than the log's by more than
    ``TURN_TOLERANCE``: which of its two factors, the speed in the turn or the yaw rate, carries
    the miss. A steady turn's diameter is 2U/|r|, so the two say which equation to look at: the
    surge's loss of speed in the turn, which zig-zags hardly excite (from one Esso Osaka zig-zag
    the 35° turns held 1.2–2.1 times the measured speed where their yaw rates came within
    10 %; benchmarks/README.md), or the sway and yaw equations'."""
    measured, closed = indices.get("measured") or {}, indices.get("closed_loop") or {}
    values = [d.get(k) for d in (measured, closed)
              for k in ("steady_turning_diameter", "steady_speed", "steady_yaw_rate")]
    if not all(isinstance(x, float) and math.isfinite(x) and x != 0 for x in values):
        return []
    d_meas, u_meas, r_meas, d_model, u_model, r_model = values
    if abs(d_model / d_meas - 1) <= TURN_TOLERANCE:
        return []
    speed, yaw = u_model / u_meas, abs(r_model / r_meas)
    if abs(math.log(speed)) > 2 * abs(math.log(yaw)):
        what = ("mostly the speed: the surge equation's loss of speed in the turn, which "
                "zig-zags hardly excite; train on a turning log too")
    elif abs(math.log(yaw)) > 2 * abs(math.log(speed)):
        what = "mostly the yaw rate: the sway and yaw equations' balance in the turn"
    else:
        what = ("both: the surge's loss of speed in the turn and the sway and yaw equations' "
                "balance in it")
    return [f"the closed loop's steady turn is {d_model:.4g} m across, the log's "
            f"{d_meas:.4g} m ({100 * (d_model / d_meas - 1):+.0f} %): its speed in the turn "
            f"{u_model:.4g} m/s against {u_meas:.4g} m/s ({100 * (speed - 1):+.0f} %), its "
            f"yaw rate {abs(r_model):.4g} rad/s against {abs(r_meas):.4g} rad/s "
            f"({100 * (yaw - 1):+.0f} %); a steady turn is 2U/|r| across, so the miss is {what}"]


# Reversal headings of a zig-zag further apart than this [deg], and than the heading's change over
# one sample there (how finely the log, and a replica stepping as it does, resolve them), are the
# trial's own execution: the closed loop reverses at each of them in turn, as the trial did, not
# at their median every time (MARIN's −20° run at Δk 0.2 s: 19.81°, −21.24°, 19.54°, 0.7° a
# sample, where a degree of switch heading moved an overshoot by 1.0–1.5°, ad hoc).
REVERSAL_SPREAD_DEG = 1.0


def uneven_reversals(trial: Trial) -> list[float] | None:
    """The heading changes [deg] at which a zig-zag's rudder was reversed, in turn, where they lie
    further apart than ``REVERSAL_SPREAD_DEG`` and a sample's heading change; else None."""
    sizes = [abs(h) for h in trial.reversal_headings_deg]
    if len(sizes) < 2 or not min(sizes) > 0 or max(sizes) - min(sizes) <= max(
            REVERSAL_SPREAD_DEG, trial.reversal_step_deg):  # fmt: skip
        return None  # (a reversal at no heading change is none a replica can make)
    return list(trial.reversal_headings_deg)


def _reversal_notes(trial: Trial) -> list[str]:
    """A note where the trial's rudder was reversed unevenly (``uneven_reversals``): the closed
    loop follows its reversals, so what is left of its overshoot errors is the model's."""
    headings = uneven_reversals(trial)
    if headings is None:
        return []
    sizes = [abs(h) for h in headings]
    shown = ", ".join(f"{h:+.2f}°" for h in headings)
    return [f"its rudder was reversed at heading changes of {shown} ({max(sizes) - min(sizes):.2g}° "
            f"apart, around the median {trial.switch_heading_deg:.4g}°): the closed loop reverses "
            "at each of them in turn, as the trial did (its overshoots are measured from the "
            "median, as the log's are)"]


def trial_replica(model, log: pd.DataFrame, method: str = "euler", trial: Trial | None = None,
                  start: dict | None = None, indices: bool = True,
                  step: float | None = None) -> ManoeuvreResult | None:  # fmt: skip
    """The log's manoeuvre run closed loop on ``model`` (``trial_zigzag``, ``trial_turning``);
    None for other logs. ``start``: states that replace the log's first ones. ``indices=False``:
    without the manoeuvre's own indices, for a caller that reads them as the log's are
    (``_indices_of``; computed twice, they were half of ``start_spread``'s time). ``step``: the
    integration step [s] (default ``replica_step(log)``)."""
    trial = trial or describe_trial(log)
    if trial.kind == "zigzag":
        return trial_zigzag(model, log, method, trial, start, indices, step)
    if trial.kind in TURN_KINDS:  # a pull-out's replica is released where the log was
        return trial_turning(model, log, method, trial, start, indices, step)
    return None


def trial_turning(model, log: pd.DataFrame, method: str = "euler", trial: Trial | None = None,
                  start: dict | None = None, indices: bool = True,
                  step: float | None = None) -> ManoeuvreResult | None:  # fmt: skip
    """The turning circle of a measured log run on ``model`` as ``shipid manoeuvre turning``
    runs it: where the log approaches steady and the model's surge answers the propeller, from
    the model's own steady straight speed at the log's propeller speed (straight, the log's
    heading and held rudder); else from the log's initial state. The log's rudder angle, side,
    rate, execute time, propeller speed and duration (``step``: as ``trial_replica``'s). None
    when the log starts without headway."""
    trial = trial or describe_trial(log, "turning")
    if not float(log["u"].iloc[0]) > 0:
        return None
    # The side of the rudder held from the execute (``trial.first_rudder`` is a zig-zag's: a
    # turn's mid-range "neutral" puts its approach rudder on the other side). The largest swing
    # from the first sample was the release of a pull-out that starts on its order: its replica
    # turned the other way.
    delta = column_values(log, "delta", float)
    held = float(np.median(delta[trial.execute_index : trial.held_end_index + 1]))
    turns = np.sign(held) * starboard_sign(rudder_positive(log))
    initial, rps, wind = _replica_start(model, log, trial, start)
    # A turn that ends in a pull-out is released where the log's was: held on, the replica's
    # steady turn was read over a later span than the log's (0.16 % on the scale ship's).
    release = math.inf if trial.release_time is None else \
        trial.release_time - float(log["t"].iloc[0])  # fmt: skip
    return turning_circle(model, math.degrees(trial.plateau_angle),
                          "starboard" if turns > 0 else "port", speed=initial["u"], method=method,
                          rps=rps, initial=initial, release=release, indices=indices,
                          **_replica_run(log, trial, wind, step))  # fmt: skip


# A closed-loop replica of a measured log runs at steps in which its heading turns at most this
# much at the log's largest yaw rate [rad], in at most ``REPLICA_MAX_STEPS`` steps.
REPLICA_HEADING_STEP = math.radians(0.1)
REPLICA_MAX_STEPS = 100_000


def replica_step(log: pd.DataFrame) -> float:
    """The step a closed-loop replica of ``log`` runs at: a simulated log's own integrator step
    (its metadata's ``integrator``: the true model's replica of its trial is then that trial, to
    the bit); for a measured log, the largest whole fraction of its sampling in which the heading
    turns ``REPLICA_HEADING_STEP`` at the log's largest yaw rate (its sampling where that is
    finer already), in no more than ``REPLICA_MAX_STEPS``.

    A measured ship runs in continuous time, and a replica reverses its rudder at the first step
    after its heading reaches the switch. At the log's own step that came up to a step late:
    the true ship's 20°/20° zig-zag sampled every 0.5 s (its RK4 run at 0.01 s) came back from
    its own model with overshoots 1.1° and 0.8° too large at 0.1 s steps, 2.0° and 8.7° at
    0.5 s (now within 0.2°); the Esso Osaka's nine zig-zags, each held out at Δk 0.5 s, had
    their first overshoots predicted 2.1° large on average, now 0.7° (with ``approach_rudder``)
    (``benchmarks/study_replica_step.py``). It costs ``validate`` of the README's Esso example
    (100 replicates) 1.4 times its time at the log's step (``bench_validate_replicas.py``)."""
    made = log.attrs.get("integrator")
    if made:
        return float(made["step"])
    t = column_values(log, "t")
    sampling = float(np.median(np.diff(t)))
    yaw = np.abs(column_values(log, "r", float)) if "r" in log.columns else np.zeros(1)
    fastest = float(np.nanmax(yaw)) if np.isfinite(yaw).any() else 0.0
    needed = math.ceil(sampling * fastest / REPLICA_HEADING_STEP - 1e-9) if fastest > 0 else 1
    allowed = math.floor(REPLICA_MAX_STEPS * sampling / max(float(t[-1] - t[0]), sampling))
    return sampling / max(1, min(needed, allowed))


def _replica_run(log: pd.DataFrame, trial: Trial, wind: tuple[float, float] | None,
                 step: float | None = None) -> dict:
    """What a closed-loop replica takes from the log as it is: duration, ``step`` (default
    ``replica_step``), the execute time (``approach``: the first sample the rudder has moved at
    in a simulated log, halfway to it from the last one before in a measured log), the steering
    machine (the log's rudder rate, and an angle limit that holds its rudder) and the true
    ``wind`` (``_log_wind``; the turn's own approach is found in it too, ``_own_approach``)."""
    t = column_values(log, "t")
    ordered = min(trial.execute_index + 1, len(t) - 1)
    approach = float(t[ordered] - t[0])
    if not log.attrs.get("integrator") and ordered > 0:
        # A measured rudder was ordered between the last sample on the approach and the next,
        # on average halfway (as the reversal headings are read): at the next sample, a turn of
        # the scale ship sampled every 0.5 s came back 0.45 m long in advance, on average
        # (``benchmarks/study_replica_step.py``).
        approach -= 0.5 * float(t[ordered] - t[ordered - 1])
    return {"duration": float(t[-1] - t[0]), "dt": step or replica_step(log),
            "approach": approach,
            "steering": SteeringMachine(max_angle=max(math.radians(35.0), trial.plateau_angle),
                                        max_rate=trial.rudder_rate),
            **({"wind": wind} if wind is not None else {})}  # fmt: skip


def validate(
    model,
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    names: Sequence[str] | None = None,
    method: str = "euler",
    kind: str | None = None,
    smooth_s: float = 0.0,
    ensemble: Ensemble | None = None,
    error_band: ErrorBand | None = None,
    start_draws: bool = True,
) -> list[Validation]:
    """Validate ``model`` on each log; errors are over the simulated (not diverged) part. A log
    that cannot be validated gets a ``Validation`` with ``error`` set; the others go on. With a
    bootstrap ``ensemble`` of the model (``shipid.identification.uncertainty``): bands and
    intervals; with a cross-validated ``error_band`` (``Selection.error_band``): each log's share
    of samples within it; ``start_draws``: the closed loop's spread with its start
    (``start_spread``, ``START_DRAWS`` more closed-loop runs per log)."""
    require_dynamics(model)
    logs = require_frames(logs, names, "log to validate against")
    names = names or [log.attrs.get("name", f"log {i}") for i, log in enumerate(logs)]
    out = []
    for log, name in zip(logs, names, strict=True):
        try:
            out.append(validate_log(model, log, name, method, kind, smooth_s, ensemble,
                                    error_band, start_draws))
        except ShipidError as exc:
            message = str(exc)
            # Messages from deeper down may name the log by its file name alone.
            short = f"{Path(name).name}: "
            if message.startswith(short) and not message.startswith(name):
                message = message[len(short):]
            out.append(Validation(name, None, {}, {}, None,
                                  message if message.startswith(name) else f"{name}: {message}"))
    return out


def trial_zigzag(model, log: pd.DataFrame, method: str = "euler", trial: Trial | None = None,
                 start: dict | None = None, indices: bool = True,
                 step: float | None = None) -> ManoeuvreResult | None:  # fmt: skip
    """The zig-zag of a measured log run closed loop on ``model``: same initial state (u, v, r, ψ)
    and held rudder (or the model's own steady approach, ``_replica_start``), first execute time
    and side, rudder angle (the median plateau), rudder rate (over its swings,
    ``shipid.data.rudder_signal.rise_rate``), switch heading (inferred from the log; where the
    trial reversed unevenly, each reversal at its own: ``uneven_reversals``), mean propeller
    speed and duration (``step``: as ``trial_replica``'s).
    None when the log has no detectable switch heading or starts without headway (a zig-zag
    needs an approach speed)."""
    trial = trial or describe_trial(log, "zigzag")
    switch = trial.switch_heading_deg
    if not switch or not float(log["u"].iloc[0]) > 0:
        return None
    turns = trial.first_rudder * starboard_sign(rudder_positive(log))
    initial, rps, wind = _replica_start(model, log, trial, start)
    return zigzag(model, math.degrees(trial.plateau_angle), switch,
                  first="starboard" if turns > 0 else "port", speed=initial["u"], method=method,
                  initial=initial, rps=rps, switches=uneven_reversals(trial), indices=indices,
                  **_replica_run(log, trial, wind, step))  # fmt: skip


__all__ = ["Validation", "free_run", "manoeuvre_from_approach", "replica_step",
           "steady_log_approach", "trial_replica", "trial_turning", "trial_zigzag", "validate",
           "validate_log", "zigzag_indices"]
