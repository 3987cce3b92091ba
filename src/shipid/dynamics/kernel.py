"""Compiled (numba) kernels: a models' accelerations for any term set, open-loop integration driven
by input series, and closed-loop manoeuvres (zig-zag, held rudder, pull-out) with the steering
machine, all batched over trajectories that may each have their own coefficients.

A term set is the factor table of ``shipid.dynamics.terms.TermCode``; coefficients are θ (B, 3, T)
(rows u̇, v̇, ṙ; a held DOF has a zero row). Inputs are (B, N, 5) in ``INPUT_SIGNALS`` order
(delta, n, thrust, wind_speed, wind_angle), held over each step (zero-order hold).

State: [u, v, r, ψ, x, y] with ψ̇ = r, ẋ = u cosψ − v sinψ, ẏ = u sinψ + v cosψ.

Closed loop: each step the rudder command of the manoeuvre (``_command``) goes through the steering
machine (``steer``), the state is recorded, then integrated over the step; the same order as a log
replays with ``simulate_log``. Wind in a closed loop is a constant true wind (speed, direction it
blows from, clockwise from north), turned into the relative wind from the ship's heading and
velocity at every evaluation.
"""

from __future__ import annotations

import math

import numba
import numpy as np

N_INPUTS = 5
N_SIGNALS = 10
# Closed-loop parameters, one row per trajectory.
P_MODE, P_VALUE, P_SWITCH, P_SIDE, P_STBD, P_APPROACH, P_RELEASE, P_HELD, P_PSI_REF = range(9)
P_MAX_ANGLE, P_MAX_RATE, P_TIME_CONST, P_RPS, P_THRUST, P_WIND_SPEED, P_WIND_DIR = range(9, 16)
N_PARAMS = 16
MODE_HOLD, MODE_ZIGZAG = 0, 1


@numba.njit(cache=True, inline="always")
def _factor(x, op, k, p):
    if op == 0:
        b = x
    elif op == 1:
        b = abs(x)
    elif op == 2:
        b = x if x > 0.0 else 0.0
    elif op == 3:
        b = -x if x < 0.0 else 0.0
    elif op == 4:
        b = math.sin(k * x)
    else:
        b = math.cos(k * x)
    out = b
    for _ in range(p - 1):
        out *= b
    return out


@numba.njit(cache=True, inline="always")
def _acc(th, start, sig, op, kk, pw, s):
    """(u̇, v̇, ṙ) = θ φ(s) for the signal vector s; terms with a zero column are skipped."""
    a0 = 0.0
    a1 = 0.0
    a2 = 0.0
    for j in range(start.size - 1):
        c0, c1, c2 = th[0, j], th[1, j], th[2, j]
        if c0 == 0.0 and c1 == 0.0 and c2 == 0.0:
            continue
        phi = 1.0
        for f in range(start[j], start[j + 1]):
            phi *= _factor(s[sig[f]], op[f], kk[f], pw[f])
        a0 += c0 * phi
        a1 += c1 * phi
        a2 += c2 * phi
    return a0, a1, a2


@numba.njit(cache=True)
def _rhs(th, start, sig, op, kk, pw, derived, s, u, v, r, psi, inp, wind_true, vw, dw):
    c, sn = math.cos(psi), math.sin(psi)
    xd = u * c - v * sn
    yd = u * sn + v * c
    s[0], s[1], s[2] = u, v, r
    if derived:
        s[3] = math.sqrt(u * u + v * v)
        s[4] = math.atan2(-v, u)
    s[5], s[6], s[7] = inp[0], inp[1], inp[2]
    if wind_true:
        # Air velocity relative to the ship, earth frame, then body frame; the angle it comes from.
        ax = -vw * math.cos(dw) - xd
        ay = -vw * math.sin(dw) - yd
        bx = ax * c + ay * sn
        by = -ax * sn + ay * c
        s[8] = math.sqrt(bx * bx + by * by)
        s[9] = math.atan2(-by, -bx)
    else:
        s[8], s[9] = inp[3], inp[4]
    a0, a1, a2 = _acc(th, start, sig, op, kk, pw, s)
    return a0, a1, a2, r, xd, yd


@numba.njit(cache=True)
def _step(th, start, sig, op, kk, pw, derived, s, st, inp, h, rk4, wind_true, vw, dw):
    """One Euler or RK4 step of the state tuple st = (u, v, r, ψ, x, y), inputs held."""
    u, v, r, psi, x, y = st
    k1 = _rhs(th, start, sig, op, kk, pw, derived, s, u, v, r, psi, inp, wind_true, vw, dw)
    if not rk4:
        return (u + h * k1[0], v + h * k1[1], r + h * k1[2], psi + h * k1[3], x + h * k1[4],
                y + h * k1[5])  # fmt: skip
    g = 0.5 * h
    k2 = _rhs(th, start, sig, op, kk, pw, derived, s, u + g * k1[0], v + g * k1[1], r + g * k1[2],
              psi + g * k1[3], inp, wind_true, vw, dw)  # fmt: skip
    k3 = _rhs(th, start, sig, op, kk, pw, derived, s, u + g * k2[0], v + g * k2[1], r + g * k2[2],
              psi + g * k2[3], inp, wind_true, vw, dw)  # fmt: skip
    k4 = _rhs(th, start, sig, op, kk, pw, derived, s, u + h * k3[0], v + h * k3[1], r + h * k3[2],
              psi + h * k3[3], inp, wind_true, vw, dw)  # fmt: skip
    w = h / 6.0
    return (u + w * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
            v + w * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]),
            r + w * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]),
            psi + w * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]),
            x + w * (k1[4] + 2 * k2[4] + 2 * k3[4] + k4[4]),
            y + w * (k1[5] + 2 * k2[5] + 2 * k3[5] + k4[5]))  # fmt: skip


@numba.njit(cache=True, inline="always")
def _ok(st, speed_lim, yaw_lim):
    return (abs(st[0]) <= speed_lim and abs(st[1]) <= speed_lim and abs(st[2]) <= yaw_lim
            and math.isfinite(st[3]) and math.isfinite(st[4]) and math.isfinite(st[5]))  # fmt: skip


@numba.njit(cache=True, parallel=True)
def integrate_open(theta, start, sig, op, kk, pw, derived, t, inputs, n_steps, s0, rk4,
                   speed_lim, yaw_lim, out, n_valid):  # fmt: skip
    """Free runs driven by input series: out (B, N, 6), n_valid (B,) valid samples per run
    (a run stops at ``n_steps[b]`` samples or where it diverges)."""
    for b in numba.prange(theta.shape[0]):
        s = np.zeros(N_SIGNALS)
        th = theta[b]
        st = (s0[b, 0], s0[b, 1], s0[b, 2], s0[b, 3], s0[b, 4], s0[b, 5])
        for j in range(6):
            out[b, 0, j] = st[j]
        n_ok = 1
        for k in range(n_steps[b] - 1):
            new = _step(th, start, sig, op, kk, pw, derived, s, st, inputs[b, k], t[k + 1] - t[k],
                        rk4, False, 0.0, 0.0)  # fmt: skip
            if not _ok(new, speed_lim[b], yaw_lim[b]):
                break
            st = new
            for j in range(6):
                out[b, k + 1, j] = st[j]
            n_ok = k + 2
        n_valid[b] = n_ok


@numba.njit(cache=True)
def steer(delta, command, dt, max_angle, max_rate, time_constant):
    """Steering machine: angle limit, first-order lag (exact over the step), rate limit (0: none)."""
    command = min(max(command, -max_angle), max_angle)
    change = command - delta
    if time_constant > 0.0:
        change *= 1.0 - math.exp(-dt / time_constant)
    if max_rate > 0.0:
        lim = max_rate * dt
        change = min(max(change, -lim), lim)
    return delta + change


@numba.njit(cache=True)
def command(p, t, psi, side):
    """Rudder command of a manoeuvre at time t and heading ψ; returns (command, side).

    Hold mode: the held rudder before ``approach``, ``value`` until ``release``, then 0.
    Zig-zag: the held rudder before ``approach``, then ``side``·``stbd``·``value``, the side
    reversed when the heading change from ψ_ref reaches ±switch on the side the ship turns to."""
    if t < p[P_APPROACH] - 1e-9:
        return p[P_HELD], side
    if p[P_MODE] == MODE_HOLD:
        return (p[P_VALUE] if t < p[P_RELEASE] - 1e-9 else 0.0), side
    dpsi = psi - p[P_PSI_REF]
    if side > 0 and dpsi >= p[P_SWITCH]:
        side = -1.0
    elif side < 0 and dpsi <= -p[P_SWITCH]:
        side = 1.0
    return side * p[P_STBD] * p[P_VALUE], side


@numba.njit(cache=True, parallel=True)
def integrate_closed(theta, start, sig, op, kk, pw, derived, dt, n_steps, s0, params, rk4,
                     speed_lim, yaw_lim, states, rudder, n_valid):  # fmt: skip
    """Closed-loop manoeuvres: states (B, N, 6), rudder (B, N), n_valid (B,)."""
    for b in numba.prange(theta.shape[0]):
        s = np.zeros(N_SIGNALS)
        p = params[b]
        th = theta[b]
        inp = np.zeros(N_INPUTS)
        inp[1], inp[2] = p[P_RPS], p[P_THRUST]
        st = (s0[b, 0], s0[b, 1], s0[b, 2], s0[b, 3], s0[b, 4], s0[b, 5])
        delta = p[P_HELD]
        side = p[P_SIDE]
        m = n_steps
        for k in range(n_steps):
            cmd, side = command(p, k * dt, st[3], side)
            delta = steer(delta, cmd, dt, p[P_MAX_ANGLE], p[P_MAX_RATE], p[P_TIME_CONST])
            for j in range(6):
                states[b, k, j] = st[j]
            rudder[b, k] = delta
            if k == n_steps - 1:
                break
            inp[0] = delta
            # Still air is wind too: the apparent wind of the ship's own motion.
            new = _step(th, start, sig, op, kk, pw, derived, s, st, inp, dt, rk4, True,
                        p[P_WIND_SPEED], p[P_WIND_DIR])  # fmt: skip
            if not _ok(new, speed_lim[b], yaw_lim[b]):
                m = k + 1
                break
            st = new
        n_valid[b] = m


@numba.njit(cache=True)
def accelerations(theta, start, sig, op, kk, pw, derived, states, inputs, out):
    """(M, 3) accelerations of one coefficient set θ (3, T) at states (M, 3) and inputs (M, 5):
    the compiled evaluation, checked against ``term_matrix`` by the tests."""
    s = np.zeros(N_SIGNALS)
    for i in range(states.shape[0]):
        a = _rhs(theta, start, sig, op, kk, pw, derived, s, states[i, 0], states[i, 1],
                 states[i, 2], 0.0, inputs[i], False, 0.0, 0.0)  # fmt: skip
        out[i, 0], out[i, 1], out[i, 2] = a[0], a[1], a[2]
