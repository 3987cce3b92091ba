"""The MMG standard method (Yasukawa & Yoshimura 2015) compiled once for any ship's coefficients:
the built-in KVLCC2 (``shipid.vessels.kvlcc2``), a ship's own MMG file
(``shipid.vessels.mmg_file``) and either of them with a correction fitted by ``shipid correct``
(``shipid.identification.correction``) run this one formula in the kernels' integrators.

reference-ships.md §2: midship sway velocity throughout, dimensional lever arms, the
propeller's wake in drift, flow straightening γ_R that differs with the sign of the drift at
the rudder. The coefficients travel as a ``Coefficients`` named tuple (prime values and the
mass matrix's inverse); numba reads each field as a constant offset, so the formula with its
coefficients as arguments runs as fast as it did with them typed in (``benchmarks/README.md``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import NamedTuple

import numba
import numpy as np

import shipid.vessels.mmg as _this  # this module: see the entries below
from shipid.dynamics import kernel

from .vessel import CompiledDynamics

kernel.drop_stale_caches(__file__)


class Coefficients(NamedTuple):
    """One ship's MMG model as the compiled formula reads it: dimensional particulars, prime
    hull, propeller and rudder coefficients (``mmg_file``'s names), the sway–yaw mass matrix's
    inverse."""

    rho: float
    length: float
    draught: float
    m: float
    mx: float
    my: float
    x_g: float
    inv00: float
    inv01: float
    inv10: float
    inv11: float
    r0: float
    x_vv: float
    x_vr: float
    x_rr: float
    x_vvvv: float
    y_v: float
    y_r: float
    y_vvv: float
    y_vvr: float
    y_vrr: float
    y_rrr: float
    n_v: float
    n_r: float
    n_vvv: float
    n_vvr: float
    n_vrr: float
    n_rrr: float
    diameter: float
    t_p: float
    w_p0: float
    k0: float
    k1: float
    k2: float
    x_p: float
    c1: float
    c2_pos: float
    c2_neg: float
    area: float
    eta: float
    t_r: float
    a_h: float
    x_h: float
    x_r: float
    l_r: float
    epsilon: float
    kappa: float
    f_alpha: float
    gamma_r_pos: float
    gamma_r_neg: float


def pack(c: Mapping) -> Coefficients:
    """The compiled formula's coefficients from ``mmg_file.coefficients``' flat dictionary
    (``hull.y_v``, ``rudder.area``, ...): masses, added masses and the mass matrix's inverse
    worked out here, once."""
    rho, L, d = c["rho"], c["length"], c["draught"]
    m = rho * c["volume"]
    half = 0.5 * rho * L**2 * d
    mx, my = c["hull.m_x"] * half, c["hull.m_y"] * half
    jz = c["hull.j_z"] * 0.5 * rho * L**4 * d
    izg = m * (c["k_zz"] * L) ** 2
    xg = c["x_g"]
    # Sway–yaw: [[m + my, xG m], [xG m, IzG + xG² m + Jz]] (v̇, ṙ) = (Y − (m + mx) u r, N − xG m u r)
    (i00, i01), (i10, i11) = np.linalg.inv([[m + my, xg * m],
                                            [xg * m, izg + xg**2 * m + jz]]).tolist()  # fmt: skip
    fields = {"rho": rho, "length": L, "draught": d, "m": m, "mx": mx, "my": my, "x_g": xg,
              "inv00": i00, "inv01": i01, "inv10": i10, "inv11": i11,
              "eta": c["propeller.diameter"] / c["rudder.height"]}  # fmt: skip
    for key, value in c.items():
        name = key.rpartition(".")[2]
        if "." in key and name in Coefficients._fields:
            fields[name] = float(value)
    return Coefficients(**{name: float(fields[name]) for name in Coefficients._fields})


# NumPy's error model: a state at rest mid-run (U = 0, where the prime forces are undefined)
# gives NaN, which the integrators report as the run's end, not a crash.
@numba.njit(cache=True, error_model="numpy")
def accelerations(c, u, vm, r, delta, n):
    """(u̇, v̇m, ṙ) of the MMG model ``c`` (``Coefficients``) at midship sway vm, rudder δ and
    propeller speed n [rps]: hull, propeller and rudder forces through the mass matrix."""
    L = c.length
    U = math.sqrt(u * u + vm * vm)
    beta = math.atan2(-vm, u)
    vp, rp = vm / U, r * L / U
    q = 0.5 * c.rho * L * c.draught * U * U
    XH = q * (-c.r0 + c.x_vv * vp**2 + c.x_vr * vp * rp + c.x_rr * rp**2 + c.x_vvvv * vp**4)
    YH = q * (c.y_v * vp + c.y_r * rp + c.y_vvv * vp**3 + c.y_vvr * vp**2 * rp
              + c.y_vrr * vp * rp**2 + c.y_rrr * rp**3)  # fmt: skip
    NH = q * L * (c.n_v * vp + c.n_r * rp + c.n_vvv * vp**3 + c.n_vvr * vp**2 * rp
                  + c.n_vrr * vp * rp**2 + c.n_rrr * rp**3)  # fmt: skip
    DP = c.diameter
    beta_p = beta - c.x_p * rp
    c2 = c.c2_pos if beta_p > 0 else c.c2_neg
    one_minus_wp = (1 - c.w_p0) * (1 + (1 - math.exp(-c.c1 * abs(beta_p))) * (c2 - 1))
    Jp = u * one_minus_wp / (n * DP)
    KT = c.k0 + c.k1 * Jp + c.k2 * Jp**2
    XP = (1 - c.t_p) * c.rho * n**2 * DP**4 * KT
    beta_r = beta - c.l_r * rp
    gamma_r = c.gamma_r_neg if beta_r < 0 else c.gamma_r_pos
    vR = U * gamma_r * beta_r
    uR = c.epsilon * u * one_minus_wp * math.sqrt(
        c.eta * (1 + c.kappa * (math.sqrt(1 + 8 * KT / (math.pi * Jp**2)) - 1)) ** 2
        + (1 - c.eta))  # fmt: skip
    alpha_r = delta - math.atan2(vR, uR)
    FN = 0.5 * c.rho * c.area * (uR**2 + vR**2) * c.f_alpha * math.sin(alpha_r)
    X = XH + XP - (1 - c.t_r) * FN * math.sin(delta)
    Y = YH - (1 + c.a_h) * FN * math.cos(delta)
    N = NH - (c.x_r * L + c.a_h * c.x_h * L) * FN * math.cos(delta)
    m = c.m
    ry = Y - (m + c.mx) * u * r
    rn = N - c.x_g * m * u * r
    return ((X + (m + c.my) * vm * r + c.x_g * m * r * r) / (m + c.mx),
            c.inv00 * ry + c.inv01 * rn, c.inv10 * ry + c.inv11 * rn)  # fmt: skip


@numba.njit(cache=True)
def rhs(ctx, u, v, r, psi):
    """State derivative for the compiled integrators; ctx = (inputs, n, coefficients, follow):
    δ = inputs[0]; the propeller at inputs[1] (the log's or the manoeuvre's) where ``follow``,
    else at n."""
    inp = ctx[0]
    a0, a1, a2 = accelerations(ctx[2], u, v, r, inp[0], inp[1] if ctx[3] else ctx[1])
    psi_dot, xd, yd = kernel.kinematics(u, v, r, psi)
    return a0, a1, a2, psi_dot, xd, yd


# Entries reach ``rhs`` as a module attribute: numba caches them only then.
@numba.njit(cache=True)
def _batch(c, nu, delta, n):
    out = np.empty_like(nu)
    for i in range(nu.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = accelerations(c, nu[i, 0], nu[i, 1], nu[i, 2],
                                                        delta[i], n[i])  # fmt: skip
    return out


@numba.njit(cache=True)
def _open(c, n, follow, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
    for b in range(inputs.shape[0]):
        inp = np.zeros(kernel.N_INPUTS)
        n_valid[b] = kernel.open_run(_this.rhs, (inp, n, c, follow), inp, t, inputs[b], n_steps[b],
                                     s0[b], rk4, speed_lim[b], yaw_lim[b], out[b])  # fmt: skip


@numba.njit(cache=True)
def _closed(c, n, follow, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder,
            n_valid):  # fmt: skip
    for b in range(params.shape[0]):
        inp = np.zeros(kernel.N_INPUTS)
        n_valid[b] = kernel.closed_run(_this.rhs, (inp, n, c, follow), inp, params[b], dt, n_steps,
                                       s0[b], rk4, speed_lim[b], yaw_lim[b], states[b],
                                       rudder[b])  # fmt: skip


@numba.njit(cache=True)
def open_corrected(c, n, follow, terms, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out,
                   n_valid):  # fmt: skip
    """Free runs of the MMG model ``c`` at propeller speed ``n`` (the inputs' where ``follow``)
    plus a correction's terms (``kernel.open_corrected_runs``)."""
    kernel.open_corrected_runs(_this.rhs, (n, c, follow), terms, t, inputs, n_steps, s0, rk4,
                               speed_lim, yaw_lim, out, n_valid)  # fmt: skip


@numba.njit(cache=True)
def closed_corrected(c, n, follow, terms, windy, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim,
                     states, rudder, n_valid):  # fmt: skip
    """Closed-loop manoeuvres of the MMG model ``c`` plus a correction's terms, in the true
    wind of each row of ``params`` where they have wind terms (``windy``)."""
    kernel.closed_corrected_runs(_this.rhs, (n, c, follow), terms, windy, dt, n_steps, s0,
                                 params, rk4, speed_lim, yaw_lim, states, rudder, n_valid)


def ahead_only(rps: np.ndarray, t: np.ndarray | None = None, what: str = "") -> None:
    """Refuse a propeller speed that is not ahead (> 0): the MMG standard method's propeller
    (K_T of the advance ratio J = u (1 − w_P) / (n D_P)) and the rudder's inflow in its race
    hold for a propeller turning ahead only (the harbour manoeuvres of the Esso Osaka's random
    runs stop and reverse it)."""
    rps = np.asarray(rps, dtype=float)
    bad = np.argwhere(~(rps > 0.0))
    if bad.size:
        from shipid.errors import ShipidError

        first = tuple(bad[0])
        when = f" at t = {t[first[-1]]:.4g} s" if t is not None and first[-1] < len(t) else ""
        raise ShipidError(f"{what + ': ' if what else ''}the propeller speed is {rps[first]:.3g} "
                          f"rps{when} (its lowest {np.min(rps):.3g}), and the MMG standard "
                          "method models a propeller turning ahead only; cut the log before it "
                          "(--end) or use a model identified from logs that reverse it")


def under_way(s0: np.ndarray) -> None:
    """Refuse a run that starts at rest: the MMG model's hull forces are written in the drift
    angle and the yaw rate per ship length travelled, undefined where the ship does not move."""
    speed = np.hypot(np.asarray(s0)[:, 0], np.asarray(s0)[:, 1])
    if not np.all(speed > 0):
        from shipid.errors import ShipidError

        raise ShipidError("the run starts at rest (u = v = 0), where the MMG standard method's "
                          "hull forces are undefined: start it under way (a log cut to its "
                          "manoeuvre, --start auto)")  # fmt: skip


def ahead_orders(params: np.ndarray) -> None:
    """Refuse a manoeuvre whose propeller order is not ahead (a crash stop's astern, a stopped
    propeller): ``ahead_only``'s reason, for the closed loops' parameter rows."""
    p = np.atleast_2d(params)
    start = p[:, kernel.P_RPS]
    order = np.where(p[:, kernel.P_RPS_RAMP] < 0, start, p[:, kernel.P_RPS_TO])
    if not (np.all(start > 0) and np.all(order > 0)):
        from shipid.errors import ShipidError

        raise ShipidError(f"the propeller is ordered to {float(np.min(order)):.3g} rps (from "
                          f"{float(np.min(start)):.3g}), and the MMG standard method models a "
                          "propeller turning ahead only (no crash stop, no propeller stopped)")


def trimmed_rps(c: Mapping, speed: float) -> float:
    """The propeller rps for u̇ = 0 at ``speed`` in straight running of the MMG model of flat
    coefficients ``c`` (``mmg_file.coefficients``' form; the KVLCC2's ≈ 11.85 rps at 1.179 m/s),
    or a one-line error naming the ship where no rate holds it."""
    from scipy.optimize import brentq  # 0.4 s to import: only when an MMG ship is trimmed

    packed = pack(c)
    state, rudder = np.array([[speed, 0.0, 0.0]]), np.zeros(1)

    def surge(n: float) -> float:
        return float(_batch(packed, state, rudder, np.array([n]))[0, 0])

    low = 1e-3 * speed / c["propeller.diameter"] + 1e-6
    if not surge(low) < 0 < surge(1e4):
        from shipid.errors import ShipidError

        raise ShipidError(f"{c.get('name', 'the MMG ship')}: no propeller speed holds {speed:g} "
                          "m/s straight ahead (check the resistance and the propeller's "
                          "coefficients)")  # fmt: skip
    return brentq(surge, low, 1e4, xtol=1e-12)


class MMGDynamics(CompiledDynamics):
    """The MMG model's accelerations, its propeller at a constant ``n_prop`` [rps] (trimmed for
    the approach speed) or, where ``follow_rps``, at the rate each run gives (a log's column n,
    a manoeuvre's rps: ``uses_rps``); ``c`` the flat coefficients of ``mmg_file.coefficients``
    (kept: a corrected ship's file embeds them)."""

    # The MMG standard method's propeller turns ahead: no crash stop (``shipid.trials.criteria``).
    propeller_ahead_only = True

    def __init__(self, c: Mapping, n_prop: float, follow_rps: bool = False) -> None:
        self.c = dict(c)
        self.n_prop = float(n_prop)
        self.follow_rps = bool(follow_rps)
        self.packed = pack(self.c)

    @property
    def uses_rps(self) -> bool:
        """Whether a run gives the propeller speed (the simulator then asks for it)."""
        return self.follow_rps

    def derivatives(self, nu, delta, thrust=None, rps=None):
        """(B, 3) body accelerations at states nu (B, 3) (midship sway) and rudder delta (B,),
        the propeller at ``rps`` (B,) where the ship follows it, else at ``n_prop``."""
        nu = kernel.c_array(nu).reshape(-1, 3)
        delta = kernel.c_array(np.broadcast_to(np.asarray(delta, dtype=float), nu.shape[:1]))
        n = self.n_prop  # checked ahead where it was trimmed or read
        if self.follow_rps and rps is not None:
            n = rps
            ahead_only(n)
        return _batch(self.packed, nu, delta,
                      kernel.c_array(np.broadcast_to(np.asarray(n, dtype=float), nu.shape[:1])))

    def integrate_open(self, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
        """Free runs driven by (B, N, 5) inputs, the propeller at ``n_prop`` or the inputs'."""
        under_way(s0)
        if self.follow_rps:
            ahead_only(inputs[:, :-1, 1], t)
        _open(self.packed, self.n_prop, self.follow_rps, t, inputs, n_steps, s0, rk4, speed_lim,
              yaw_lim, out, n_valid)  # fmt: skip

    def integrate_closed(self, dt, n_steps, s0, params, rk4, speed_lim, yaw_lim, states, rudder,
                         n_valid):  # fmt: skip
        """Closed-loop manoeuvres of parameter rows ``params``, the propeller at ``n_prop`` or
        the manoeuvre's."""
        under_way(s0)
        if self.follow_rps:
            ahead_orders(params)
        _closed(self.packed, self.n_prop, self.follow_rps, dt, n_steps, s0, params, rk4,
                speed_lim, yaw_lim, states, rudder, n_valid)  # fmt: skip

    def corrected_kernels(self):
        """(open runs, closed runs) plus a correction's terms, and the arguments that lead
        theirs (``shipid.identification.correction.CorrectedMMGDynamics``)."""
        return _this.open_corrected, _this.closed_corrected, (self.packed, self.n_prop,
                                                              self.follow_rps)
