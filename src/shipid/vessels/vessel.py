"""A reference ship: dynamics plus the particulars a manoeuvre needs."""

from __future__ import annotations

from dataclasses import dataclass

from shipid.dynamics.steering import SteeringMachine


@dataclass(frozen=True)
class Vessel:
    """A truth simulator.

    Attributes
    ----------
    dynamics : object with ``derivatives(nu, delta, thrust)`` and ``uses_thrust`` (see simulate)
    length : Lpp [m], for indices in ship lengths
    approach_speed : straight-running surge speed [m/s] at which the ship is trimmed
    steering : the rudder servo of the ship
    rudder_positive : 'port' or 'starboard', where a positive rudder angle turns the ship
    scale : λ (1 at full scale)
    """

    name: str
    dynamics: object
    length: float
    approach_speed: float
    steering: SteeringMachine
    rudder_positive: str
    scale: float = 1.0
    source: str = ""

    def log_metadata(self) -> dict:
        return {"ship": self.name, "source": f"simulated: {self.source}",
                "rudder_positive": self.rudder_positive, "scale": self.scale}  # fmt: skip
