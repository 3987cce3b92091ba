"""The paper's 1/16.95 scale ship: its identified Blanke model, eq. (16), as a truth simulator.

The embedded default of shipid. The surge constant is the thrust term 0.0600 plus the external term
0.06 (0.12 in all, reference-ships.md §7.2); it sets the straight-running speed at √(0.12/0.0321).
"""

from __future__ import annotations

import math

from shipid.dynamics.model import ManoeuvringModel, get_structure
from shipid.dynamics.steering import SteeringMachine

from .vessel import Vessel

LENGTH = 4.389  # Lpp [m]
SCALE = 16.95
PAPER_SURGE_CONSTANT = 0.12
ABS_UU = -0.0321

# Paper eq. (16): continuous-time acceleration form; u, v in m/s, r in rad/s, δ in rad.
EQ16 = {
    "u": {"|u|u": ABS_UU, "vr": -2.7053, "r^2": 0.0, "delta^2": -0.2257},
    "v": {"ur": -0.4531, "uv": -0.5284, "|v|v": 0.5354, "|v|r": -0.4121, "delta": 0.0520,
          "1": 0.0007},
    "r": {"ur": -1.1699, "uv": -0.6696, "|v|v": 2.3001, "|v|r": 3.9335, "delta": -0.5503,
          "1": -0.0054},
}  # fmt: skip


def scale_ship_model(surge_constant: float = PAPER_SURGE_CONSTANT) -> ManoeuvringModel:
    """Eq. (16) with the given surge constant (0.12 in the paper; 0.1284 trims it at 2.0 m/s)."""
    coefs = {dof: dict(c) for dof, c in EQ16.items()}
    coefs["u"]["1"] = surge_constant
    return ManoeuvringModel(get_structure("blanke"), coefs, name="scale-ship (paper eq. 16)")


def scale_ship(
    surge_constant: float = PAPER_SURGE_CONSTANT,
    rudder_rate_deg: float | None = None,
) -> Vessel:
    """The scale ship as a vessel: model, particulars, straight-running speed and rudder servo.

    ``rudder_rate_deg`` None is an instantaneous rudder (the paper states no rate; the SOLAS rate
    Froude-scaled to 1/16.95 is ≈ 9.6 °/s).
    """
    model = scale_ship_model(surge_constant)
    return Vessel(
        name="scale-ship",
        dynamics=model,
        length=LENGTH,
        approach_speed=math.sqrt(surge_constant / -ABS_UU),
        steering=SteeringMachine(
            max_angle=math.radians(35.0),
            max_rate=None if rudder_rate_deg is None else math.radians(rudder_rate_deg),
        ),
        rudder_positive="port",
        scale=SCALE,
        source="Moreno-Salinas et al. (2013), eq. (16)",
    )
