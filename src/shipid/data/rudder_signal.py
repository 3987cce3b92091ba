"""The rudder signal as the manoeuvre's events see it: white sensor noise removed.

A rudder angle sensor (a potentiometer read by an ADC) adds noise of a tenth of a degree or so.
The events of a manoeuvre are read off the rudder sample by sample: the execute is where the
rudder starts moving its way, a held rudder stays within a tolerance of its plateau, a zig-zag's
swings cross half their amplitude once. Noise breaks each of these: a held 35° turn became "the
rudder is not held", a zig-zag's swing split at the threshold into two, and the rudder rate read
from sample-to-sample steps measured the noise (24°/s from 0.5° of noise on a 5°/s rudder).

``rudder_for_events`` leaves a clean rudder as it is (simulated, or quantised like the Esso
Osaka's 0.56° and MARIN's 0.1° steps, whose second differences are mostly zero). A noisy one is
median-filtered over half a second (a median leaves a monotone ramp and its plateau untouched)
and then held until it moves by more than the filtered noise can (a dead band): plateaus become
constant and ramps monotone, as the events assume.
"""

from __future__ import annotations

import math

import numpy as np

# Below this the rudder is taken as clean (a resampled rudder's interpolation error, say).
NOISE_FLOOR = math.radians(0.01)
MEDIAN_WINDOW_S = 0.5
# Half-width of the dead band, in standard deviations of the median-filtered noise.
BAND_SIGMAS = 4.0


def stand_samples(t: np.ndarray, stand_s: float = 1.0) -> int:
    """Samples in ``stand_s`` seconds: the longest stand of the event rudder inside a swing."""
    return max(1, int(round(stand_s / float(np.median(np.diff(t))))))


def rudder_noise(delta: np.ndarray) -> float:
    """Standard deviation [rad] of white noise on the rudder, robustly: the median absolute
    second difference over √6 × 0.6745. Second differences vanish on a steering machine's ramps
    and plateaus, so its motion does not count; nor do quantisation steps (their median is 0)."""
    if delta.size < 5:
        return 0.0
    d2 = np.diff(delta, 2)
    return float(np.median(np.abs(d2 - np.median(d2))) / 0.6745 / math.sqrt(6.0))


def median_filtered(x: np.ndarray, window: int) -> np.ndarray:
    """Centred running median over ``window`` (odd) samples, the ends padded with the end values."""
    half = window // 2
    padded = np.concatenate([np.full(half, x[0]), x, np.full(half, x[-1])])
    return np.median(np.lib.stride_tricks.sliding_window_view(padded, window), axis=1)


def dead_band(x: np.ndarray, half_width: float) -> np.ndarray:
    """``x`` held at its last value until it moves by more than 2 × ``half_width`` from where the
    band last stood (a play operator, read at the band's centre): constant where ``x`` only
    wavers, equal to ``x`` where it moves on."""
    out = np.empty_like(x)
    band = x[0]  # the band's centre less the offset of the last move
    direction = 0.0
    for k, value in enumerate(x.tolist()):
        if value > band + half_width:
            band, direction = value - half_width, 1.0
        elif value < band - half_width:
            band, direction = value + half_width, -1.0
        out[k] = band + direction * half_width
    return out


def rudder_for_events(t: np.ndarray, delta: np.ndarray) -> tuple[np.ndarray, float]:
    """The rudder the events are read from, and the noise [rad] found on ``delta`` (0 when clean:
    ``delta`` itself is returned)."""
    sigma = rudder_noise(delta)
    if sigma <= NOISE_FLOOR:
        return delta, 0.0
    dt = float(np.median(np.diff(t)))
    window = max(3, 2 * int(round(0.5 * MEDIAN_WINDOW_S / dt)) + 1)
    smooth = median_filtered(delta, window)
    # A median of w samples of white noise has about 1.2533 σ / √w.
    residual = 1.2533 * sigma / math.sqrt(window)
    return dead_band(smooth, BAND_SIGMAS * residual), sigma


def ramp_line(t: np.ndarray, delta: np.ndarray, a: int, b: int) -> tuple[float, float] | None:
    """(rate [rad/s], angle at t = 0) of the ramp of the monotone swing from sample ``a`` to
    ``b``: the least-squares line through its samples within 10–90 % of the swing, which lie
    on the ramp wherever its corners fall between samples. The 10 % and 90 % points
    interpolated between samples do not where a sample moves more than a tenth of the swing:
    HSVA's 20/10 zig-zag resampled to 0.5 s read 15.54 °/s against 15.85 °/s at its own
    0.05 s (now 15.87 at both). None with fewer than two such samples."""
    seg = delta[a : b + 1]
    swing = float(seg[-1] - seg[0])
    if swing == 0.0:
        return None
    frac = (seg - seg[0]) / swing
    inside = (frac >= 0.1) & (frac <= 0.9)
    if np.count_nonzero(inside) < 2:
        return None
    tt, dd = t[a : b + 1][inside], seg[inside]
    tm = float(np.mean(tt))
    rate = float(np.sum((tt - tm) * (dd - np.mean(dd))) / np.sum((tt - tm) ** 2))
    return rate, float(np.mean(dd)) - rate * tm


def ramp_start(t: np.ndarray, delta: np.ndarray, a: int, b: int, level: float) -> float:
    """When the swing from sample ``a`` to ``b`` (monotone) left ``level`` (the measured rudder
    where it stood): its ramp (``ramp_line``) extended back, else the line through its 10 %
    and 90 % points. Noise blurs the corner itself, and the dead band's plateau creeps towards
    the highest noise."""
    line = ramp_line(t, delta, a, b)
    if line is not None and line[0] != 0.0:
        return float((level - line[1]) / line[0])
    s = 1.0 if delta[b] >= delta[a] else -1.0
    seg = s * delta[a : b + 1]
    swing = seg[-1] - seg[0]
    if swing <= 0:
        return float(t[a])
    low, high = seg[0] + 0.1 * swing, seg[0] + 0.9 * swing
    t10, t90 = np.interp([low, high], seg, t[a : b + 1])
    if t90 <= t10:
        return float(t10)
    return float(t10 - (low - s * level) * (t90 - t10) / (high - low))


def rise_rate(t: np.ndarray, delta: np.ndarray, hold_s: float = 1.0) -> float | None:
    """Rudder rate [rad/s] of a log's rudder (the event rudder of a noisy one): the median over
    its swings (runs of steps one way, a stand of ``hold_s`` or a reversal ending one) of the
    slope of its ramp (``ramp_line``). Steps between samples would measure the noise, or the
    quantisation: MARIN's rudder, to three digits at 50 Hz, steps by 0.3° or 0.4° at its
    15.7°/s, and the 90th percentile of its steps read 20°/s. A swing with fewer than two
    samples within 10–90 % of it counts its fastest step (a rate-limited gear moves at its
    limit between two samples)."""
    step = np.sign(np.diff(delta))
    edges = np.flatnonzero(step[1:] != step[:-1]) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges, [step.size]])  # run i covers steps starts[i] .. ends[i] - 1
    swings: list[list[int]] = []  # [first sample, last sample, direction]
    for a, b in zip(starts.tolist(), ends.tolist(), strict=True):
        s = int(step[a])
        if s == 0:
            continue
        last = swings[-1] if swings else None
        if last is not None and last[2] == s and t[a] - t[last[1]] < hold_s:
            last[1] = b  # a short stand inside the swing (the dead band waited)
        else:
            swings.append([a, b, s])
    rates = []
    for a, b, _ in swings:
        swing = abs(delta[b] - delta[a])
        if swing < math.radians(2.0):
            continue
        line = ramp_line(t, delta, a, b)
        if line is not None:
            rates.append(abs(line[0]))
        else:
            rates.append(float(np.max(np.abs(np.diff(delta[a : b + 1])) / np.diff(t[a : b + 1]))))
    return float(np.median(rates)) if rates else None
