"""IMO/ITTC manoeuvring indices from any log, measured or simulated (manoeuvring-standards.md §7).

Event times (heading crossings) are interpolated between the bracketing samples. Headings are
unwrapped and taken relative to ψ0, the mean heading over the approach (up to the rudder order).
Angles in the returned dictionaries are in degrees where the key says ``_deg``; everything else SI.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.integrate import cumulative_trapezoid

from shipid.data.trim import first_swing_index

MANOEUVRE_KINDS = ("zigzag", "turning")


def track(log: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unwrapped heading and earth-fixed position; dead-reckoned from u, v, r where absent."""
    t = log["t"].to_numpy()
    if "psi" in log.columns:
        psi = np.unwrap(log["psi"].to_numpy())
    else:
        psi = cumulative_trapezoid(log["r"].to_numpy(), t, initial=0.0)
    if "x" in log.columns and "y" in log.columns:
        return psi, log["x"].to_numpy(), log["y"].to_numpy()
    u, v = log["u"].to_numpy(), log["v"].to_numpy()
    xd = u * np.cos(psi) - v * np.sin(psi)
    yd = u * np.sin(psi) + v * np.cos(psi)
    return psi, cumulative_trapezoid(xd, t, initial=0.0), cumulative_trapezoid(yd, t, initial=0.0)


def rudder_order_index(delta: np.ndarray, threshold: float = math.radians(0.5)) -> int:
    """Index of the rudder order: the last sample before the rudder leaves its initial angle."""
    moved = np.flatnonzero(np.abs(delta - delta[0]) > threshold)
    if moved.size == 0:
        return 0
    return max(int(moved[0]) - 1, 0)


def _smooth(x: np.ndarray, t: np.ndarray, window_s: float) -> np.ndarray:
    if window_s <= 0:
        return x
    n = max(1, int(round(window_s / np.median(np.diff(t)))))
    if n < 2:
        return x
    kernel = np.ones(n) / n
    pad = np.pad(x, (n // 2, n - 1 - n // 2), mode="edge")
    return np.convolve(pad, kernel, mode="valid")


def _crossing_time(t: np.ndarray, y: np.ndarray, level: float, start: int) -> tuple[float, int]:
    """First time ≥ t[start] at which y rises through ``level`` (linear interpolation)."""
    above = np.flatnonzero(y[start:] >= level)
    if above.size == 0:
        return math.nan, -1
    k = start + int(above[0])
    if k == 0 or y[k - 1] >= level:
        return float(t[k]), k
    frac = (level - y[k - 1]) / (y[k] - y[k - 1])
    return float(t[k - 1] + frac * (t[k] - t[k - 1])), k


def _interp(t: np.ndarray, values: np.ndarray, at: float) -> float:
    return float(np.interp(at, t, values)) if math.isfinite(at) else math.nan


def execute_index(log: pd.DataFrame) -> int:
    """Index of the rudder execute: the start of the first swing that takes the rudder at least
    halfway to its largest deflection (``preprocess.first_swing_index``), so that small helm
    corrections of a hand-steered approach are not taken for the execute."""
    return first_swing_index(log["delta"].to_numpy())


def _reference(log: pd.DataFrame, t_order: float | None):
    t = log["t"].to_numpy()
    delta = log["delta"].to_numpy()
    i0 = execute_index(log) if t_order is None else int(np.searchsorted(t, t_order))
    i0 = min(i0, len(t) - 1)
    psi, x, y = track(log)
    psi0 = float(np.mean(psi[: i0 + 1]))
    return t, delta, i0, psi, x, y, psi0


def _none_if_nan(d: dict) -> dict:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}


def zigzag_indices(
    log: pd.DataFrame,
    heading_deg: float | None = None,
    t_order: float | None = None,
    smooth_s: float = 0.0,
    length: float | None = None,
) -> dict:
    """Overshoot angles, initial turning time and time to check yaw of a δ/ψ zig-zag.

    ``heading_deg`` is the switch heading ψ; when None it is inferred from the heading at the
    rudder reversals. ``smooth_s`` is a moving-average window on the heading (noisy logs).
    """
    t, delta, i0, psi, x, y, psi0 = _reference(log, t_order)
    dpsi = _smooth(psi - psi0, t, smooth_s)
    if heading_deg is None:
        heading_deg = _inferred_switch_deg(delta, dpsi, i0)
    nan = math.nan
    result = {"switch_heading_deg": heading_deg if heading_deg is not None else nan,
              "first_overshoot_deg": nan, "second_overshoot_deg": nan,
              "initial_turning_time": nan, "time_to_check_yaw": nan,
              "distance_to_second_execute": nan, "first_execute_time": float(t[i0])}  # fmt: skip
    if heading_deg is None or heading_deg <= 0:
        return _none_if_nan(result)
    switch = math.radians(heading_deg)
    # First turning direction: the side on which the heading first reaches the switch angle.
    t_pos, _ = _crossing_time(t, dpsi, switch, i0)
    t_neg, _ = _crossing_time(t, -dpsi, switch, i0)
    if math.isnan(t_pos) and math.isnan(t_neg):
        return _none_if_nan(result)
    side = 1.0 if (math.isnan(t_neg) or (not math.isnan(t_pos) and t_pos <= t_neg)) else -1.0
    executes = [(float(t[i0]), i0, side)]
    while True:
        _, k_prev, s = executes[-1]
        te, k = _crossing_time(t, s * dpsi, switch, k_prev)
        if k < 0:
            break
        executes.append((te, k, -s))
    if len(executes) >= 2:
        result["initial_turning_time"] = executes[1][0] - executes[0][0]
        seg = slice(i0, executes[1][1] + 1)
        result["distance_to_second_execute"] = float(np.sum(np.hypot(np.diff(x[seg]),
                                                                      np.diff(y[seg]))))
    keys = ("first_overshoot_deg", "second_overshoot_deg")
    for j, key in enumerate(keys, start=1):
        if j >= len(executes):
            break
        _, k_start, _ = executes[j]
        s = executes[j - 1][2]  # still turning the way the previous rudder sent it
        k_end = executes[j + 1][1] if j + 1 < len(executes) else len(t) - 1
        window = s * dpsi[k_start : k_end + 1]
        k_max = int(np.argmax(window))
        if k_start + k_max >= len(t) - 1:
            break  # the heading had not turned back before the log ended
        result[key] = math.degrees(window[k_max]) - heading_deg
        if j == 1:
            result["time_to_check_yaw"] = float(t[k_start + k_max]) - executes[1][0]
    if length:
        result["distance_to_second_execute_L"] = result["distance_to_second_execute"] / length
    return _none_if_nan(result)


def neutral_rudder(delta: np.ndarray) -> float:
    """Mid-range of the rudder: the neutral of a zig-zag whatever side the log starts on."""
    return 0.5 * (float(np.max(delta)) + float(np.min(delta)))


def _inferred_switch_deg(delta: np.ndarray, dpsi: np.ndarray, i0: int) -> float | None:
    """Switch heading from the heading at the rudder reversals, read where each swing *starts*
    (the order), not where the rudder crosses neutral: a slow rudder crosses it well past ψ."""
    d = delta[i0:]
    dev = d - neutral_rudder(d)
    side = np.sign(dev)
    side[np.abs(dev) < math.radians(1.0)] = 0
    nz = np.flatnonzero(side)
    if nz.size < 2:
        return None
    flips = nz[1:][side[nz[1:]] != side[nz[:-1]]]
    starts = []
    for f in flips:
        before = np.flatnonzero(side[:f] == -side[f])
        seg = d[before]
        plateau = seg[np.argmax(np.abs(dev[before]))]
        near = before[np.abs(seg - plateau) <= math.radians(0.5)]
        starts.append(int(near[-1]) if near.size else int(f))
    if not starts:
        return None
    # The order fell between the last plateau sample and the next one: take their midpoint.
    k = i0 + np.array(starts)
    at_order = 0.5 * (np.abs(dpsi[k]) + np.abs(dpsi[np.minimum(k + 1, len(dpsi) - 1)]))
    return float(np.median(np.degrees(at_order)))


def turning_indices(
    log: pd.DataFrame, t_order: float | None = None, length: float | None = None
) -> dict:
    """Advance, transfer, tactical diameter, steady turning diameter, speed and yaw rate."""
    t, delta, i0, psi, x, y, psi0 = _reference(log, t_order)
    dpsi = psi - psi0
    side = 1.0 if dpsi[-1] >= 0 else -1.0
    turned = side * dpsi
    e_c = np.array([math.cos(psi0), math.sin(psi0)])
    e_n = np.array([-math.sin(psi0), math.cos(psi0)])
    p0 = np.array([x[i0], y[i0]])
    t90, _ = _crossing_time(t, turned, math.pi / 2, i0)
    t180, _ = _crossing_time(t, turned, math.pi, i0)
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
    result.update(_steady_turn(log, t, turned, x, y))
    if length:
        for k in ("advance", "transfer", "tactical_diameter", "steady_turning_diameter"):
            result[f"{k}_L"] = result[k] / length
    return _none_if_nan(result)


def _steady_turn(log, t, turned, x, y) -> dict:
    """Steady turn: the last 360° of heading change after the first 360° (or after 180° when the
    log is shorter): circle fit to the track when the window spans ≥ 270°, else 2U/|r|."""
    final = turned[-1]
    start = max(360.0, math.degrees(final) - 360.0) if math.degrees(final) >= 540.0 else 180.0
    win = turned >= math.radians(start)
    nan = math.nan
    if win.sum() < 3:
        return {"steady_turning_diameter": nan, "steady_speed": nan, "steady_yaw_rate": nan}
    u, v, r = (log[c].to_numpy()[win] for c in ("u", "v", "r"))
    speed = float(np.mean(np.hypot(u, v)))
    yaw_rate = float(np.mean(r))
    span = math.degrees(turned[win][-1] - turned[win][0])
    if span >= 270.0:
        diameter = 2.0 * _circle_fit_radius(x[win], y[win])
    else:
        diameter = float(np.mean(2.0 * np.hypot(u, v) / np.abs(r)))
    return {"steady_turning_diameter": diameter, "steady_speed": speed, "steady_yaw_rate": yaw_rate}


def _circle_fit_radius(x: np.ndarray, y: np.ndarray) -> float:
    """Algebraic (Kåsa) least-squares circle fit."""
    A = np.column_stack([x, y, np.ones_like(x)])
    b = x * x + y * y
    cx2, cy2, c = np.linalg.lstsq(A, b, rcond=None)[0]
    cx, cy = cx2 / 2, cy2 / 2
    return float(math.sqrt(c + cx * cx + cy * cy))


def detect_manoeuvre(log: pd.DataFrame) -> str | None:
    """'turning' when the heading changes by ≥ 180° (no zig-zag does), 'zigzag' when the rudder
    swings from side to side at least twice, else None. A swing takes the rudder at least halfway
    from the neutral (mid-range) to its largest deflection: helm corrections do not count."""
    delta = log["delta"].to_numpy()
    i0 = rudder_order_index(delta)
    psi, _, _ = track(log)
    if np.max(np.abs(psi - psi[i0])) >= math.pi:
        return "turning"
    dev = delta - neutral_rudder(delta)
    big = np.abs(dev) >= max(0.5 * float(np.max(np.abs(dev))), math.radians(1.0))
    side = np.sign(dev[big])
    if side.size and np.count_nonzero(side[1:] != side[:-1]) >= 2:
        return "zigzag"
    return None


def manoeuvre_indices(
    log: pd.DataFrame,
    kind: str | None = None,
    heading_deg: float | None = None,
    length: float | None = None,
    smooth_s: float = 0.0,
) -> dict:
    """Indices of a log, the manoeuvre detected when ``kind`` is None ({} if none is detected)."""
    kind = kind or detect_manoeuvre(log)
    if kind is None:
        return {}
    if kind == "zigzag":
        out = zigzag_indices(log, heading_deg=heading_deg, smooth_s=smooth_s, length=length)
    elif kind == "turning":
        out = turning_indices(log, length=length)
    else:
        raise ValueError(f"manoeuvre kind must be one of {MANOEUVRE_KINDS}, got {kind!r}")
    return {"kind": kind, **out}
