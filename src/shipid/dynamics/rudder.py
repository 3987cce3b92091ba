"""The rudder's inflow for its normal force (``rudder_normal`` of the term algebra), from a ship's
particulars.

The MMG standard method (Yasukawa & Yoshimura 2015) gives the rudder one inflow, in the propeller's
race and the hull's straightened flow, and from it one normal force F_N ∝ U_R² sin α_R that
drives all three equations: −(1 − t_R) F_N sin δ in surge, −(1 + a_H) F_N cos δ in sway,
−(x_R + a_H x_H) F_N cos δ in yaw. The fit keeps the three factors in front free; the inflow
is fixed from the particulars (``RudderInflow.from_particulars``):

* a = (1 − w)², w = 0.5 C_b − 0.05 (Taylor's wake fraction of a single-screw ship; the rudder's
  own wake is close to the propeller's, ε = (1 − w_R)/(1 − w_P) ≈ 1);
* c = η κ² (8 K_T0/π) D²: the race of the momentum theory at the propeller's bollard point
  (u_R² → η κ² 8 K_T n² D²/π as u → 0), κ = 0.5 (MMG), K_T0 = 0.3 (a merchant ship's propeller
  at J = 0), η = D/H_R the share of the rudder's height in the race (0.7 where the particulars do
  not give the rudder's height);
* g = 0.5, the hull's flow straightening γ_R (MMG's KVLCC2: 0.395 and 0.640 with the drift's
  sign), signed as positive rudder turns the ship (− where it turns it to port);
* x = −L, the rudder's effective position ℓ_R (MMG's published values −0.7 L to −1 L).

Why fixed: on one zig-zag the race terms' three coefficients (u²δ, uδ, δ) come out of opposite
signs and cancel at a turn's low speed; one inflow shared by the three equations keeps the rudder
force of a turn. How much the defaults matter: on the real KVLCC2 zig-zag, halving or doubling c,
g or x moved the 35° turn's tactical diameter by −13 to +4 % and its steady yaw rate by ±5 %
(``benchmarks/study_kvlcc2_turn.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shipid.dynamics.terms import inflow_problem
from shipid.errors import ShipidError

KAPPA = 0.5
KT0 = 0.3
ETA_DEFAULT = 0.7
STRAIGHTENING = 0.5
POSITION = -1.0  # ℓ_R / L


@dataclass(frozen=True)
class RudderInflow:
    """u_R² = a u² + c n⁺², v_R = −g (v + x r) (see ``shipid.dynamics.terms.rudder_normal``)."""

    a: float
    c: float  # [m²]
    g: float
    x: float  # [m]

    def __post_init__(self) -> None:
        problem = inflow_problem(self.a, self.c, self.g, self.x)
        if problem:
            raise ShipidError(f"rudder inflow: {problem}")

    @property
    def factor(self) -> str:
        """The factor's text, ``rudder_normal(a c g x)``."""
        return f"rudder_normal({self.a:.6g} {self.c:.6g} {self.g:.6g} {self.x:.6g})"

    @property
    def surge(self) -> str:
        """The surge term: the rudder's drag, F_N sin δ."""
        return f"{self.factor}*sin(delta)"

    @property
    def lateral(self) -> str:
        """The sway and yaw term: the rudder's side force, F_N cos δ."""
        return f"{self.factor}*cos(delta)"

    @classmethod
    def from_particulars(cls, particulars, rudder_positive: str) -> RudderInflow:
        """The inflow of a ship with these particulars (``shipid.data.particulars``: length,
        propeller_diameter and block_coefficient needed, rudder_height used where given) whose
        positive rudder turns it to ``rudder_positive`` ('port' or 'starboard')."""
        if rudder_positive not in ("port", "starboard"):
            raise ShipidError(f"the rudder's inflow needs the logs' rudder convention ('port' or "
                              f"'starboard'), got {rudder_positive!r}")  # fmt: skip
        a, race = inflow_speed(particulars)
        sign = 1.0 if rudder_positive == "starboard" else -1.0
        return cls(a, race, sign * STRAIGHTENING, POSITION * particulars.length)


def inflow_speed(particulars) -> tuple[float, float]:
    """(a, c [m²]) of the rudder's inflow speed u_R² = a u² + c n⁺² from the particulars (the
    module's note; length, propeller_diameter and block_coefficient needed, rudder_height used
    where given). Its side needs no convention: what the rudder's drag takes from it."""
    missing = [k for k in ("propeller_diameter", "block_coefficient")
               if getattr(particulars, k) is None]  # fmt: skip
    if missing:
        raise ShipidError(f"the rudder's inflow needs the particulars' {' and '.join(missing)}"
                          " (--particulars FILE)")  # fmt: skip
    diameter = particulars.propeller_diameter
    wake = 0.5 * particulars.block_coefficient - 0.05
    height = particulars.rudder_height
    eta = ETA_DEFAULT if height is None else min(1.0, diameter / height)
    return (1.0 - wake) ** 2, eta * KAPPA**2 * 8.0 * KT0 / math.pi * diameter**2
