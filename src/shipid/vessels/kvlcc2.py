"""KVLCC2 tanker at model scale (L7, 1/45.7), MMG standard method (Yasukawa & Yoshimura 2015).

reference-ships.md §2 with x′P = −0.48, the wake formula of pitfall 1, midship sway velocity
throughout (pitfall 3) and dimensional lever arms (pitfall 4). Propeller revolutions are trimmed
numerically for the SIMMAN approach speed 1.179 m/s (≈ 11.85 rps). Positive δ turns to starboard.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numba
import numpy as np

import shipid.vessels.kvlcc2 as _this  # this module: see the entries below
from shipid.dynamics import kernel
from shipid.dynamics.steering import SteeringMachine

from .vessel import ConstantRpsDynamics, Vessel

kernel.drop_stale_caches(__file__)

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
(_MI00, _MI01), (_MI10, _MI11) = np.linalg.inv(_MSY).tolist()


@numba.njit(cache=True)
def accelerations(u, vm, r, delta, n):
    """(u̇, v̇m, ṙ) of the MMG model at midship sway vm, rudder δ and propeller speed n [rps]:
    hull, propeller and rudder forces (reference-ships.md §2) through the mass matrix."""
    U = math.sqrt(u * u + vm * vm)
    beta = math.atan2(-vm, u)
    vp, rp = vm / U, r * L / U
    q = 0.5 * RHO * L * D_DRAUGHT * U * U
    XH = q * (-R0 + XVV * vp**2 + XVR * vp * rp + XRR * rp**2 + XVVVV * vp**4)
    YH = q * (YV * vp + YR * rp + YVVV * vp**3 + YVVR * vp**2 * rp + YVRR * vp * rp**2
              + YRRR * rp**3)  # fmt: skip
    NH = q * L * (NV * vp + NR * rp + NVVV * vp**3 + NVVR * vp**2 * rp + NVRR * vp * rp**2
                  + NRRR * rp**3)  # fmt: skip
    beta_p = beta - XP_PRIME * rp
    c2 = 1.6 if beta_p > 0 else 1.1
    one_minus_wp = (1 - WP0) * (1 + (1 - math.exp(-C1 * abs(beta_p))) * (c2 - 1))
    Jp = u * one_minus_wp / (n * DP)
    KT = K0 + K1 * Jp + K2 * Jp**2
    XP = (1 - TP) * RHO * n**2 * DP**4 * KT
    beta_r = beta - LR_PRIME * rp
    gamma_r = 0.395 if beta_r < 0 else 0.640
    vR = U * gamma_r * beta_r
    uR = EPS * u * one_minus_wp * math.sqrt(
        ETA * (1 + KAPPA * (math.sqrt(1 + 8 * KT / (math.pi * Jp**2)) - 1)) ** 2 + (1 - ETA))
    alpha_r = delta - math.atan2(vR, uR)
    FN = 0.5 * RHO * AR * (uR**2 + vR**2) * F_ALPHA * math.sin(alpha_r)
    X = XH + XP - (1 - TR) * FN * math.sin(delta)
    Y = YH - (1 + AH) * FN * math.cos(delta)
    N = NH - (XR_PRIME * L + AH * XH_PRIME * L) * FN * math.cos(delta)
    # Sway–yaw: [[m + my, xG m], [xG m, IzG + xG² m + Jz]] (v̇, ṙ) = (Y − (m + mx) u r, N − xG m u r)
    ry = Y - (m + mx) * u * r
    rn = N - XG * m * u * r
    return ((X + (m + my) * vm * r + XG * m * r * r) / (m + mx),
            _MI00 * ry + _MI01 * rn, _MI10 * ry + _MI11 * rn)  # fmt: skip


@numba.njit(cache=True)
def rhs(ctx, u, v, r, psi):
    """State derivative for the compiled integrators; ctx = (inputs, n): δ = inputs[0]."""
    a0, a1, a2 = accelerations(u, v, r, ctx[0][0], ctx[1])
    psi_dot, xd, yd = kernel.kinematics(u, v, r, psi)
    return a0, a1, a2, psi_dot, xd, yd


class KVLCC2Dynamics(ConstantRpsDynamics):
    """MMG accelerations at constant propeller revolutions ``n_prop`` [rps]."""

    def kernels(self):
        """This module's compiled entries."""
        return _batch, _open, _closed


# Entries reach ``rhs`` as a module attribute: numba caches them only then.
@numba.njit(cache=True)
def _batch(nu, delta, n):
    out = np.empty_like(nu)
    for i in range(nu.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = accelerations(nu[i, 0], nu[i, 1], nu[i, 2], delta[i], n)
    return out


@numba.njit(cache=True)
def _open(n, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
    for b in range(inputs.shape[0]):
        inp = np.zeros(kernel.N_INPUTS)
        n_valid[b] = kernel.open_run(_this.rhs, (inp, n), inp, t, inputs[b], n_steps[b], s0[b],
                                     rk4, speed_lim[b], yaw_lim[b], out[b])  # fmt: skip


@numba.njit(cache=True)
def _closed(n, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder, n_valid):
    for b in range(params.shape[0]):
        inp = np.zeros(kernel.N_INPUTS)
        n_valid[b] = kernel.closed_run(_this.rhs, (inp, n), inp, params[b], dt, n_steps, s0[b],
                                       rk4, speed_lim[b], yaw_lim[b], states[b], rudder[b])


@lru_cache(maxsize=8)
def trimmed_revolutions(speed: float = APPROACH_SPEED) -> float:
    """Propeller rps for u̇ = 0 at ``speed`` in straight running (≈ 11.85 rps at 1.179 m/s)."""
    from scipy.optimize import brentq  # 0.4 s to import: only when a KVLCC2 is built

    state = np.array([[speed, 0.0, 0.0]])

    def surge_acc(n: float) -> float:
        return float(KVLCC2Dynamics(n).derivatives(state, np.zeros(1))[0, 0])

    return brentq(surge_acc, 1.0, 60.0, xtol=1e-12)


def kvlcc2(speed: float = APPROACH_SPEED) -> Vessel:
    """The KVLCC2 L7 model as a vessel, trimmed for ``speed`` [m/s]."""
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
