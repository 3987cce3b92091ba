"""A reference ship: dynamics plus the particulars a manoeuvre needs."""

from __future__ import annotations

import math
from dataclasses import dataclass

from shipid.dynamics.steering import SteeringMachine


class CompiledDynamics:
    """Base of the reference ships' dynamics: NumPy ``derivatives`` for analysis and compiled
    ``integrate_open`` / ``integrate_closed`` (same arguments as ``shipid.dynamics.kernel``'s,
    without the term table) for the simulator and the manoeuvres. Rudder and trimmed propeller
    only: no thrust, propeller-speed or wind inputs."""

    uses_thrust = False
    uses_rps = False

    def derivatives(self, nu, delta, thrust=None):
        """(B, 3) body accelerations at states nu (B, 3) and rudder delta (B,)."""
        raise NotImplementedError

    def integrate_open(self, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
        """Free runs driven by (B, N, 5) inputs: out (B, N, 6), n_valid (B,)."""
        raise NotImplementedError

    def integrate_closed(self, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder,
                         n_valid):  # fmt: skip
        """Closed-loop manoeuvres of the rows of ``params``: states (B, N, 6), rudder (B, N)."""
        raise NotImplementedError


class ConstantRpsDynamics(CompiledDynamics):
    """Dynamics whose propeller turns at a constant ``n_prop`` [rps], trimmed for the approach
    (the KVLCC2, CyberShip II). A subclass gives its module's compiled entries in ``kernels``:
    numba caches an entry only where it reaches the ship's ``rhs`` as its own module's
    attribute, so each ship module keeps its three."""

    def __init__(self, n_prop: float) -> None:
        self.n_prop = n_prop

    def kernels(self):
        """(batch accelerations, open runs, closed runs, the open and the closed runs plus a
        correction's terms) of the ship's module."""
        raise NotImplementedError

    def corrected_kernels(self):
        """(open runs, closed runs) plus a correction's terms, and the arguments that lead
        theirs (``shipid.identification.correction.CorrectedCompiledDynamics``)."""
        return (*self.kernels()[3:], (float(self.n_prop),))

    def derivatives(self, nu, delta, thrust=None):
        """(B, 3) body accelerations at states nu and rudder delta, the propeller at n_prop."""
        from shipid.dynamics import kernel

        return self.kernels()[0](kernel.c_array(nu), kernel.c_array(delta), float(self.n_prop))

    def integrate_open(self, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
        """Free runs driven by (B, N, 5) inputs, the propeller at ``n_prop``."""
        self.kernels()[1](float(self.n_prop), t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim,
                          out, n_valid)  # fmt: skip

    def integrate_closed(self, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder,
                         n_valid):  # fmt: skip
        """Closed-loop manoeuvres of parameter rows ``params``, the propeller at ``n_prop``."""
        self.kernels()[2](float(self.n_prop), dt, n_steps, s0, params, rk4, speed_lim, yaw_lim,
                          states, rudder, n_valid)  # fmt: skip


@dataclass(frozen=True)
class Vessel:
    """A truth simulator.

    Attributes
    ----------
    dynamics : a ``CompiledDynamics`` (or a ``ManoeuvringModel``)
    length : Lpp [m], for indices in ship lengths
    approach_speed : straight-running surge speed [m/s] at which the ship is trimmed
    steering : the rudder servo of the ship
    rudder_positive : 'port' or 'starboard', where a positive rudder angle turns the ship
    scale : λ (1 at full scale); NaN where it is not known (a vessel built from an identified
        model, which carries no scale), and then its logs say none
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
        """Metadata of the logs this vessel's simulations produce."""
        out = {"ship": self.name, "source": f"simulated: {self.source}",
               "rudder_positive": self.rudder_positive}  # fmt: skip
        # An unknown scale is left out: a log that said 1 was read as full scale (validate then
        # told the user to re-read it with the model's own --scale).
        if math.isfinite(self.scale):
            out["scale"] = self.scale
        return out
