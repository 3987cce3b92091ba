"""KVLCC2 tanker at model scale (L7, 1/45.7), MMG standard method (Yasukawa & Yoshimura 2015).

reference-ships.md §2 with x′P = −0.48, the wake formula of pitfall 1, midship sway velocity
throughout (pitfall 3) and dimensional lever arms (pitfall 4). Propeller revolutions are trimmed
numerically for the SIMMAN approach speed 1.179 m/s (≈ 11.85 rps). Positive δ turns to starboard.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq

from shipid.dynamics.steering import SteeringMachine

from .vessel import Vessel

RHO = 1025.0
L, B, D_DRAUGHT, VOLUME, XG = 7.00, 1.27, 0.46, 3.27, 0.25
DP, HR, AR = 0.216, 0.345, 0.0539
APPROACH_SPEED = 1.179
RUDDER_RATE_DEG = 15.8
SCALE = 45.7

MX, MY, JZ = 0.022, 0.223, 0.011
R0 = 0.022
XVV, XVR, XRR, XVVVV = -0.040, 0.002, 0.011, 0.771
YV, YR, YVVV, YVVR, YVRR, YRRR = -0.315, 0.083, -1.607, 0.379, -0.391, 0.008
NV, NR, NVVV, NVVR, NVRR, NRRR = -0.137, -0.049, -0.030, -0.294, 0.055, -0.013
TP, WP0, K0, K1, K2, XP_PRIME, C1 = 0.220, 0.40, 0.2931, -0.2753, -0.1385, -0.48, 2.0
TR, AH, XH_PRIME, XR_PRIME, LR_PRIME, EPS, KAPPA, F_ALPHA = (
    0.387, 0.312, -0.464, -0.5, -0.710, 1.09, 0.50, 2.747)  # fmt: skip
ETA = DP / HR

m = RHO * VOLUME
mx = MX * 0.5 * RHO * L**2 * D_DRAUGHT
my = MY * 0.5 * RHO * L**2 * D_DRAUGHT
Jz = JZ * 0.5 * RHO * L**4 * D_DRAUGHT
IzG = m * (0.25 * L) ** 2
# Mass matrix of the sway–yaw equations: [[m + my, xG m], [xG m, IzG + xG² m + Jz]].
_MSY = np.array([[m + my, XG * m], [XG * m, IzG + XG**2 * m + Jz]])
_MSY_INV = np.linalg.inv(_MSY)


class KVLCC2Dynamics:
    """MMG accelerations at constant propeller revolutions ``n_prop`` [rps]."""

    uses_thrust = False

    def __init__(self, n_prop: float) -> None:
        self.n_prop = n_prop

    def forces(self, u, vm, r, delta):
        U = np.sqrt(u**2 + vm**2)
        beta = np.arctan2(-vm, u)
        vp, rp = vm / U, r * L / U
        q = 0.5 * RHO * L * D_DRAUGHT * U**2
        XH = q * (-R0 + XVV * vp**2 + XVR * vp * rp + XRR * rp**2 + XVVVV * vp**4)
        YH = q * (YV * vp + YR * rp + YVVV * vp**3 + YVVR * vp**2 * rp + YVRR * vp * rp**2
                  + YRRR * rp**3)  # fmt: skip
        NH = q * L * (NV * vp + NR * rp + NVVV * vp**3 + NVVR * vp**2 * rp + NVRR * vp * rp**2
                      + NRRR * rp**3)  # fmt: skip
        n = self.n_prop
        beta_p = beta - XP_PRIME * rp
        c2 = np.where(beta_p > 0, 1.6, 1.1)
        one_minus_wp = (1 - WP0) * (1 + (1 - np.exp(-C1 * np.abs(beta_p))) * (c2 - 1))
        Jp = u * one_minus_wp / (n * DP)
        KT = K0 + K1 * Jp + K2 * Jp**2
        XP = (1 - TP) * RHO * n**2 * DP**4 * KT
        beta_r = beta - LR_PRIME * rp
        gamma_r = np.where(beta_r < 0, 0.395, 0.640)
        vR = U * gamma_r * beta_r
        uR = EPS * u * one_minus_wp * np.sqrt(
            ETA * (1 + KAPPA * (np.sqrt(1 + 8 * KT / (np.pi * Jp**2)) - 1)) ** 2 + (1 - ETA))
        alpha_r = delta - np.arctan2(vR, uR)
        FN = 0.5 * RHO * AR * (uR**2 + vR**2) * F_ALPHA * np.sin(alpha_r)
        X_rudder = -(1 - TR) * FN * np.sin(delta)
        Y_rudder = -(1 + AH) * FN * np.cos(delta)
        N_rudder = -(XR_PRIME * L + AH * XH_PRIME * L) * FN * np.cos(delta)
        return XH + X_rudder + XP, YH + Y_rudder, NH + N_rudder

    def derivatives(self, nu: np.ndarray, delta: np.ndarray, thrust=None) -> np.ndarray:
        u, vm, r = nu[:, 0], nu[:, 1], nu[:, 2]
        X, Y, N = self.forces(u, vm, r, delta)
        out = np.empty_like(nu)
        out[:, 0] = (X + (m + my) * vm * r + XG * m * r**2) / (m + mx)
        rhs = np.vstack([Y - (m + mx) * u * r, N - XG * m * u * r])
        acc = _MSY_INV @ rhs
        out[:, 1], out[:, 2] = acc[0], acc[1]
        return out


@lru_cache(maxsize=8)
def trimmed_revolutions(speed: float = APPROACH_SPEED) -> float:
    """Propeller rps for u̇ = 0 at ``speed`` in straight running (≈ 11.85 rps at 1.179 m/s)."""
    state = np.array([[speed, 0.0, 0.0]])

    def surge_acc(n: float) -> float:
        return float(KVLCC2Dynamics(n).derivatives(state, np.zeros(1))[0, 0])

    return brentq(surge_acc, 1.0, 60.0, xtol=1e-12)


def kvlcc2(speed: float = APPROACH_SPEED) -> Vessel:
    return Vessel(
        name="kvlcc2",
        dynamics=KVLCC2Dynamics(trimmed_revolutions(speed)),
        length=L,
        approach_speed=speed,
        # Model scale: the rudder moves at the constant rate until the ordered angle (pure rate).
        steering=SteeringMachine(math.radians(35.0), math.radians(RUDDER_RATE_DEG)),
        rudder_positive="starboard",
        scale=SCALE,
        source="KVLCC2 L7, MMG standard method (Yasukawa & Yoshimura 2015)",
    )
