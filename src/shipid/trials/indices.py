"""IMO/ITTC manoeuvring indices from any log, measured or simulated (manoeuvring-standards.md §7).

Event times (heading crossings) are interpolated between the bracketing samples. Headings are
unwrapped and taken relative to ψ0, the mean heading over the approach (up to the rudder order).
Angles in the returned dictionaries are in degrees where the key says ``_deg``; everything else SI.
Every function is linear in the length of the log.

Positions: measured positions carry metres of noise, velocities centimetres per second. The track
(``track``) is the measured positions smoothed with the velocities (a Rauch–Tung–Striebel smoother
whose noise levels are estimated from the log itself), dead reckoning from u, v, ψ where the log
has no positions. Track lengths are integrals of the speed √(u² + v²), which noise barely biases.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from shipid.data.log import column_values, log_name
from shipid.data.preprocess import cumulative_integral, gap_text, time_gaps, white_noise_variance
from shipid.errors import ShipidError
from shipid.trials.trial import (
    KINDS,
    TURN_KINDS,
    Trial,
    describe_trial,
    moving_average,
    unwrapped_heading,
)

MANOEUVRE_KINDS = KINDS
# Fraction of the steady yaw rate within which r counts as settled in a held turn.
SETTLED_RATE = 0.05


# ---------------------------------------------------------------------------- the track
_compiled_rts = None


def _rts_smooth(z: np.ndarray, w: np.ndarray, R: float, q: float) -> np.ndarray:
    """``_rts_smooth_loop`` compiled by numba on first use (cached on disk like every kernel):
    a zig-zag's indices need no track, and ``shipid indices`` of one no longer pays numba's
    import (0.25 s of its 0.52 s)."""
    global _compiled_rts
    if _compiled_rts is None:
        import numba

        _compiled_rts = numba.njit(cache=True)(_rts_smooth_loop)
    return _compiled_rts(z, w, R, q)


def _rts_smooth_loop(z: np.ndarray, w: np.ndarray, R: float, q: float) -> np.ndarray:
    """Smoothed positions of p_{k+1} = p_k + w_k + η (var q), z_k = p_k + ε (var R); z (N, 2)."""
    n = z.shape[0]
    pf = np.empty_like(z)
    pp = np.empty_like(z)
    Pf = np.empty(n)
    Pp = np.empty(n)
    pp[0] = z[0]
    Pp[0] = 1e6 * R + 1e-12
    for k in range(n):
        K = Pp[k] / (Pp[k] + R)
        pf[k] = pp[k] + K * (z[k] - pp[k])
        Pf[k] = (1.0 - K) * Pp[k]
        if k + 1 < n:
            pp[k + 1] = pf[k] + w[k]
            Pp[k + 1] = Pf[k] + q
    out = np.empty_like(z)
    out[n - 1] = pf[n - 1]
    for k in range(n - 2, -1, -1):
        G = Pf[k] / Pp[k + 1] if Pp[k + 1] > 0 else 0.0
        out[k] = pf[k] + G * (out[k + 1] - pp[k + 1])
    return out

# Where and how an index was measured (the switch heading, the execute time, the span of the
# steady turn), not a property of the ship: no interval is drawn over them.
BOOKKEEPING = ("switch_heading_deg", "first_execute_time", "steady_from", "steady_to",
               "release_time")  # fmt: skip


def smoothed_positions(t, x, y, u, v, psi) -> tuple[np.ndarray, np.ndarray]:
    """Positions smoothed with the velocity-integrated increments (see module docstring).

    Position noise R from the one-step innovations d_k = Δz_k − w_k (Cov(d_k, d_k+1) = −R);
    increment noise q from the velocities' own white noise (their second differences), which the
    innovations cannot resolve under metres of position noise. A constant drift of d (a current)
    is kept in the increments."""
    xd = u * np.cos(psi) - v * np.sin(psi)
    yd = u * np.sin(psi) + v * np.cos(psi)
    h = np.diff(t)
    if len(t) < 4:
        return x, y
    w = np.column_stack([0.5 * (xd[1:] + xd[:-1]) * h, 0.5 * (yd[1:] + yd[:-1]) * h])
    z = np.column_stack([x, y]).astype(float)
    d = np.diff(z, axis=0) - w
    drift = d.mean(axis=0)
    w = w + drift
    d = d - drift
    var = float(np.mean(d * d))
    R = max(-float(np.mean(d[1:] * d[:-1])), 0.0)
    if R <= 1e-9 * max(var, 1e-30):
        return x, y  # positions as precise as the increments: keep them
    h2 = float(np.median(h)) ** 2
    q_velocity = 0.5 * h2 * 0.5 * (white_noise_variance(xd) + white_noise_variance(yd))
    # Var d − 2R is q only where it stands out of its own sampling error (≈ var·√(2/N)).
    q_moment = var - 2.0 * R
    if q_moment < 3.0 * var * math.sqrt(2.0 / d.size):
        q_moment = 0.0
    q = max(q_moment, q_velocity, 1e-9 * R)
    out = _rts_smooth(np.ascontiguousarray(z), np.ascontiguousarray(w), R, q)
    return out[:, 0], out[:, 1]


def track(log: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unwrapped heading and earth-fixed position (smoothed; dead-reckoned where absent)."""
    t = column_values(log, "t")
    psi = unwrapped_heading(log)
    u, v = column_values(log, "u"), column_values(log, "v")
    if "x" in log.columns and "y" in log.columns:
        x, y = smoothed_positions(t, column_values(log, "x"), column_values(log, "y"), u, v, psi)
        return psi, x, y
    xd = u * np.cos(psi) - v * np.sin(psi)
    yd = u * np.sin(psi) + v * np.cos(psi)
    return psi, cumulative_integral(xd, t, initial=0.0), cumulative_integral(yd, t, initial=0.0)


def travelled(log: pd.DataFrame) -> np.ndarray:
    """Distance along the track from the first sample: ∫ √(u² + v²) dt."""
    speed = np.hypot(column_values(log, "u"), column_values(log, "v"))
    return cumulative_integral(speed, column_values(log, "t"), initial=0.0)


# ---------------------------------------------------------------------------- events
def smooth_heading(x: np.ndarray, t: np.ndarray, window_s: float) -> np.ndarray:
    """Centred moving average over ``window_s`` seconds (``moving_average``)."""
    if not (math.isfinite(window_s) and window_s >= 0):
        raise ShipidError(f"--smooth must be a finite number of seconds ≥ 0, got {window_s!r}")
    if window_s == 0:
        return x
    span = float(t[-1] - t[0])
    if window_s >= span:
        raise ShipidError(f"--smooth {window_s:g} s is not shorter than the log ({span:.4g} s)")
    n = max(1, int(round(window_s / np.median(np.diff(t)))))
    return x if n < 2 else moving_average(x, n)


def _crossings(y: np.ndarray, level: float) -> np.ndarray:
    """Indices k ≥ 1 where y rises through ``level`` between k − 1 and k (k = 0 if it starts at it)."""
    up = np.flatnonzero((y[:-1] < level) & (y[1:] >= level)) + 1
    return np.concatenate([[0], up]) if y[0] >= level else up


def _event_time(t: np.ndarray, y: np.ndarray, level: float, k: int, sign: float = 1.0) -> float:
    """Time at which sign·y reaches ``level`` between samples k − 1 and k (interpolated)."""
    if k == 0 or sign * y[k - 1] >= level:
        return float(t[k])
    a, b = sign * y[k - 1], sign * y[k]
    frac = (level - a) / (b - a)
    return float(t[k - 1] + frac * (t[k] - t[k - 1]))


def _first_crossing(t, y, level, start) -> tuple[float, int]:
    """First time ≥ t[start] at which y reaches ``level`` (interpolated), and its sample."""
    if y[start] >= level:
        return float(t[start]), start
    ks = _crossings(y, level)
    ks = ks[ks > start]
    if ks.size == 0:
        return math.nan, -1
    k = int(ks[0])
    return _event_time(t, y, level, k), k


def _interp(t: np.ndarray, values: np.ndarray, at: float) -> float:
    return float(np.interp(at, t, values)) if math.isfinite(at) else math.nan


def _none_if_nan(d: dict) -> dict:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}


# ---------------------------------------------------------------------------- zig-zag
def zigzag_indices(
    log: pd.DataFrame,
    heading_deg: float | None = None,
    t_order: float | None = None,
    smooth_s: float = 0.0,
    length: float | None = None,
    trial: Trial | None = None,
) -> dict:
    """Overshoot angles, initial turning time, time to check yaw and the track length to the
    second execute of a δ/ψ zig-zag.

    ``heading_deg`` is the switch heading ψ; when None it is inferred from the heading at the
    rudder orders. ``smooth_s`` is a moving-average window on the heading (noisy logs).
    """
    if trial is None:
        trial = describe_trial(log, "zigzag", heading_deg, t_order, indices_only=True)
    t = column_values(log, "t")
    i0 = trial.execute_index
    dpsi = smooth_heading(unwrapped_heading(log) - trial.psi0, t, smooth_s)
    heading = heading_deg if heading_deg is not None else trial.switch_heading_deg
    nan = math.nan
    result = {"switch_heading_deg": heading if heading is not None else nan,
              "first_overshoot_deg": nan, "second_overshoot_deg": nan,
              "initial_turning_time": nan, "time_to_check_yaw": nan,
              "distance_to_second_execute": nan, "first_execute_time": float(t[i0])}  # fmt: skip
    if heading is None or not heading > 0:
        return _none_if_nan(result)
    switch = math.radians(heading)
    up = _crossings(dpsi, switch)
    down = _crossings(-dpsi, switch)
    up, down = up[up >= i0], down[down >= i0]
    if up.size == 0 and down.size == 0:
        return _none_if_nan(result)
    # First turning direction: the side on which the heading first reaches the switch angle.
    side = 1.0 if down.size == 0 or (up.size and up[0] <= down[0]) else -1.0
    executes = [(float(t[i0]), i0, side)]
    # The indices need the first four executes (the second overshoot ends at the fourth); a
    # long log's hundreds of reversals after them cost a Python step each.
    while len(executes) < 4:
        _, k_prev, s = executes[-1]
        ks = up if s > 0 else down
        j = int(np.searchsorted(ks, k_prev))
        if j >= ks.size:
            break
        k = int(ks[j])
        executes.append((_event_time(t, dpsi, switch, k, s), k, -s))
    if len(executes) >= 2:
        result["initial_turning_time"] = executes[1][0] - executes[0][0]
        dist = travelled(log)
        result["distance_to_second_execute"] = _interp(t, dist, executes[1][0]) - float(dist[i0])
    for j, key in enumerate(("first_overshoot_deg", "second_overshoot_deg"), start=1):
        if j >= len(executes):
            break
        _, k_start, _ = executes[j]
        s = executes[j - 1][2]  # still turning the way the previous rudder sent it
        k_end = executes[j + 1][1] if j + 1 < len(executes) else len(t) - 1
        window = s * dpsi[k_start : k_end + 1]
        k_max = int(np.argmax(window))
        if k_start + k_max >= len(t) - 1:
            break  # the heading had not turned back before the log ended
        result[key] = math.degrees(window[k_max]) - heading
        if j == 1:
            result["time_to_check_yaw"] = float(t[k_start + k_max]) - executes[1][0]
    if length:
        result["distance_to_second_execute_L"] = result["distance_to_second_execute"] / length
    return _none_if_nan(result)


# ---------------------------------------------------------------------------- turning circle
def turning_indices(
    log: pd.DataFrame,
    t_order: float | None = None,
    length: float | None = None,
    trial: Trial | None = None,
) -> dict:
    """Advance, transfer, tactical diameter, times to 90° and 180°, and the steady turn
    (diameter, speed and yaw rate over the span with the rudder held and r settled)."""
    if trial is None:
        trial = describe_trial(log, "turning", t_order=t_order, indices_only=True)
    t = column_values(log, "t")
    i0 = trial.execute_index
    psi, x, y = track(log)
    dpsi = psi - trial.psi0
    held = slice(i0, trial.held_end_index + 1)
    side = 1.0 if dpsi[held][-1] >= 0 else -1.0
    turned = side * dpsi
    psi0 = trial.psi0
    e_c = np.array([math.cos(psi0), math.sin(psi0)])
    e_n = np.array([-math.sin(psi0), math.cos(psi0)])
    p0 = np.array([x[i0], y[i0]])
    t90, _ = _first_crossing(t, turned, math.pi / 2, i0)
    t180, _ = _first_crossing(t, turned, math.pi, i0)
    p90 = np.array([_interp(t, x, t90), _interp(t, y, t90)]) - p0
    p180 = np.array([_interp(t, x, t180), _interp(t, y, t180)]) - p0
    result = {
        "advance": float(p90 @ e_c),
        "transfer": float(abs(p90 @ e_n)),
        "tactical_diameter": float(abs(p180 @ e_n)),
        "time_to_90": t90 - float(t[i0]),
        "time_to_180": t180 - float(t[i0]),
        "turn_direction": "starboard" if side > 0 else "port",
    }
    result.update(_steady_turn(log, t, turned, x, y, i0, trial.held_end_index))
    if length:
        for k in ("advance", "transfer", "tactical_diameter", "steady_turning_diameter"):
            result[f"{k}_L"] = result[k] / length
    return _none_if_nan(result)


def _steady_turn(log, t, turned, x, y, i0: int, held_end: int) -> dict:
    """Steady turn over the held rudder only (a measured turn often ends with a pull-out): past
    180° of heading change, from where the yaw rate has settled (its trailing mean within 5 % of
    the final value) to the end of the held phase, the last 360° when more is available. Circle
    fit to the track when the span covers ≥ 270°, else 2U/|r|. ``steady_from``/``steady_to`` say
    which span was used."""
    nan = math.nan
    empty = {"steady_turning_diameter": nan, "steady_speed": nan, "steady_yaw_rate": nan,
             "steady_from": nan, "steady_to": nan}  # fmt: skip
    r = column_values(log, "r")
    k1 = held_end
    past180 = np.flatnonzero(turned[i0 : k1 + 1] >= math.pi)
    if past180.size == 0 or k1 - (i0 + int(past180[0])) < 3:
        return empty
    k0 = i0 + int(past180[0])
    n = k1 - k0 + 1
    w = max(3, n // 10)
    c = np.concatenate([[0.0], np.cumsum(r[k0 : k1 + 1])])
    trailing = (c[w:] - c[:-w]) / w  # mean of r over the w samples ending at k0 + w − 1 + i
    final = float(trailing[-1])
    off = np.flatnonzero(np.abs(trailing - final) > SETTLED_RATE * abs(final))
    if off.size and off[-1] + w < n - w:
        k0 += int(off[-1]) + 1
    lo = turned[k1] - 2 * math.pi
    if turned[k0] < lo:
        k0 += int(np.searchsorted(turned[k0 : k1 + 1], lo))  # the last 360°
    win = slice(k0, k1 + 1)
    u, v, rr = column_values(log, "u")[win], column_values(log, "v")[win], r[win]
    speed = float(np.mean(np.hypot(u, v)))
    yaw_rate = float(np.mean(rr))
    span = math.degrees(turned[k1] - turned[k0])
    if span >= 270.0:
        diameter = 2.0 * _circle_fit_radius(x[win], y[win])
    else:
        diameter = float(2.0 * speed / abs(yaw_rate)) if yaw_rate != 0 else nan
    return {"steady_turning_diameter": diameter, "steady_speed": speed,
            "steady_yaw_rate": yaw_rate, "steady_from": float(t[k0]),
            "steady_to": float(t[k1])}  # fmt: skip


def _circle_fit_radius(x: np.ndarray, y: np.ndarray) -> float:
    """Algebraic (Kåsa) least-squares circle fit."""
    xm, ym = float(np.mean(x)), float(np.mean(y))
    xc, yc = x - xm, y - ym  # centred: keeps the fit accurate far from the origin
    A = np.column_stack([xc, yc, np.ones_like(xc)])
    b = xc * xc + yc * yc
    cx2, cy2, c = np.linalg.lstsq(A, b, rcond=None)[0]
    cx, cy = cx2 / 2, cy2 / 2
    return float(math.sqrt(max(c + cx * cx + cy * cy, 0.0)))


# ---------------------------------------------------------------------------- pull-out
# The yaw rates at the release and at the end: means over the last share of the held and the
# released spans (a noisy log's one sample is one sample of noise).
RELEASE_SHARE = 0.05


def pull_out_yaw_rates(t: np.ndarray, r: np.ndarray, t_release: float, t_order: float = 0.0
                       ) -> dict:  # fmt: skip
    """The yaw rate at the release (the mean over the last 5 % of the rudder held from
    ``t_order``), the residual one at the end (over the last 5 % of the released span) and their
    ratio: a straight-line stable ship's residual goes to 0, an unstable one keeps turning
    (IMO MSC/Circ.1053, pull-out)."""
    held = np.flatnonzero((t >= t_order) & (t < t_release))
    released = np.flatnonzero(t >= t_release)
    at_release, residual = (
        float(np.mean(r[k[int((1.0 - RELEASE_SHARE) * k.size):]])) if k.size else math.nan
        for k in (held, released))  # fmt: skip
    return {"yaw_rate_at_release": at_release, "residual_yaw_rate": residual,
            "residual_fraction": residual / at_release if at_release else math.nan}


def pull_out_indices(
    log: pd.DataFrame,
    length: float | None = None,
    trial: Trial | None = None,
) -> dict:
    """A pull-out's held turn (``turning_indices``) and its release (``pull_out_yaw_rates``)."""
    if trial is None:
        trial = describe_trial(log, "pull-out", indices_only=True)
    out = turning_indices(log, length=length, trial=trial)
    if trial.release_time is not None:
        out["release_time"] = trial.release_time
        out.update(pull_out_yaw_rates(column_values(log, "t"), column_values(log, "r"),
                                      trial.release_time, trial.execute_time))  # fmt: skip
    return _none_if_nan(out)


# ---------------------------------------------------------------------------- any log
def detect_manoeuvre(log: pd.DataFrame) -> str:
    """'zigzag', 'turning', 'pull-out' or 'other' (see ``shipid.trials.trial``)."""
    return describe_trial(log).kind


def _refuse_gap_after_execute(log: pd.DataFrame, trial: Trial) -> None:
    """A manoeuvre's indices read the heading, rate and track after the execute: a gap in time
    there (``time_gaps``) hides an overshoot's peak or a turn's advance (a 20/20 zig-zag with 7 s
    missing read its first overshoot 23.5° for 27.4°)."""
    t = column_values(log, "t")
    gaps = [k for k in time_gaps(t) if k + 1 > trial.execute_index]
    if gaps:
        raise ShipidError(f"{log_name(log)}: {gap_text(t, gaps)}, after the {trial.kind}'s "
                          f"execute at t = {trial.execute_time:.6g}: its indices would miss what "
                          f"the ship did there; cut the log before it (--end {t[gaps[0]]:.6g})")


def manoeuvre_indices(
    log: pd.DataFrame,
    kind: str | None = None,
    heading_deg: float | None = None,
    length: float | None = None,
    smooth_s: float = 0.0,
    trial: Trial | None = None,
) -> dict:
    """Indices of a log, the manoeuvre detected when ``kind`` is None ({"kind": "other"} when the
    log is neither a zig-zag, a turning circle nor a pull-out)."""
    if trial is None:
        trial = describe_trial(log, kind, heading_deg)
    if trial.kind in ("zigzag", *TURN_KINDS):
        _refuse_gap_after_execute(log, trial)
    if trial.kind == "zigzag":
        out = zigzag_indices(log, heading_deg=heading_deg, smooth_s=smooth_s, length=length,
                             trial=trial)  # fmt: skip
    elif trial.kind == "turning":
        out = turning_indices(log, length=length, trial=trial)
    elif trial.kind == "pull-out":
        out = pull_out_indices(log, length=length, trial=trial)
    else:
        return {"kind": "other", "reason": trial.reason}
    return {"kind": trial.kind, **out}
