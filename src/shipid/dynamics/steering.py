"""Steering machine: commanded rudder → actual rudder (angle limit, rate limit, first-order lag)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SteeringMachine:
    """Rudder servo.

    Parameters
    ----------
    max_angle : float
        Largest rudder angle [rad]; commands beyond it are refused by manoeuvres and clipped here.
    max_rate : float or None
        Largest rudder rate [rad/s]; None for an instantaneous rudder.
    time_constant : float
        First-order lag [s] (δ̇ = (δc − δ)/T, then rate-limited; the Mariner servo has T = 1 s).
        0 gives a pure rate limit.
    """

    max_angle: float = math.radians(35.0)
    max_rate: float | None = None
    time_constant: float = 0.0

    def __post_init__(self) -> None:
        if not (self.max_angle > 0):
            raise ValueError(f"max_angle must be > 0, got {self.max_angle!r}")
        if self.max_rate is not None and not (self.max_rate > 0):
            raise ValueError(f"max_rate must be > 0 or None, got {self.max_rate!r}")
        if not (self.time_constant >= 0):
            raise ValueError(f"time_constant must be ≥ 0, got {self.time_constant!r}")

    def capped_deg(self, standard_deg: float) -> float:
        """A standard manoeuvre's rudder ``standard_deg`` [deg], or this gear's largest where it
        stops short of it (MSC.137(76) §4.2: the tanker's 10° for its turning circle)."""
        return min(float(standard_deg), round(math.degrees(self.max_angle), 6))

    def step(self, delta: float, command: float, dt: float) -> float:
        """Rudder angle after dt seconds of following ``command`` from ``delta``."""
        command = min(max(command, -self.max_angle), self.max_angle)
        error = command - delta
        if self.time_constant > 0:
            # Exact first-order response over the step, then the rate limit.
            change = error * (1.0 - math.exp(-dt / self.time_constant))
        else:
            change = error
        if self.max_rate is not None:
            limit = self.max_rate * dt
            change = min(max(change, -limit), limit)
        return delta + change

    def apply(self, t: np.ndarray, command: np.ndarray, delta0: float = 0.0) -> np.ndarray:
        """Actual rudder series for a commanded series sampled at ``t``.

        Sample k is the angle held over [t_k, t_k+1): δ_k = step(δ_k−1, c_k, Δt), with δ_−1 = delta0,
        the same rule as the closed-loop manoeuvres, so a log replays exactly.
        """
        t = np.asarray(t, dtype=float)
        command = np.asarray(command, dtype=float)
        steps = np.diff(t)
        dts = np.concatenate([steps[:1] if steps.size else [0.0], steps])
        out = np.empty_like(command)
        delta = delta0
        for k in range(len(t)):
            delta = self.step(delta, command[k], dts[k])
            out[k] = delta
        return out
