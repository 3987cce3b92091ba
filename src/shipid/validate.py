"""Validation of a model against logs: free-run simulation from the measured initial state driven by
the measured rudder (paper section 4), error metrics per state and IMO indices measured vs simulated."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import pandas as pd

from .indices import detect_manoeuvre, manoeuvre_indices
from .metrics import error_metrics
from .simulate import SimulationResult, simulate_log

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
        sim = simulate_log(model, log, method=method)
        n = len(sim.log)
        metrics = {s: error_metrics(log[s].to_numpy()[:n], sim.log[s].to_numpy()) for s in STATES}
        k = kind or detect_manoeuvre(log)
        indices = {}
        if k is not None:
            simulated = manoeuvre_indices(sim.log, k) if not sim.diverged else {}
            indices = {"measured": manoeuvre_indices(log, k, smooth_s=smooth_s),
                       "simulated": simulated}
        out.append(Validation(name, sim, metrics, indices, k))
    return out
