"""Predictions over a horizon: free runs restarted from the measured state every H seconds.

A free run over a whole log (the paper's validation, ``validate``) carries every early error to
its end. Over a random run of a quarter of an hour, astern spans included, it says little of how
well a model predicts the next half minute, which is what an autopilot or a model-predictive
controller asks of it. Here the log is cut into consecutive windows of H seconds; each is
simulated from the measured u, v, r at its start, driven by the measured rudder (and propeller,
wind), and its error kept over the window. Reported per state as the root-mean-square error over
all windows' samples, and over the state's spread in the log (1 ≈ predicting the log's mean).

Given the model's training envelope (``shipid.evaluation.envelope``), the windows are also split
by whether every signal stays within it: a model is only known where its trials went, and a
run that leaves them (a random run astern, from zig-zags ahead) mixes what it was trained for
with extrapolation. The two parts' errors say which of them the run's error is.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.data.log import column_values
from shipid.dynamics.simulate import model_inputs, simulate_batch
from shipid.errors import ShipidError
from shipid.evaluation.envelope import allowed_ranges
from shipid.vessels.vessel import Vessel

STATES = ("u", "v", "r")
# The caption of the columns the envelope adds (``validate --horizon``, its report).
ENVELOPE_COLUMNS_NOTE = ("the windows whose every signal stays within the training logs' "
                         "envelope, and the yaw rate's error over them and over the rest "
                         "(extrapolation)")  # fmt: skip


@dataclass
class HorizonErrors:
    """The errors of free runs over windows of ``horizon_s`` (see the module)."""

    horizon_s: float
    windows: int
    diverged: int
    rmse: dict[str, float] = field(default_factory=dict)
    over_spread: dict[str, float] = field(default_factory=dict)
    # Given the training envelope: how many windows stay within it, and the error over the
    # log's spread of those windows and of the rest (NaN where there are none).
    inside: int | None = None
    over_spread_inside: dict[str, float] = field(default_factory=dict)
    over_spread_outside: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The errors as JSON-ready data (``validate --json``, each log's ``horizons``)."""
        out = {"horizon_s": self.horizon_s, "windows": self.windows, "diverged": self.diverged,
               "rmse": dict(self.rmse), "over_spread": dict(self.over_spread)}  # fmt: skip
        if self.inside is not None:
            out.update(inside_envelope=self.inside,
                       over_spread_inside=dict(self.over_spread_inside),
                       over_spread_outside=dict(self.over_spread_outside))  # fmt: skip
        return out


def windows_inside(env: Mapping[str, Sequence[float]], log: pd.DataFrame, index: np.ndarray,
                   real: np.ndarray) -> np.ndarray:  # fmt: skip
    """(B,) whether each window (rows of ``index`` into ``log``, ``real`` its samples) keeps
    every signal of ``log`` the envelope ``env`` has within its allowed range (as
    ``outside_envelope`` judges a whole log)."""
    inside = np.ones(index.shape[0], dtype=bool)
    for s, (lo, hi, margin) in allowed_ranges(env).items():
        if s not in log.columns:
            continue
        x = column_values(log, s, float)[index]
        inside &= ~np.any(((x < lo - margin) | (x > hi + margin)) & real, axis=1)
    return inside


def horizon_errors(model, log: pd.DataFrame, horizon_s: float, method: str = "euler",
                   name: str | None = None, envelope=None) -> HorizonErrors:  # fmt: skip
    """Free runs of ``model`` over consecutive windows of ``horizon_s`` seconds of ``log``, each
    from the log's measured state at its start (``HorizonErrors``). A window whose run diverges
    counts in ``diverged`` and its samples from there on as missing. With ``envelope`` (the
    model's training envelope, {signal: [min, max]}), the windows within it and the rest are
    also reported apart."""
    name = name or log.attrs.get("name", "log")
    if isinstance(model, Vessel):  # a reference ship runs its dynamics
        model = model.dynamics
    if not (isinstance(horizon_s, int | float) and math.isfinite(horizon_s) and horizon_s > 0):
        raise ShipidError(f"--horizon must be seconds > 0, got {horizon_s!r}")
    t = column_values(log, "t", float)
    if len(t) < 3:
        raise ShipidError(f"{name}: too short for predictions over a horizon")
    dt = float(np.median(np.diff(t)))
    steps = max(1, int(round(horizon_s / dt)))
    if steps >= len(t) - 1:
        raise ShipidError(f"{name}: a horizon of {horizon_s:g} s spans the whole log "
                          f"({t[-1] - t[0]:.4g} s): its error is the free run's")  # fmt: skip
    starts = np.arange(0, len(t) - 1, steps)
    index = np.minimum(starts[:, None] + np.arange(steps + 1)[None, :], len(t) - 1)  # (B, L)
    real = (starts[:, None] + np.arange(steps + 1)[None, :]) <= len(t) - 1
    initial = np.zeros((len(starts), 6))
    for j, s in enumerate(("u", "v", "r", "psi", "x", "y")):
        if s in log.columns:
            initial[:, j] = column_values(log, s, float)[starts]
    series = {k: np.asarray(v, dtype=float)[index] for k, v in model_inputs(model, log, name).items()}
    thrust, rps = series.pop("thrust", None), series.pop("n", None)
    batch = simulate_batch(model, np.arange(steps + 1) * dt, column_values(log, "delta", float)[index],
                           initial, thrust, method, rps=rps, inputs=series or None,
                           n_trajectories=len(starts))  # fmt: skip
    alive = np.arange(steps + 1)[None, :] < batch.n_valid[:, None]
    keep = real & alive
    keep[:, 0] = False  # the measured start itself
    out = HorizonErrors(steps * dt, len(starts), int(batch.diverged.sum()))
    inside = windows_inside(envelope, log, index, real) if envelope else None
    if inside is not None:
        out.inside = int(inside.sum())
    for j, s in enumerate(STATES):
        measured = column_values(log, s, float)
        spread = float(np.std(measured))
        error = batch.states[:, :, j] - measured[index]
        out.rmse[s] = _rms(error[keep])
        out.over_spread[s] = out.rmse[s] / spread if spread > 0 else math.nan
        if inside is not None:
            for part, windows in ((out.over_spread_inside, inside),
                                  (out.over_spread_outside, ~inside)):  # fmt: skip
                part[s] = _rms(error[keep & windows[:, None]]) / spread if spread > 0 else math.nan
    return out


def _rms(err: np.ndarray) -> float:
    return float(np.sqrt(np.mean(err**2))) if err.size else math.nan
