"""Compiled (numba) kernels: a models' accelerations for any term set, open-loop integration driven
by input series, and closed-loop manoeuvres (zig-zag, held rudder, pull-out) with the steering
machine, all batched over trajectories that may each have their own coefficients.

The integrators (``step``, ``open_run``, ``closed_run``) take the state derivative as a function
``rhs(ctx, u, v, r, ψ) -> (u̇, v̇, ṙ, ψ̇, ẋ, ẏ)`` and its context tuple: ``terms_rhs`` for a term
set, the reference ships' own compiled physics (``shipid.vessels``) otherwise.

A term set is the factor table of ``shipid.dynamics.terms.TermCode``; coefficients are θ (B, 3, T)
(rows u̇, v̇, ṙ; a held DOF has a zero row). Inputs are (B, N, 5) in ``INPUT_SIGNALS`` order
(delta, n, thrust, wind_speed, wind_angle), held over each step (zero-order hold).

State: [u, v, r, ψ, x, y] with ψ̇ = r, ẋ = u cosψ − v sinψ, ẏ = u sinψ + v cosψ.

Closed loop: each step the rudder command of the manoeuvre (``command``) goes through the steering
machine (``steer``), the state is recorded, then integrated over the step; the same order as a log
replays with ``simulate_log``. Wind in a closed loop is a constant true wind (speed, direction it
blows from, clockwise from north), turned into the relative wind from the ship's heading and
velocity at every evaluation.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numba
import numpy as np

# numba caches a function that hands ``terms_rhs`` on only when it reaches it as a module
# attribute, not as a bare global.
import shipid.dynamics.kernel as _kernel  # noqa: E402  (this module)
from shipid.dynamics.terms import CROSSFLOW_SLOTS, INPUT_SIGNALS, RUDDER_SLOT, SIGNALS, TINY

SWAY_SLOT, YAW_SLOT = CROSSFLOW_SLOTS
WIND_SPEED_SLOT, WIND_ANGLE_SLOT = SIGNALS.index("wind_speed"), SIGNALS.index("wind_angle")

N_INPUTS = 5
# The inputs (``INPUT_SIGNALS``: delta, n, thrust, wind_speed, wind_angle) are the signals from
# here on, in that order: a run's input buffer is that part of the signal buffer.
INPUT_SLOT = SIGNALS.index("delta")
assert SIGNALS[INPUT_SLOT:INPUT_SLOT + N_INPUTS] == INPUT_SIGNALS
# The signal buffer: ``SIGNALS``, then the cross-flow factors' values (``terms.CROSSFLOW_SLOTS``)
# and the rudder's normal force (``terms.RUDDER_SLOT``), filled once per evaluation by
# ``terms_rhs_crossflow`` or ``terms_rhs_rudder`` for a term set that has them; the factor loop
# itself keeps the six operations (a branch for the drag in it, or in ``terms_rhs``, made every
# model's interpreted runs 1.15–1.6 times slower, taken or not).
# The rudder's inflow (a, c, g, x) rides in the buffer after its slot, set once per run: as a
# fifth array in the run's context it made the drag's interpreted runs 10 % slower.
INFLOW_SLOT = RUDDER_SLOT + 1
N_SIGNALS = INFLOW_SLOT + 4
# Which state derivative a run takes (ctx[13]): ``terms_rhs``, ``terms_rhs_crossflow`` or
# ``terms_rhs_rudder`` (the rudder's normal force, and the drag where the hull's length is set).
SLOTS_NONE, SLOTS_CROSSFLOW, SLOTS_RUDDER = 0, 1, 2
# Closed-loop parameters, one row per trajectory.
P_MODE, P_VALUE, P_SWITCH, P_SIDE, P_STBD, P_APPROACH, P_RELEASE, P_HELD, P_PSI_REF = range(9)
P_MAX_ANGLE, P_MAX_RATE, P_TIME_CONST, P_RPS, P_THRUST, P_WIND_SPEED, P_WIND_DIR = range(9, 16)
# Propeller order: from P_RPS to P_RPS_TO, linearly over P_RPS_RAMP seconds from P_RPS_AT.
P_RPS_TO, P_RPS_AT, P_RPS_RAMP = range(16, 19)
# Heading autopilot: PID gains on the heading error (P_VALUE is the ordered heading).
P_KP, P_KI, P_KD = range(19, 22)
# Line-of-sight path following: lookahead and acceptance distance [m], number of waypoints;
# the waypoints (x, y relative to the first, where the run starts) follow the N_PARAMS entries.
P_LOOKAHEAD, P_ACCEPT, P_N_WAYPOINTS = range(22, 25)
# A zig-zag's own switch heading for each of its first reversals, in turn (a replica of a trial
# reversed unevenly), follows the N_PARAMS entries as the waypoints do; the same slot counts them.
# Past them, P_SWITCH.
P_N_SWITCHES = P_N_WAYPOINTS
N_PARAMS = 25
MODE_HOLD, MODE_ZIGZAG, MODE_HEADING, MODE_FOLLOW = 0, 1, 2, 3


@functools.lru_cache(maxsize=1)
def source_digest() -> str:
    """SHA-256 of this module's source: what compiled code that inlines it depends on (the
    generated kernels' names, the reference ships' caches)."""
    import hashlib  # 3 ms: on first use, not on every command's start-up

    return hashlib.sha256(Path(__file__).read_bytes()).hexdigest()


def drop_stale_caches(module_file: str) -> None:
    """Delete numba's cache of the module at ``module_file`` when this file has changed since it
    was written. numba stamps a cached function with its own file only, not its callees': a
    reference ship's closed loop, compiled with this module's ``closed_run`` inlined, came back
    from the cache with the old one after an edit here (a new command mode ran as a zig-zag).
    Called at the top of such modules, before their entries are compiled or loaded."""
    path = Path(module_file)
    folder = path.parent / "__pycache__"
    marker = folder / f"{path.stem}.kernel-sha256"
    digest = source_digest()
    try:
        if marker.read_text() == digest:
            return
    except OSError:
        pass
    try:
        for stale in [*folder.glob(f"{path.stem}.*.nbi"), *folder.glob(f"{path.stem}.*.nbc")]:
            stale.unlink()
        folder.mkdir(exist_ok=True)
        marker.write_text(digest)
    except OSError:
        pass  # a read-only install: its caches were written with its own kernel


def c_array(a, dtype=np.float64) -> np.ndarray:
    """``a`` as a writeable C-contiguous array: every entry point is compiled for that layout
    only (a read-only or strided argument would compile, and cache, one more version)."""
    return np.require(a, dtype, ("C", "W"))


# NumPy's error model: Python's puts a raise on every division, and its exception path in every
# run that can reach the call, made them 15 % slower.
@numba.njit(cache=True, error_model="numpy")
def crossflow(v, r, length):
    """(1/L ∫ |w|w dx, 1/L² ∫ x |w|w dx), w = v + x r over the hull's length: the closed form of
    ``shipid.dynamics.terms.crossflow`` for one state."""
    h = 0.5 * length
    if abs(v) >= abs(r) * h or abs(r) * h < TINY:  # w keeps v's sign along the hull
        # (or is too small for the 1/r² below)
        sign = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
        return sign * (v * v + r * r * h * h / 3.0), sign * r * v * h / 3.0
    s2, s1 = v + r * h, v - r * h
    c2, c1 = abs(s2) ** 3, abs(s1) ** 3
    return ((c2 - c1) / (3.0 * r) / length,
            ((s2 * c2 - s1 * c1) / 4.0 - v * (c2 - c1) / 3.0) / (r * r) / (length * length))


@numba.njit(cache=True, error_model="numpy")
def rudder_normal(u, v, r, delta, n, a, c, g, x):
    """U_R² sin α_R of the rudder's inflow (a, c, g, x): the closed form of
    ``shipid.dynamics.terms.rudder_normal`` for one state."""
    ahead = n if n > 0.0 else 0.0
    u_r = math.sqrt(a * u * u + c * ahead * ahead)
    v_r = -g * (v + x * r)
    return (u_r * u_r + v_r * v_r) * math.sin(delta - math.atan2(v_r, u_r))


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
    elif op == 5:
        b = math.cos(k * x)
    else:  # 9, a propeller's thrust at the ratio k astern (6–8 are read from their slots)
        b = x * x if x >= 0.0 else -k * x * x
    out = b
    for _ in range(p - 1):
        out *= b
    return out


@numba.njit(cache=True, inline="always")
def _acc(th, rows, sig, op, kk, pw, fv, s):
    """(u̇, v̇, ṙ) = θ φ(s) for the signal vector s: the distinct factors' values into ``fv``
    (its last entry reads 1), then each term's row of them multiplied; θ (T, 3) holds only the
    terms with a coefficient (``_terms_ctx``)."""
    for i in range(sig.size):
        fv[i] = _factor(s[sig[i]], op[i], kk[i], pw[i])
    a0 = 0.0
    a1 = 0.0
    a2 = 0.0
    for j in range(rows.shape[0]):
        phi = 1.0
        for f in range(rows.shape[1]):
            phi *= fv[rows[j, f]]
        a0 += th[j, 0] * phi
        a1 += th[j, 1] * phi
        a2 += th[j, 2] * phi
    return a0, a1, a2


@numba.njit(cache=True, inline="always")
def kinematics(u, v, r, psi):
    """(ψ̇, ẋ, ẏ) of the planar kinematics."""
    c, sn = math.cos(psi), math.sin(psi)
    return r, u * c - v * sn, u * sn + v * c


@numba.njit(cache=True, inline="always")
def terms_rhs(ctx, u, v, r, psi):
    """State derivative of a term-set model; ctx = (θ, factor table (5 arrays), derived, signal
    buffer, inputs, true wind?, wind speed, wind direction, hull length, which slots the buffer
    has to fill, the factors' values): ``_terms_ctx``'s."""
    th, rows, sig, op, kk, pw, derived, s, _, wind_true, vw, dw, _, _, fv = ctx
    _, xd, yd = kinematics(u, v, r, psi)
    s[0], s[1], s[2] = u, v, r
    if derived:
        s[3] = math.sqrt(u * u + v * v)
        s[4] = math.atan2(-v, u)
    # The inputs are the buffer's own slots (``_terms_ctx``): nothing to copy. Copying the logged
    # wind in at every evaluation, taken or not, made the closed loops 1.2 times slower.
    if wind_true:
        # Air velocity relative to the ship, earth frame, then body frame; the angle it comes from.
        c, sn = math.cos(psi), math.sin(psi)
        ax = -vw * math.cos(dw) - xd
        ay = -vw * math.sin(dw) - yd
        bx = ax * c + ay * sn
        by = -ax * sn + ay * c
        s[8] = math.sqrt(bx * bx + by * by)
        s[9] = math.atan2(-by, -bx)
    a0, a1, a2 = _acc(th, rows, sig, op, kk, pw, fv, s)
    return a0, a1, a2, r, xd, yd


@numba.njit(cache=True, inline="always")
def terms_rhs_crossflow(ctx, u, v, r, psi):
    """``terms_rhs`` of a term set with the hull's cross-flow drag: its factors' values into the
    signal buffer's slots first (ctx[12] the hull's length). A run picks it before its loop
    (ctx[13]): computed in ``terms_rhs`` behind a flag, even never taken, the drag made every
    model's interpreted runs 1.15–1.6 times slower."""
    ctx[7][SWAY_SLOT], ctx[7][YAW_SLOT] = crossflow(v, r, ctx[12])
    return terms_rhs(ctx, u, v, r, psi)


@numba.njit(cache=True, inline="always")
def terms_rhs_rudder(ctx, u, v, r, psi):
    """``terms_rhs`` of a term set with the rudder's normal force (its inflow in the buffer from
    ``INFLOW_SLOT``), and the cross-flow drag where ctx[12], the hull's length, is set: their
    values into the signal buffer's slots first. Apart from ``terms_rhs_crossflow``: its branch
    made the drag's runs 10 % slower."""
    s, inp = ctx[7], ctx[8]
    if ctx[12] > 0.0:
        s[SWAY_SLOT], s[YAW_SLOT] = crossflow(v, r, ctx[12])
    i = INFLOW_SLOT
    s[RUDDER_SLOT] = rudder_normal(u, v, r, inp[0], inp[1], s[i], s[i + 1], s[i + 2], s[i + 3])
    return terms_rhs(ctx, u, v, r, psi)


@numba.njit(cache=True, inline="always")
def terms_rhs_any(ctx, u, v, r, psi):
    """``terms_rhs``, or its cross-flow or rudder variant as ctx[13] says, chosen at every
    evaluation: for a state derivative that adds its own to a term model's (a hybrid's kernel
    residual), whose own cost dwarfs the branch."""
    if ctx[13] == SLOTS_CROSSFLOW:
        return terms_rhs_crossflow(ctx, u, v, r, psi)
    if ctx[13] == SLOTS_RUDDER:
        return terms_rhs_rudder(ctx, u, v, r, psi)
    return terms_rhs(ctx, u, v, r, psi)


# Inlined: a function passed on through two calls would make numba refuse to cache the caller.
@numba.njit(cache=True, inline="always")
def step(rhs, ctx, st, h, rk4):
    """One Euler or RK4 step of the state tuple st = (u, v, r, ψ, x, y) with the inputs held;
    ``rhs(ctx, u, v, r, ψ)`` is the state derivative (``terms_rhs`` or a reference ship's)."""
    u, v, r, psi, x, y = st
    k1 = rhs(ctx, u, v, r, psi)
    if not rk4:
        return (u + h * k1[0], v + h * k1[1], r + h * k1[2], psi + h * k1[3], x + h * k1[4],
                y + h * k1[5])  # fmt: skip
    g = 0.5 * h
    k2 = rhs(ctx, u + g * k1[0], v + g * k1[1], r + g * k1[2], psi + g * k1[3])
    k3 = rhs(ctx, u + g * k2[0], v + g * k2[1], r + g * k2[2], psi + g * k2[3])
    k4 = rhs(ctx, u + h * k3[0], v + h * k3[1], r + h * k3[2], psi + h * k3[3])
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


# Not cached on its own (nor closed_run): numba keys such an entry by the rhs's dispatcher, whose
# identity is new in every process, so each process that compiled a caller (a generated term
# set's kernel, a reference ship's) added one entry to one index, read whole at every later
# compile (0.35 s at 123 entries, measured once), and once it held more entries than numba
# keeps dispatchers alive (128) writing it failed ("underlying object has vanished"). Their
# cached callers keep them compiled in.
@numba.njit
def open_run(rhs, ctx, inp, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out):
    """One free run driven by the input series ``inputs`` (N, 5), copied step by step into
    ``inp`` (the buffer ``rhs`` reads); out (N, 6). Returns the valid samples."""
    st = (s0[0], s0[1], s0[2], s0[3], s0[4], s0[5])
    for j in range(6):
        out[0, j] = st[j]
    n_ok = 1
    for k in range(n_steps - 1):
        for j in range(N_INPUTS):
            inp[j] = inputs[k, j]
        new = step(rhs, ctx, st, t[k + 1] - t[k], rk4)
        if not _ok(new, speed_lim, yaw_lim):
            break
        st = new
        for j in range(6):
            out[k + 1, j] = st[j]
        n_ok = k + 2
    return n_ok


@numba.njit(cache=True)
def _terms_ctx(th, rows, sig, op, kk, pw, rud, derived, wind_true, vw, dw):
    """A run's context for ``terms_rhs`` from θ (3, T) and the factor table
    (``TermCode.arrays``): θ transposed to the terms with a coefficient, and their rows."""
    hull = 0.0
    reads_wind = False
    for f in range(sig.size):  # a cross-flow factor's k is the hull's length
        if sig[f] == SWAY_SLOT or sig[f] == YAW_SLOT:
            hull = kk[f]
        elif sig[f] == WIND_SPEED_SLOT or sig[f] == WIND_ANGLE_SLOT:
            reads_wind = True
    # A term whose three coefficients are 0 is left out here, not tested at every evaluation.
    kept = 0
    for j in range(th.shape[1]):
        if th[0, j] != 0.0 or th[1, j] != 0.0 or th[2, j] != 0.0:
            kept += 1
    coef = np.empty((kept, 3))
    used = np.empty((kept, rows.shape[1]), dtype=np.int64)
    i = 0
    for j in range(th.shape[1]):
        if th[0, j] != 0.0 or th[1, j] != 0.0 or th[2, j] != 0.0:
            for e in range(3):
                coef[i, e] = th[e, j]
            for f in range(rows.shape[1]):
                used[i, f] = rows[j, f]
            i += 1
    slots = SLOTS_RUDDER if rud[0] > 0.0 else (SLOTS_CROSSFLOW if hull > 0.0 else SLOTS_NONE)
    buffer = np.zeros(N_SIGNALS)
    buffer[INFLOW_SLOT:] = rud
    # The apparent wind of a term set that reads none is never computed (a square root, an
    # arctangent and a sine and cosine in every evaluation of a closed loop's: 107 -> 91 ns).
    # The inputs' buffer is a view of the signals' (``INPUT_SLOT``): a run's inputs are set in
    # it once per step, and the apparent wind written over the logged one's slots.
    return (coef, used, sig, op, kk, pw, derived, buffer,
            buffer[INPUT_SLOT:INPUT_SLOT + N_INPUTS], wind_true and reads_wind, vw, dw, hull,
            slots, np.ones(sig.size + 1))  # fmt: skip


@numba.njit(cache=True, parallel=True)
def integrate_open(theta, rows, sig, op, kk, pw, rud, derived, t, inputs, n_steps, s0, rk4,
                   speed_lim, yaw_lim, out, n_valid):  # fmt: skip
    """Free runs driven by input series: out (B, N, 6), n_valid (B,) valid samples per run
    (a run stops at ``n_steps[b]`` samples or where it diverges)."""
    for b in numba.prange(theta.shape[0]):
        ctx = _terms_ctx(theta[b], rows, sig, op, kk, pw, rud, derived, False, 0.0, 0.0)
        if ctx[13] == SLOTS_CROSSFLOW:
            n_valid[b] = open_run(_kernel.terms_rhs_crossflow, ctx, ctx[8], t, inputs[b],
                                  n_steps[b], s0[b], rk4, speed_lim[b], yaw_lim[b], out[b])
        elif ctx[13] == SLOTS_RUDDER:
            n_valid[b] = open_run(_kernel.terms_rhs_rudder, ctx, ctx[8], t, inputs[b],
                                  n_steps[b], s0[b], rk4, speed_lim[b], yaw_lim[b], out[b])
        else:
            n_valid[b] = open_run(_kernel.terms_rhs, ctx, ctx[8], t, inputs[b], n_steps[b],
                                  s0[b], rk4, speed_lim[b], yaw_lim[b], out[b])  # fmt: skip


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
def line_of_sight(p, x, y, leg):
    """Line of sight along the waypoints of ``p`` from position (x, y) on leg ``leg`` (the next
    leg once the along-track distance reaches the leg's length less the acceptance distance):
    (ordered heading, cross-track error, leg, whether the last leg's end is reached)."""
    k = int(leg)
    last = int(p[P_N_WAYPOINTS]) - 2
    while True:
        j = N_PARAMS + 2 * k
        x0, y0, x1, y1 = p[j], p[j + 1], p[j + 2], p[j + 3]
        a = math.atan2(y1 - y0, x1 - x0)
        length = math.hypot(x1 - x0, y1 - y0)
        dx, dy = x - x0, y - y0
        along = dx * math.cos(a) + dy * math.sin(a)
        if along >= length - p[P_ACCEPT] and k < last:
            k += 1
            continue
        break
    cross = -dx * math.sin(a) + dy * math.cos(a)
    return a + math.atan2(-cross, p[P_LOOKAHEAD]), cross, float(k), k == last and along >= length


@numba.njit(cache=True)
def follow_track(p, x, y, out):
    """The line of sight along a recorded track (x, y): out (N, 2) the ordered heading and the
    cross-track error per sample, as the run's commands had them; returns the index of the
    first sample at the end of the path, −1 if none."""
    leg = 0.0
    for i in range(x.size):
        out[i, 0], out[i, 1], leg, done = line_of_sight(p, x[i], y[i], leg)
        if done:
            return i
    return -1


@numba.njit(cache=True)
def command(p, t, psi, r, target, side, integral, dt):
    """Rudder command of a manoeuvre at time t, heading ψ and yaw rate r (and for the autopilot
    the ordered heading ``target``); returns (command, side, integral).

    Hold mode: the held rudder before ``approach``, ``value`` until ``release``, then 0.
    Zig-zag: the held rudder before ``approach``, then ``side``·``stbd``·``value``, the side
    reversed when the heading change from ψ_ref reaches ±switch on the side the ship turns to
    (the k-th reversal's own switch where ``P_N_SWITCHES`` > k; ``integral``, the autopilot's,
    counts the reversals).
    Heading: the PID autopilot δc = −(Kp ψ̃ + Ki ∫ψ̃ dt + Kd r), ψ̃ = ψ − ``target`` (the
    ``value``) wrapped to [−π, π), the integral frozen while the command exceeds the rudder
    limit (anti-windup). Follow: the same autopilot on the line-of-sight heading, which
    ``closed_run`` gives as ``target`` (``line_of_sight`` is kept out of this function: inside
    it, it slowed the other modes by 5–13 %)."""
    if t < p[P_APPROACH] - 1e-9:
        return p[P_HELD], side, integral
    if p[P_MODE] == MODE_HOLD:
        return (p[P_VALUE] if t < p[P_RELEASE] - 1e-9 else 0.0), side, integral
    if p[P_MODE] == MODE_ZIGZAG:
        dpsi = psi - p[P_PSI_REF]
        switch = p[P_SWITCH]
        if integral < p[P_N_SWITCHES]:  # one float comparison where no list is given
            switch = p[N_PARAMS + int(integral)]
        if side > 0 and dpsi >= switch:
            side = -1.0
            integral += 1.0
        elif side < 0 and dpsi <= -switch:
            side = 1.0
            integral += 1.0
        return side * p[P_STBD] * p[P_VALUE], side, integral
    err = (psi - target + math.pi) % (2.0 * math.pi) - math.pi
    cmd = -(p[P_KP] * err + p[P_KI] * integral + p[P_KD] * r)
    if -p[P_MAX_ANGLE] <= cmd <= p[P_MAX_ANGLE]:
        integral += err * dt
    return cmd, side, integral


@numba.njit(cache=True)
def propeller(p, t):
    """Propeller speed of a manoeuvre at time t: the approach rps, then a ramp to the order."""
    if p[P_RPS_RAMP] < 0.0 or t < p[P_RPS_AT]:
        return p[P_RPS]
    frac = 1.0 if p[P_RPS_RAMP] == 0.0 else min((t - p[P_RPS_AT]) / p[P_RPS_RAMP], 1.0)
    return p[P_RPS] + frac * (p[P_RPS_TO] - p[P_RPS])


@numba.njit  # not cached on its own: see open_run
def closed_run(rhs, ctx, inp, p, dt, n_steps, s0, rk4, speed_lim, yaw_lim, states, rudder):
    """One closed-loop manoeuvre of parameters ``p``: each step the rudder command through the
    steering machine, the state recorded, then one step with δ and the propeller speed set in
    ``inp`` (the buffer ``rhs`` reads). states (N, 6), rudder (N,); returns the valid samples."""
    st = (s0[0], s0[1], s0[2], s0[3], s0[4], s0[5])
    delta = p[P_HELD]
    side = p[P_SIDE]
    integral = 0.0
    inp[2] = p[P_THRUST]
    follow = p[P_MODE] == MODE_FOLLOW
    target, leg = p[P_VALUE], 0.0
    for k in range(n_steps):
        if follow:
            target, _, leg, _ = line_of_sight(p, st[4], st[5], leg)
        cmd, side, integral = command(p, k * dt, st[3], st[2], target, side, integral, dt)
        delta = steer(delta, cmd, dt, p[P_MAX_ANGLE], p[P_MAX_RATE], p[P_TIME_CONST])
        for j in range(6):
            states[k, j] = st[j]
        rudder[k] = delta
        if k == n_steps - 1:
            break
        inp[0] = delta
        inp[1] = propeller(p, k * dt)
        new = step(rhs, ctx, st, dt, rk4)
        if not _ok(new, speed_lim, yaw_lim):
            return k + 1
        st = new
    return n_steps


@numba.njit(cache=True, parallel=True)
def integrate_closed(theta, rows, sig, op, kk, pw, rud, derived, dt, n_steps, s0, params, rk4,
                     speed_lim, yaw_lim, states, rudder, n_valid):  # fmt: skip
    """Closed-loop manoeuvres: states (B, N, 6), rudder (B, N), n_valid (B,)."""
    for b in numba.prange(theta.shape[0]):
        p = params[b]
        # Still air is wind too: the apparent wind of the ship's own motion.
        ctx = _terms_ctx(theta[b], rows, sig, op, kk, pw, rud, derived, True, p[P_WIND_SPEED],
                         p[P_WIND_DIR])  # fmt: skip
        if ctx[13] == SLOTS_CROSSFLOW:
            n_valid[b] = closed_run(_kernel.terms_rhs_crossflow, ctx, ctx[8], p, dt, n_steps,
                                    s0[b], rk4, speed_lim[b], yaw_lim[b], states[b], rudder[b])
        elif ctx[13] == SLOTS_RUDDER:
            n_valid[b] = closed_run(_kernel.terms_rhs_rudder, ctx, ctx[8], p, dt, n_steps,
                                    s0[b], rk4, speed_lim[b], yaw_lim[b], states[b], rudder[b])
        else:
            n_valid[b] = closed_run(_kernel.terms_rhs, ctx, ctx[8], p, dt, n_steps, s0[b], rk4,
                                    speed_lim[b], yaw_lim[b], states[b], rudder[b])  # fmt: skip


@numba.njit(cache=True)
def corrected_rhs(ctx, u, v, r, psi):
    """A reference ship's state derivative plus a correction's terms (``shipid correct``); ctx =
    (inputs, the reference's ``rhs``, its context, the terms' context, which share the input
    buffer). A correction's terms are in u, v, r, δ and the wind: the hull's cross-flow drag
    may be among them, the rudder's normal force (its propeller's inflow) not. Two ways, not
    ``terms_rhs_any``'s three: half the compilation."""
    a0, a1, a2, rd, xd, yd = ctx[1](ctx[2], u, v, r, psi)
    if ctx[3][13] == SLOTS_CROSSFLOW:
        b0, b1, b2, _, _, _ = terms_rhs_crossflow(ctx[3], u, v, r, psi)
    else:
        b0, b1, b2, _, _, _ = terms_rhs(ctx[3], u, v, r, psi)
    return a0 + b0, a1 + b1, a2 + b2, rd, xd, yd


# Inlined into each ship's entries (``shipid.vessels``), which hand on their own ``rhs``: a
# function passed on through two calls would make numba refuse to cache the caller.
@numba.njit(cache=True, inline="always")
def open_corrected_runs(rhs, extra, terms, t, inputs, n_steps, s0, rk4, speed_lim, yaw_lim, out,
                        n_valid):  # fmt: skip
    """Free runs of a reference ship (``rhs``, its context the input buffer and ``extra``) plus
    a correction's terms (``terms``: θ (3, T), its factor table and ``derived``)."""
    theta, rows, sig, op, kk, pw, rud, derived = terms
    for b in range(inputs.shape[0]):
        own = _terms_ctx(theta, rows, sig, op, kk, pw, rud, derived, False, 0.0, 0.0)
        inp = own[8]
        n_valid[b] = open_run(_kernel.corrected_rhs, (inp, rhs, (inp,) + extra, own), inp, t,
                              inputs[b], n_steps[b], s0[b], rk4, speed_lim[b], yaw_lim[b],
                              out[b])  # fmt: skip


@numba.njit(cache=True, inline="always")
def closed_corrected_runs(rhs, extra, terms, windy, dt, n_steps, s0, params, rk4, speed_lim,
                          yaw_lim, states, rudder, n_valid):  # fmt: skip
    """Closed-loop manoeuvres of a reference ship plus a correction's terms
    (``open_corrected_runs``), in the true wind of each row of ``params`` where the correction
    has wind terms (``windy``): the reference ships model none, so the terms meet it as the
    relative wind of the ship's own motion, as a term model's do; without such terms it is not
    computed at every evaluation."""
    theta, rows, sig, op, kk, pw, rud, derived = terms
    for b in range(params.shape[0]):
        p = params[b]
        own = _terms_ctx(theta, rows, sig, op, kk, pw, rud, derived, windy, p[P_WIND_SPEED],
                         p[P_WIND_DIR])  # fmt: skip
        inp = own[8]
        n_valid[b] = closed_run(_kernel.corrected_rhs, (inp, rhs, (inp,) + extra, own), inp, p,
                                dt, n_steps, s0[b], rk4, speed_lim[b], yaw_lim[b], states[b],
                                rudder[b])  # fmt: skip


@numba.njit(cache=True)
def accelerations(theta, rows, sig, op, kk, pw, rud, derived, states, inputs, out):
    """(M, 3) accelerations of one coefficient set θ (3, T) at states (M, 3) and inputs (M, 5):
    the compiled evaluation, checked against ``term_matrix`` by the tests."""
    ctx = _terms_ctx(theta, rows, sig, op, kk, pw, rud, derived, False, 0.0, 0.0)
    inp = ctx[8]
    for i in range(states.shape[0]):
        for j in range(N_INPUTS):
            inp[j] = inputs[i, j]
        u, v, r = states[i, 0], states[i, 1], states[i, 2]
        if ctx[13] == SLOTS_CROSSFLOW:
            a = terms_rhs_crossflow(ctx, u, v, r, 0.0)
        elif ctx[13] == SLOTS_RUDDER:
            a = terms_rhs_rudder(ctx, u, v, r, 0.0)
        else:
            a = terms_rhs(ctx, u, v, r, 0.0)
        out[i, 0], out[i, 1], out[i, 2] = a[0], a[1], a[2]
