"""Compiled runs of a hybrid model (``shipid.dynamics.hybrid``): the term model's state derivative
(``kernel.terms_rhs``) plus its faded RBF residual, through the kernel's own integrators
(``open_run``, ``closed_run``), so a hybrid steps, steers and meets the wind as its physical
model does. ``HybridModel.derivatives`` (NumPy) is the same function; the tests hold them to
each other.

Not ``parallel``: a hybrid runs one trajectory at a time (validate, simulate, manoeuvres), and
numba compiles a serial loop in a fraction of the time.
"""

from __future__ import annotations

import math

import numba
import numpy as np

# numba caches a function that hands ``hybrid_rhs`` on only when it reaches it as a module
# attribute, not as a bare global.
import shipid.dynamics.hybrid_kernel as _self  # noqa: E402  (this module)
from shipid.dynamics import kernel

kernel.drop_stale_caches(__file__)


@numba.njit(cache=True, inline="always")
def hybrid_rhs(ctx, u, v, r, psi):
    """State derivative of a hybrid; ctx = (the term model's context, the residual's mean,
    scale, standardised centres (M, d), weights (M, 3), intercept (3,), 1/σ², 1/reach, feature
    indices into (u, v, r, δ, n), buffers of 5 for the raw and the standardised features)."""
    tctx, mean, scale, centres, weights, intercept, inv_s2, inv_reach, fidx, x, z = ctx
    # A hybrid's own cost dwarfs the choice (its centres' kernel sums): made per evaluation.
    a0, a1, a2, rd, xd, yd = kernel.terms_rhs_any(tctx, u, v, r, psi)
    inp = tctx[8]
    x[0], x[1], x[2], x[3], x[4] = u, v, r, inp[0], inp[1]
    d = fidx.size
    for j in range(d):  # standardised once per evaluation, not per centre
        z[j] = (x[fidx[j]] - mean[j]) / scale[j]
    k_max, s0, s1, s2 = 0.0, 0.0, 0.0, 0.0
    for i in range(centres.shape[0]):
        d2 = 0.0
        for j in range(d):
            e = z[j] - centres[i, j]
            d2 += e * e
        k = math.exp(-d2 * inv_s2)
        k_max = max(k_max, k)
        s0 += k * weights[i, 0]
        s1 += k * weights[i, 1]
        s2 += k * weights[i, 2]
    w = min(1.0, k_max * inv_reach)
    return (a0 + w * (s0 + intercept[0]), a1 + w * (s1 + intercept[1]),
            a2 + w * (s2 + intercept[2]), rd, xd, yd)  # fmt: skip


@numba.njit(cache=True)
def _ctx(th, rows, sig, op, kk, pw, rud, derived, wind_true, vw, dw, mean, scale, centres,
         weights, intercept, inv_s2, inv_reach, fidx):  # fmt: skip
    return (kernel._terms_ctx(th, rows, sig, op, kk, pw, rud, derived, wind_true, vw, dw), mean,
            scale, centres, weights, intercept, inv_s2, inv_reach, fidx, np.zeros(5),
            np.zeros(5))  # fmt: skip


@numba.njit(cache=True)
def integrate_open(theta, rows, sig, op, kk, pw, rud, derived, mean, scale, centres, weights,
                   intercept, inv_s2, inv_reach, fidx, t, inputs, n_steps, s0, rk4, speed_lim,
                   yaw_lim, out, n_valid):  # fmt: skip
    """Free runs driven by input series, as ``kernel.integrate_open``."""
    for b in range(theta.shape[0]):
        ctx = _ctx(theta[b], rows, sig, op, kk, pw, rud, derived, False, 0.0, 0.0, mean, scale,
                   centres, weights, intercept, inv_s2, inv_reach, fidx)  # fmt: skip
        n_valid[b] = kernel.open_run(_self.hybrid_rhs, ctx, ctx[0][8], t, inputs[b], n_steps[b],
                                     s0[b], rk4, speed_lim[b], yaw_lim[b], out[b])  # fmt: skip


@numba.njit(cache=True)
def integrate_closed(theta, rows, sig, op, kk, pw, rud, derived, mean, scale, centres, weights,
                     intercept, inv_s2, inv_reach, fidx, dt, n_steps, s0, params, rk4, speed_lim,
                     yaw_lim, states, rudder, n_valid):  # fmt: skip
    """Closed-loop manoeuvres, as ``kernel.integrate_closed`` (still air is the apparent wind
    of the ship's own motion)."""
    for b in range(theta.shape[0]):
        p = params[b]
        ctx = _ctx(theta[b], rows, sig, op, kk, pw, rud, derived, True, p[kernel.P_WIND_SPEED],
                   p[kernel.P_WIND_DIR], mean, scale, centres, weights, intercept, inv_s2,
                   inv_reach, fidx)  # fmt: skip
        n_valid[b] = kernel.closed_run(_self.hybrid_rhs, ctx, ctx[0][8], p, dt, n_steps, s0[b],
                                       rk4, speed_lim[b], yaw_lim[b], states[b], rudder[b])  # fmt: skip
