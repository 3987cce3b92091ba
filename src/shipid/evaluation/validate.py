"""Validation of a model against logs: free-run simulation from the measured initial state driven by
the measured rudder (paper section 4), error metrics per state and IMO indices measured vs simulated.

Zig-zag indices are predicted twice. "simulated" reads them off the open-loop replay (the measured
rudder, switched when the *ship* reached the switch heading), so a small heading drift of the model
shifts its second overshoot by the whole drift. "closed_loop" runs the zig-zag itself on the model,
from the trial's initial state with its rudder angle, rate and switch heading: the model's own
prediction of the manoeuvre, the one to compare overshoot angles with.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.data.log import rudder_positive, starboard_sign
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.simulate import SimulationResult, simulate_log
from shipid.dynamics.steering import SteeringMachine
from shipid.evaluation.metrics import error_metrics
from shipid.trials.indices import detect_manoeuvre, execute_index, manoeuvre_indices, zigzag_indices
from shipid.trials.manoeuvres import ManoeuvreResult, zigzag
from shipid.vessels.vessel import Vessel

STATES = ("u", "v", "r")


@dataclass
class Validation:
    name: str
    simulation: SimulationResult
    metrics: dict[str, dict[str, float]]
    indices: dict[str, dict] = field(default_factory=dict)
    kind: str | None = None

    def to_dict(self) -> dict:
        sim = self.simulation
        return {"name": self.name, "diverged": sim.diverged, "diverged_at": sim.diverged_at,
                "reason": sim.reason, "manoeuvre": self.kind, "metrics": self.metrics,
                "indices": self.indices}  # fmt: skip


def free_run(model, log: pd.DataFrame, method: str = "euler") -> tuple[SimulationResult, dict]:
    """The free run of ``model`` on ``log`` and its error metrics per state (over the part
    simulated before any divergence)."""
    sim = simulate_log(model, log, method=method)
    n = len(sim.log)
    return sim, {s: error_metrics(log[s].to_numpy()[:n], sim.log[s].to_numpy()) for s in STATES}


def validate(
    model,
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    names: Sequence[str] | None = None,
    method: str = "euler",
    kind: str | None = None,
    smooth_s: float = 0.0,
) -> list[Validation]:
    """Validate ``model`` on each log; errors are over the simulated (not diverged) part."""
    if isinstance(logs, pd.DataFrame):
        logs = [logs]
    names = names or [log.attrs.get("name", f"log {i}") for i, log in enumerate(logs)]
    out = []
    for log, name in zip(logs, names, strict=True):
        sim, metrics = free_run(model, log, method)
        k = kind or detect_manoeuvre(log)
        indices = {}
        if k is not None:
            simulated = manoeuvre_indices(sim.log, k) if not sim.diverged else {}
            indices = {"measured": manoeuvre_indices(log, k, smooth_s=smooth_s),
                       "simulated": simulated}
            if k == "zigzag" and isinstance(model, ManoeuvringModel | Vessel):
                replica = trial_zigzag(model, log, method)
                indices["closed_loop"] = (replica.indices if replica and not replica.diverged
                                          else {})  # fmt: skip
        out.append(Validation(name, sim, metrics, indices, k))
    return out


def trial_zigzag(model, log: pd.DataFrame, method: str = "euler") -> ManoeuvreResult | None:
    """The zig-zag of a measured log run closed loop on ``model``: same initial state (u, v, r, ψ)
    and held rudder, first execute time and side, rudder angle (the median plateau), rudder rate
    (the 90th percentile while it moves), switch heading (inferred from the log), mean propeller
    speed, duration and step.
    None when the log is not a zig-zag with a detectable switch heading."""
    measured = zigzag_indices(log)
    switch = measured.get("switch_heading_deg")
    if not switch:
        return None
    t = log["t"].to_numpy()
    delta = log["delta"].to_numpy()
    dt = float(np.median(np.diff(t)))
    # The sample after the last unmoved one is where the rudder order took effect.
    i0 = execute_index(log)
    held = float(delta[0])
    swing = np.abs(delta - held)
    plateau = swing > 0.8 * swing.max()
    amplitude = float(np.median(np.abs(delta[plateau])))
    rate = np.abs(np.diff(delta)) / dt
    moving = rate > math.radians(0.5)
    max_rate = float(np.percentile(rate[moving], 90)) if moving.any() else None
    first_swing = delta[int(np.argmax(plateau))] - held
    turns = first_swing * starboard_sign(rudder_positive(log))
    first = "starboard" if turns > 0 else "port"
    row = log.iloc[0]
    initial = {k: float(row[k]) for k in ("u", "v", "r", "psi") if k in log.columns}
    initial["delta"] = held
    steering = SteeringMachine(max_angle=max(math.radians(35.0), amplitude), max_rate=max_rate)
    rps = float(log["n"].mean()) if "n" in log.columns else None
    return zigzag(model, math.degrees(amplitude), switch, first=first, duration=float(t[-1] - t[0]),
                  dt=dt, approach=float(t[min(i0 + 1, len(t) - 1)] - t[0]), speed=initial["u"],
                  steering=steering,
                  method=method, initial=initial, rps=rps)  # fmt: skip
