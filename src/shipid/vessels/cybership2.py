"""CyberShip II, a 1:70 model of a supply ship (Skjetne, Smogeli & Fossen 2004).

reference-ships.md §5: M ν̇ + C(ν) ν + D(ν) ν = τ with rigid-body and added-mass Coriolis terms,
modulus damping with the |r|·v and |r|·r terms the Blanke model lacks, two propellers with a
thrust dead zone and two rudders in their race. The propellers turn at one speed, trimmed for the
approach speed (closed form, ``trimmed_revolutions``); the bow thruster is idle, so the two
propellers' moments cancel and the rudders steer. Positive δ gives sway force > 0 and yaw
moment < 0: a turn to port. The marine-robotics test ship of the references, a "mild structural
mismatch" for the Blanke model (§9).
"""

from __future__ import annotations

import math

import numba
import numpy as np

import shipid.vessels.cybership2 as _this  # this module: see the entries below
from shipid.dynamics import kernel
from shipid.dynamics.steering import SteeringMachine

from .vessel import ConstantRpsDynamics, Vessel

kernel.drop_stale_caches(__file__)

L, SCALE = 1.255, 70.0
# The references give CyberShip II's speeds as about 0.1–0.5 m/s: the approach is taken mid-range.
APPROACH_SPEED = 0.3
# The rudder: ±35°, moving at the SOLAS rate (35° to −30° in 28 s) Froude-scaled to 1:70,
# 2.32 °/s × √70. The references' 5 °/s (one implementation's choice, §5.3) is 0.6 °/s at full
# scale, a quarter of what SOLAS asks of the ship this is a model of.
MAX_RUDDER_DEG = 35.0
RUDDER_RATE_DEG = 65.0 / 28.0 * math.sqrt(SCALE)

M, IZ, XG = 23.8, 1.76, 0.046
XUDOT, YVDOT, YRDOT, NVDOT, NRDOT = -2.0, -10.0, 0.0, 0.0, -1.0
XU, XAUU, XUUU = -0.72253, -1.32742, -5.86643
YV, YAVV, YARV, YR, YAVR, YARR = -0.88965, -36.47287, -0.805, -7.250, -0.845, -3.450
NV, NAVV, NARV, NR, NAVR, NARR = 0.03130, 3.95645, 0.130, -1.900, 0.080, -0.750
LY_T, LX_R = 0.078, 0.549  # |lyT1,2|, |lxR1,2| [m]; the bow thruster (lxT3) is idle
T_NN_AHEAD, T_NU_AHEAD, T_NN_ASTERN, T_NU_ASTERN = 3.65034e-3, 1.52468e-4, 5.10256e-3, 4.55822e-2
L_D_AHEAD, L_DD_AHEAD, L_D_ASTERN, L_DD_ASTERN = 6.43306, 5.83594, 3.19573, 2.34356
KU, DP, RHO = 0.5, 0.06, 1014.0

M11 = M - XUDOT
M22, M23 = M - YVDOT, M * XG - YRDOT
M32, M33 = M * XG - NVDOT, IZ - NRDOT
DET = M22 * M33 - M23 * M32


@numba.njit(cache=True)
def propeller_thrust(n, u):
    """Thrust of one main propeller [N] at n [rps] and surge u, zero in its dead zone."""
    if n >= max(0.0, T_NU_AHEAD * u / T_NN_AHEAD):
        return T_NN_AHEAD * abs(n) * n - T_NU_AHEAD * abs(n) * u
    if n <= min(0.0, T_NU_ASTERN * u / T_NN_ASTERN):
        return T_NN_ASTERN * abs(n) * n - T_NU_ASTERN * abs(n) * u
    return 0.0


@numba.njit(cache=True)
def rudder_lift(delta, u, thrust):
    """Lift of one rudder [N] in its propeller's race (inflow ``ku`` of the race's added speed)."""
    u_rud = u
    if u >= 0.0:
        u_rud = u + KU * (math.sqrt(max(0.0, 8.0 * thrust / (math.pi * RHO * DP**2) + u * u)) - u)
    if u_rud >= 0.0:
        c = L_D_AHEAD * delta - L_DD_AHEAD * abs(delta) * delta
    else:
        c = L_D_ASTERN * delta - L_DD_ASTERN * abs(delta) * delta
    return c * abs(u_rud) * u_rud


@numba.njit(cache=True)
def accelerations(u, v, r, delta, n):
    """(u̇, v̇, ṙ) of CyberShip II at rudder δ (both rudders) and propeller speed n (both)."""
    thrust = propeller_thrust(n, u)
    lift = rudder_lift(delta, u, thrust)
    # τ: the two propellers' moments cancel (equal thrust, ±lyT); the rudders sit aft (−lxR).
    tau_x, tau_y, tau_n = 2.0 * thrust, 2.0 * lift, -2.0 * LX_R * lift
    half = 0.5 * (NVDOT + YRDOT)
    # C(ν) ν, rigid body plus added mass (§5.2).
    c_x = -M * (XG * r + v) * r + (YVDOT * v + half * r) * r
    c_y = M * u * r - XUDOT * u * r
    c_n = M * XG * r * u + (-YVDOT * v - half * r) * u + XUDOT * u * v
    # D(ν) ν.
    d_x = -(XU + XAUU * abs(u) + XUUU * u * u) * u
    d_y = -(YV + YAVV * abs(v) + YARV * abs(r)) * v - (YR + YAVR * abs(v) + YARR * abs(r)) * r
    d_n = -(NV + NAVV * abs(v) + NARV * abs(r)) * v - (NR + NAVR * abs(v) + NARR * abs(r)) * r
    fx, fy, fn = tau_x - c_x - d_x, tau_y - c_y - d_y, tau_n - c_n - d_n
    return fx / M11, (M33 * fy - M23 * fn) / DET, (M22 * fn - M32 * fy) / DET


@numba.njit(cache=True)
def rhs(ctx, u, v, r, psi):
    """State derivative for the compiled integrators; ctx = (inputs, n): δ = inputs[0]."""
    a0, a1, a2 = accelerations(u, v, r, ctx[0][0], ctx[1])
    psi_dot, xd, yd = kernel.kinematics(u, v, r, psi)
    return a0, a1, a2, psi_dot, xd, yd


class CyberShip2Dynamics(ConstantRpsDynamics):
    """CyberShip II's accelerations, both propellers at ``n_prop`` [rps]."""

    def kernels(self):
        """This module's compiled entries."""
        return _batch, _open, _closed, _this.open_corrected, _this.closed_corrected


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


@numba.njit(cache=True)
def open_corrected(n, terms, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
    """Free runs of CyberShip II at propeller speed ``n`` plus a correction's terms
    (``kernel.open_corrected_runs``)."""
    kernel.open_corrected_runs(_this.rhs, (n,), terms, t, inputs, n_steps, s0, rk4, speed_lim,
                               yaw_lim, out, n_valid)  # fmt: skip


@numba.njit(cache=True)
def closed_corrected(n, terms, windy, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states,
                     rudder, n_valid):  # fmt: skip
    """Closed-loop manoeuvres of CyberShip II at propeller speed ``n`` plus a correction's terms."""
    kernel.closed_corrected_runs(_this.rhs, (n,), terms, windy, dt, n_steps, s0, params, rk4,
                                 speed_lim, yaw_lim, states, rudder, n_valid)  # fmt: skip


def trimmed_revolutions(speed: float = APPROACH_SPEED) -> float:
    """Propeller rps that hold ``speed`` [m/s] > 0 straight ahead: the root of
    2 (T⁺nn n² − T⁺|n|u n u) = d11(u) u (thrust against surge damping; ≈ 8.7 rps at 0.3 m/s)."""
    if not (math.isfinite(speed) and speed > 0):
        raise ValueError(f"CyberShip II's approach speed must be > 0 m/s, got {speed!r}")
    drag = -(XU + XAUU * speed + XUUU * speed**2) * speed
    a, b = 2.0 * T_NN_AHEAD, -2.0 * T_NU_AHEAD * speed
    return (-b + math.sqrt(b * b + 4.0 * a * drag)) / (2.0 * a)


def cybership2(speed: float = APPROACH_SPEED) -> Vessel:
    """CyberShip II as a vessel, its propellers trimmed for ``speed`` [m/s]."""
    return Vessel(
        name="cybership2",
        dynamics=CyberShip2Dynamics(trimmed_revolutions(speed)),
        length=L,
        approach_speed=speed,
        steering=SteeringMachine(math.radians(MAX_RUDDER_DEG), math.radians(RUDDER_RATE_DEG)),
        rudder_positive="port",
        scale=SCALE,
        source="CyberShip II, 1:70 supply ship (Skjetne, Smogeli & Fossen 2004)",
    )
