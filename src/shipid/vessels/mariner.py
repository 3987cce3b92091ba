"""Mariner class cargo ship, Abkowitz third-order model (Chislett & Strøm-Tejsen 1965).

reference-ships.md §1: prime system I with the instantaneous speed U; the surge state is the
perturbation Δu about U0 and the rigid-body terms are lumped into the coefficients (pitfall 1).
Positive δ gives N′ < 0, i.e. a turn to port.
"""

from __future__ import annotations

import math

import numba
import numpy as np

import shipid.vessels.mariner as _this  # this module: see the entries below
from shipid.dynamics import kernel
from shipid.dynamics.steering import SteeringMachine

from .vessel import CompiledDynamics, Vessel

kernel.drop_stale_caches(__file__)

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


# Coefficient tuples in the order _lateral reads them (numba freezes global tuples as constants).
_LATERAL_KEYS = ("v", "r", "vvv", "vvr", "vu", "ru", "d", "ddd", "ud", "uud", "vdd", "vvd", "c0",
                 "c0u", "c0uu")  # fmt: skip
_YC = tuple(Y[k] for k in _LATERAL_KEYS)
_NC = tuple(N[k] for k in _LATERAL_KEYS)
_XC = tuple(X[k] for k in ("u", "uu", "uuu", "vv", "rr", "rv", "dd", "udd", "vd", "uvd"))


@numba.njit(cache=True, inline="always")
def _lateral(c, up, vp, rp, d):
    return (c[0] * vp + c[1] * rp + c[2] * vp**3 + c[3] * vp**2 * rp + c[4] * vp * up
            + c[5] * rp * up + c[6] * d + c[7] * d**3 + c[8] * up * d + c[9] * up**2 * d
            + c[10] * vp * d**2 + c[11] * vp**2 * d + c[12] + c[13] * up + c[14] * up**2)  # fmt: skip


@numba.njit(cache=True)
def accelerations(u, v, r, delta):
    """(u̇, v̇, ṙ) of the Abkowitz model at total surge speed u = U0 + Δu and rudder δ."""
    du = u - U0
    U = math.sqrt(u * u + v * v)
    up, vp, rp, d = du / U, v / U, r * L / U, delta
    x = _XC
    Xp = (x[0] * up + x[1] * up**2 + x[2] * up**3 + x[3] * vp**2 + x[4] * rp**2 + x[5] * rp * vp
          + x[6] * d**2 + x[7] * up * d**2 + x[8] * vp * d + x[9] * up * vp * d)  # fmt: skip
    Yp, Np = _lateral(_YC, up, vp, rp, d), _lateral(_NC, up, vp, rp, d)
    q = U * U / L
    return (Xp * q / M11, (M33 * Yp - M23 * Np) * q / DET, (-M32 * Yp + M22 * Np) * q / L / DET)


@numba.njit(cache=True)
def rhs(ctx, u, v, r, psi):
    """State derivative for the compiled integrators; ctx = (inputs,), δ = inputs[0]."""
    a0, a1, a2 = accelerations(u, v, r, ctx[0][0])
    psi_dot, xd, yd = kernel.kinematics(u, v, r, psi)
    return a0, a1, a2, psi_dot, xd, yd


class MarinerDynamics(CompiledDynamics):
    """Body accelerations of the Mariner; the state's u is the total surge speed U0 + Δu."""

    def derivatives(self, nu: np.ndarray, delta: np.ndarray, thrust=None) -> np.ndarray:
        """(B, 3) body accelerations of the Abkowitz model at states nu and rudder delta."""
        return _batch(kernel.c_array(nu), kernel.c_array(delta))

    def integrate_open(self, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
        """Free runs driven by (B, N, 5) inputs (``shipid.dynamics.kernel.open_run``)."""
        _open(t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid)

    def integrate_closed(self, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder,
                         n_valid):  # fmt: skip
        """Closed-loop manoeuvres of parameter rows ``params`` (``kernel.closed_run``)."""
        _closed(dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder, n_valid)

    def corrected_kernels(self):
        """(open runs, closed runs) plus a correction's terms, and the arguments that lead
        theirs: none."""
        return _this.open_corrected, _this.closed_corrected, ()


# Entries reach ``rhs`` as a module attribute: numba caches them only then.
@numba.njit(cache=True)
def _batch(nu, delta):
    out = np.empty_like(nu)
    for i in range(nu.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = accelerations(nu[i, 0], nu[i, 1], nu[i, 2], delta[i])
    return out


@numba.njit(cache=True)
def _open(t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
    for b in range(inputs.shape[0]):
        inp = np.zeros(kernel.N_INPUTS)
        n_valid[b] = kernel.open_run(_this.rhs, (inp,), inp, t, inputs[b], n_steps[b], s0[b], rk4,
                                     speed_lim[b], yaw_lim[b], out[b])  # fmt: skip


@numba.njit(cache=True)
def _closed(dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder, n_valid):
    for b in range(params.shape[0]):
        inp = np.zeros(kernel.N_INPUTS)
        n_valid[b] = kernel.closed_run(_this.rhs, (inp,), inp, params[b], dt, n_steps, s0[b], rk4,
                                       speed_lim[b], yaw_lim[b], states[b], rudder[b])  # fmt: skip


@numba.njit(cache=True)
def open_corrected(terms, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
    """Free runs of the Mariner plus a correction's terms (``kernel.open_corrected_runs``)."""
    kernel.open_corrected_runs(_this.rhs, (), terms, t, inputs, n_steps, s0, rk4, speed_lim,
                               yaw_lim, out, n_valid)  # fmt: skip


@numba.njit(cache=True)
def closed_corrected(terms, windy, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states,
                     rudder, n_valid):  # fmt: skip
    """Closed-loop manoeuvres of the Mariner plus a correction's terms."""
    kernel.closed_corrected_runs(_this.rhs, (), terms, windy, dt, n_steps, s0, params, rk4,
                                 speed_lim, yaw_lim, states, rudder, n_valid)  # fmt: skip


def mariner() -> Vessel:
    """The Mariner as a vessel (U0 = 7.7175 m/s, its 5 °/s servo with a 1 s lag)."""
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
