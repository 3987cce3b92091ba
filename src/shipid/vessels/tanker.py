"""Esso 190 000 dwt tanker, Norrbin-type second-order modulus model (van Berlekom & Goddard 1972).

reference-ships.md §4 in deep water (z = 0: the shallow-water terms vanish). A single-screw
ship whose rudder sits in the propeller's race: the rudder force goes with |c|c, c² = cun·u·n +
cnn·n², so it keeps much of its force as the ship slows at constant rps; the propeller's side
force and moment (YT, NT) make port and starboard manoeuvres differ, and the ship is
course-unstable. A truth of another structure than any of shipid's term libraries, close in
kind to the Esso Osaka model of ``../shared/data`` (a different, larger VLCC). Positive δ turns
the ship to port (Nccδ < 0). The propeller turns at a constant rate; the approach speed is the
straight-running equilibrium at that rate, in closed form (8.23 m/s at the nominal 80 rpm, the
design speed).
"""

from __future__ import annotations

import math

import numba
import numpy as np

import shipid.vessels.tanker as _this  # this module: see the entries below
from shipid.dynamics import kernel
from shipid.dynamics.steering import SteeringMachine

from .vessel import ConstantRpsDynamics, Vessel

kernel.drop_stale_caches(__file__)

L = 304.8
NOMINAL_RPM = 80.0
RUDDER_LIMIT_DEG, RUDDER_RATE_DEG = 10.0, 2.33
THRUST_DEDUCTION = 0.22
CUN, CNN = 0.605, 38.2
TUU, TUN, TNN = -0.00695, -0.00063, 0.0000354
M11, M22, M33 = 1.050, 2.020, 0.1232
D11, D22, D33 = 2.020, -0.752, -0.231
XUU, XVV, XCCDD, XCCBD = -0.0377, 0.3, -0.093, 0.152
YUV, YVV, YCCD, YCCBBD, YT = -1.205, -2.400, 0.208, -2.16, 0.04
NUV, NVR, NCCD, NCCBBD, NT = -0.451, -0.300, -0.098, 0.688, -0.02


@numba.njit(cache=True)
def accelerations(u, v, r, delta, n):
    """(u̇, v̇, ṙ) of the tanker in deep water at rudder δ [rad] and propeller speed n [rps]
    (reference-ships.md §4.3 with z = 0): β = atan(v/u), the race speed c and the propeller's
    thrust and side force through gT."""
    beta = math.atan2(v, u)
    g_t = TUU * u * u / L + TUN * u * n + L * TNN * abs(n) * n
    c2 = max(CUN * u * n + CNN * n * n, 0.0)  # |c|c = c² where the race runs aft
    race_bb = c2 * abs(beta) * beta * abs(delta)
    x = (XUU * u * u + L * D11 * v * r + XVV * v * v + XCCDD * c2 * delta * delta
         + XCCBD * c2 * beta * delta + L * g_t * (1.0 - THRUST_DEDUCTION))  # fmt: skip
    y = (YUV * u * v + YVV * abs(v) * v + YCCD * c2 * delta + L * D22 * u * r
         + YCCBBD * race_bb + YT * g_t * L)  # fmt: skip
    nz = (NUV * u * v + L * NVR * abs(v) * r + NCCD * c2 * delta + L * D33 * u * r
          + NCCBBD * race_bb + L * NT * g_t)  # fmt: skip
    return x / (L * M11), y / (L * M22), nz / (L * L * M33)


@numba.njit(cache=True)
def rhs(ctx, u, v, r, psi):
    """State derivative for the compiled integrators; ctx = (inputs, n): δ = inputs[0]."""
    a0, a1, a2 = accelerations(u, v, r, ctx[0][0], ctx[1])
    psi_dot, xd, yd = kernel.kinematics(u, v, r, psi)
    return a0, a1, a2, psi_dot, xd, yd


class TankerDynamics(ConstantRpsDynamics):
    """The tanker's accelerations at a constant propeller speed ``n_prop`` [rps]."""

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
    """Free runs of the tanker at propeller speed ``n`` plus a correction's terms
    (``kernel.open_corrected_runs``)."""
    kernel.open_corrected_runs(_this.rhs, (n,), terms, t, inputs, n_steps, s0, rk4, speed_lim,
                               yaw_lim, out, n_valid)  # fmt: skip


@numba.njit(cache=True)
def closed_corrected(n, terms, windy, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states,
                     rudder, n_valid):  # fmt: skip
    """Closed-loop manoeuvres of the tanker at propeller speed ``n`` plus a correction's terms."""
    kernel.closed_corrected_runs(_this.rhs, (n,), terms, windy, dt, n_steps, s0, params, rk4,
                                 speed_lim, yaw_lim, states, rudder, n_valid)  # fmt: skip


def equilibrium_speed(rpm: float) -> float:
    """Straight-running surge speed [m/s] at which thrust balances resistance at ``rpm``: the
    positive root of (Xuu + Tuu (1 − t)) u² + L Tun n (1 − t) u + L² Tnn n² (1 − t) = 0
    (u̇ = 0 with v = r = δ = 0; n = rpm / 60)."""
    if not (math.isfinite(rpm) and 0 < rpm <= NOMINAL_RPM):
        raise ValueError(f"rpm must be in (0, {NOMINAL_RPM:g}] (the shaft's limit), got {rpm!r}")
    n, keep = rpm / 60.0, 1.0 - THRUST_DEDUCTION
    a, b, c = XUU + TUU * keep, L * TUN * n * keep, L * L * TNN * n * n * keep
    return (-b - math.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)


def tanker(rpm: float = NOMINAL_RPM, rudder_limit_deg: float = RUDDER_LIMIT_DEG) -> Vessel:
    """The tanker as a vessel at ``rpm`` (the nominal 80 rpm by default), approaching at its
    equilibrium speed, with the MSS servo: δ̇ = sat±2.33°/s(δc − δ), a 1 s lag with rate
    saturation, |δ| ≤ ``rudder_limit_deg`` (10° as published; larger to run the standard
    35° turns on the same formulas, which have no stall)."""
    if not (math.isfinite(rudder_limit_deg) and 0 < rudder_limit_deg <= 45):
        raise ValueError(f"rudder_limit_deg must be in (0, 45], got {rudder_limit_deg!r}")
    return Vessel(
        name="tanker",
        dynamics=TankerDynamics(rpm / 60.0),
        length=L,
        approach_speed=equilibrium_speed(rpm),
        steering=SteeringMachine(math.radians(rudder_limit_deg), math.radians(RUDDER_RATE_DEG),
                                 time_constant=1.0),  # fmt: skip
        rudder_positive="port",
        scale=1.0,
        source="Esso 190 000 dwt tanker, Norrbin-type model (van Berlekom & Goddard 1972)",
    )
