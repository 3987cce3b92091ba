"""Mariner class cargo ship, Abkowitz third-order model (Chislett & Strøm-Tejsen 1965).

reference-ships.md §1: prime system I with the instantaneous speed U; the surge state is the
perturbation Δu about U0 and the rigid-body terms are lumped into the coefficients (pitfall 1).
Positive δ gives N′ < 0, i.e. a turn to port.
"""

from __future__ import annotations

import math

import numpy as np

from shipid.dynamics.steering import SteeringMachine

from .vessel import Vessel

L = 160.93
U0 = 7.7175
E5 = 1e-5
M, IZ, XG = 798 * E5, 39.2 * E5, -0.023
X = dict(udot=-42, u=-184, uu=-110, uuu=-215, vv=-899, rr=18, dd=-95, udd=-190, rv=798, vd=93,
         uvd=93)  # fmt: skip
Y = dict(vdot=-748, rdot=-9.354, v=-1160, r=-499, vvv=-8078, vvr=15356, vu=-1160, ru=-499, d=278,
         ddd=-90, ud=556, uud=278, vdd=-4, vvd=1190, c0=-4, c0u=-8, c0uu=-4)  # fmt: skip
N = dict(vdot=4.646, rdot=-43.8, v=-264, r=-166, vvv=1636, vvr=-5483, vu=-264, ru=-166, d=-139,
         ddd=45, ud=-278, uud=-139, vdd=13, vvd=-489, c0=3, c0u=6, c0uu=3)  # fmt: skip
X, Y, N = ({k: v * E5 for k, v in d.items()} for d in (X, Y, N))

M11 = M - X["udot"]
M22 = M - Y["vdot"]
M23 = M * XG - Y["rdot"]
M32 = M * XG - N["vdot"]
M33 = IZ - N["rdot"]
DET = M22 * M33 - M23 * M32


class MarinerDynamics:
    """Body accelerations of the Mariner; the state's u is the total surge speed U0 + Δu."""

    uses_thrust = False

    def derivatives(self, nu: np.ndarray, delta: np.ndarray, thrust=None) -> np.ndarray:
        du, v, r = nu[:, 0] - U0, nu[:, 1], nu[:, 2]
        U = np.sqrt((U0 + du) ** 2 + v**2)
        up, vp, rp, d = du / U, v / U, r * L / U, delta
        Xp = (X["u"] * up + X["uu"] * up**2 + X["uuu"] * up**3 + X["vv"] * vp**2
              + X["rr"] * rp**2 + X["rv"] * rp * vp + X["dd"] * d**2 + X["udd"] * up * d**2
              + X["vd"] * vp * d + X["uvd"] * up * vp * d)  # fmt: skip

        def lateral(C: dict) -> np.ndarray:
            return (C["v"] * vp + C["r"] * rp + C["vvv"] * vp**3 + C["vvr"] * vp**2 * rp
                    + C["vu"] * vp * up + C["ru"] * rp * up + C["d"] * d + C["ddd"] * d**3
                    + C["ud"] * up * d + C["uud"] * up**2 * d + C["vdd"] * vp * d**2
                    + C["vvd"] * vp**2 * d + C["c0"] + C["c0u"] * up + C["c0uu"] * up**2)  # fmt: skip

        Yp, Np = lateral(Y), lateral(N)
        out = np.empty_like(nu)
        out[:, 0] = Xp * (U**2 / L) / M11
        out[:, 1] = (M33 * Yp - M23 * Np) * (U**2 / L) / DET
        out[:, 2] = (-M32 * Yp + M22 * Np) * (U**2 / L**2) / DET
        return out


def mariner() -> Vessel:
    return Vessel(
        name="mariner",
        dynamics=MarinerDynamics(),
        length=L,
        approach_speed=U0,
        # MSS servo: δ̇ = sat±5°/s(δc − δ), a 1 s lag with rate saturation; |δ| ≤ 40°.
        steering=SteeringMachine(math.radians(40.0), math.radians(5.0), time_constant=1.0),
        rudder_positive="port",
        scale=1.0,
        source="Mariner, Abkowitz model (Chislett & Strøm-Tejsen 1965)",
    )
