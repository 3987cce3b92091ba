"""Body velocities from a GNSS: u, v (and r where it is not logged) from a position track x, y
or a speed and course over ground, and the heading ψ.

Many small craft log a GNSS position and a heading, not the surge and sway the model needs. The
earth-fixed velocity is the track's slope, read at every sample off a local quadratic fitted by
least squares to the samples within half a window either side (a Savitzky–Golay derivative on
the log's own time stamps, so jitter and gaps are allowed for; at the ends the window holds the
samples there are). It is turned into the body frame by ψ:

    u = ẋ cos ψ + ẏ sin ψ,   v = −ẋ sin ψ + ẏ cos ψ     (x north, y east, ψ clockwise from north)

A receiver's antenna at (a, b) in the body frame (forward, starboard of the log's reference point)
moves at u − r·b, v + r·a; both are corrected, and x, y moved to the reference point. Without it
a 1 m lever turning at 0.3 rad/s puts 0.3 m/s on v.

The heading and the track must share their axes, which nothing else in such a log can check. A
ship runs ahead along its heading, give or take its drift angle: where x and y swapped or ψ
counter-clockwise would put the track much closer to the heading, or the track runs on average
beyond ``MAX_MEDIAN_DRIFT_DEG`` from it (an offset heading), the log is refused. Where the
heading lies along the axis a mistake mirrors (45° for the swap, north for ψ) nothing can tell.

Where the receiver gives its speed and course over ground (SOG, COG: from the carrier's Doppler
shift, centimetres per second where a position's slope is decimetres), u, v are those turned by
ψ, with the same lever and checks (``velocities_from_ground_velocity``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shipid.data.log import column_values, frozen
from shipid.errors import ShipidError

# A GNSS's speed [m/s] and course [rad, clockwise from north] over ground, read instead of a track.
GROUND_VELOCITY_COLUMNS = ("sog", "cog")
# The window's default is chosen from the log (``plug_in_window``): at least this many samples,
# and at most this many seconds ...
MIN_WINDOW_SAMPLES = 7
MAX_WINDOW_S = 30.0
# ... from the track's third derivative, read over a pilot window from this many times the
# shortest.
PILOT_FACTOR = 4.0
# The drift angle atan2(v, u) is judged where the ship runs at this share of its 90th percentile of
# speed or more. Its median there, noise-free, over the reference ships' 10/10 and 20/20 zig-zags
# and 35° turns: Mariner 2.4–7.0°, KVLCC2 3.4–19°, CyberShip II 22–57° (a model ship at 0.3 m/s).
RUNNING_SHARE = 0.5
# With x and y swapped or ψ counter-clockwise the median drift of those logs is 19–160°, but as
# little as the true one where the heading lies along the axis the mistake mirrors (45° for the
# swap, north for ψ): another convention is named only where its median drift is below this share
# of the given one's, and only beyond MIN_DRIFT_TO_JUDGE_DEG ...
ALTERNATIVE_SHARE = 0.5
MIN_DRIFT_TO_JUDGE_DEG = 15.0
# ... and a heading that is offset (from east, astern) runs at 90° and more from the track.
MAX_MEDIAN_DRIFT_DEG = 75.0
# A heading in degrees read as radians turns 57 times as far as the track's course. Heading and
# course changes over 10 s windows have an rms ratio of 0.86-1.10 on the reference ships' 10/10
# and 20/20 zig-zags and 35° turns (CyberShip II, the paper's ship, Mariner, KVLCC2, noise-free;
# the drift angle changes too); the position's noise only lowers it.
HEADING_SCALE_WINDOW_S = 10.0
MAX_HEADING_TO_COURSE = 8.0


@dataclass(frozen=True)
class TrackVelocities:
    """How u, v (and r, where absent) are read off the track.

    Attributes
    ----------
    window_s : the local fit's window [s]; None: chosen from the log (``plug_in_window``), for
        the track and, where r is read off ψ, for ψ apart.
    antenna : the position sensor's place in the body frame (forward, starboard) [m] from the
        log's reference point (where u, v, x, y are wanted).
    """

    window_s: float | None = None
    antenna: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        if self.window_s is not None and not (
                isinstance(self.window_s, int | float) and math.isfinite(self.window_s)
                and self.window_s > 0):
            raise ShipidError(f"--track-window must be a number of seconds > 0, got "
                              f"{self.window_s!r}")  # fmt: skip
        antenna = tuple(self.antenna)
        if len(antenna) != 2 or not all(isinstance(a, int | float) and math.isfinite(a)
                                        for a in antenna):
            raise ShipidError(f"--antenna must be two finite numbers FORWARD,STARBOARD [m], "
                              f"got {self.antenna!r}")  # fmt: skip
        object.__setattr__(self, "antenna", (float(antenna[0]), float(antenna[1])))

    def window(self, t: np.ndarray, *signals: np.ndarray) -> float:
        """The window [s] for ``signals`` (x, y of a track, or ψ) sampled at ``t``."""
        return float(self.window_s) if self.window_s is not None \
            else plug_in_window(t, *signals)  # fmt: skip


def plug_in_window(t: np.ndarray, *signals: np.ndarray) -> float:
    """The window whose slope's error, noise and bias together, is least (a plug-in rule) over
    ``signals`` sampled at ``t`` (x and y of a track; or ψ alone, for r).

    A local quadratic's slope over a window W of samples Δk apart errs by the positions' white
    noise σ with variance 12σ²Δk/W³, and by the track's third derivative x‴ with bias x‴·W²/40
    (a sinusoid of period P loses (πW/P)²/10 of its amplitude). Their sum of squares is least at
    W⁷ = 14400·σ²·Δk / E[x‴²]. σ² is read off the positions' second differences, E[x‴²] off the
    slopes of slopes of slopes over a pilot window, less what the noise puts there; the pilot
    starts at ``PILOT_FACTOR`` times the shortest window and doubles while noise is most of it.
    The window is kept between ``MIN_WINDOW_SAMPLES`` samples and ``MAX_WINDOW_S``.
    """
    from shipid.data.preprocess import white_noise_variance

    step = float(np.median(np.diff(t)))
    shortest = (MIN_WINDOW_SAMPLES - 1) * step
    noise = float(np.mean([white_noise_variance(p) for p in signals]))
    if not noise > 0:
        return shortest
    pilot = PILOT_FACTOR * shortest
    while pilot <= MAX_WINDOW_S:
        # Away from the ends, where the one-sided fits make the most of the noise.
        inner = (t >= t[0] + 1.5 * pilot) & (t <= t[-1] - 1.5 * pilot)
        if inner.sum() < MIN_WINDOW_SAMPLES:
            break
        measured = float(np.mean(np.square(np.concatenate(
            [_third_derivative(t, p, pilot)[inner] for p in signals]))))  # fmt: skip
        from_noise = noise * _third_derivative_gain(step, pilot)
        if measured > 2.0 * from_noise:
            best = (14400.0 * noise * step / (measured - from_noise)) ** (1.0 / 7.0)
            return float(min(max(best, shortest), MAX_WINDOW_S))
        pilot *= 2.0
    return MAX_WINDOW_S


def _third_derivative(t: np.ndarray, p: np.ndarray, window: float) -> np.ndarray:
    return local_slope(t, local_slope(t, local_slope(t, p, window), window), window)


def _third_derivative_gain(step: float, window: float) -> float:
    """What ``_third_derivative`` makes of white noise of unit variance, per sample (its
    impulse response's sum of squares, away from the ends)."""
    half = int(math.ceil(2.0 * window / step)) + 1
    impulse = np.zeros(2 * half + 1)
    impulse[half] = 1.0
    return float(np.sum(np.square(_third_derivative(step * np.arange(impulse.size), impulse,
                                                    window))))  # fmt: skip


def local_slope(t: np.ndarray, y: np.ndarray, window_s: float) -> np.ndarray:
    """dy/dt at every sample: the slope of a quadratic fitted by least squares to the samples
    within ``window_s``/2 either side (fewer at the ends).

    Where the samples are evenly spaced (the usual log), the slope away from the ends is one
    fixed filter (a Savitzky–Golay derivative), applied by correlation; the ends, and logs with
    jitter or gaps, fit each sample's own window."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    half = 0.5 * window_s
    step = np.diff(t)
    reach = int(math.floor(half * (1 + 1e-12) / step.min())) if step.size else 0
    if step.size and np.ptp(step) <= 1e-9 * step.mean() and len(t) > 4 * reach + 2:
        tau = np.arange(-reach, reach + 1) * step.mean() / half
        moments = np.array([[np.sum(tau ** (i + j)) for j in range(3)] for i in range(3)])
        kernel = np.linalg.solve(moments, np.stack([np.ones_like(tau), tau, tau**2]))[1]
        out = np.empty(len(t))
        out[reach:len(t) - reach] = np.correlate(y, kernel, mode="valid") / half
        ends = np.r_[0:reach, len(t) - reach:len(t)]
        out[ends] = _local_slope_at(t, y, half, ends)
        return out
    return _local_slope_at(t, y, half, np.arange(len(t)))


def _local_slope_at(t: np.ndarray, y: np.ndarray, half: float, index: np.ndarray) -> np.ndarray:
    """``local_slope`` at the samples ``index``, each fitted over its own window."""
    lo = np.searchsorted(t, t[index] - half * (1 + 1e-12), side="left")
    hi = np.searchsorted(t, t[index] + half * (1 + 1e-12), side="right")
    if index.size == 0:
        return np.empty(0)
    reach = int(max(np.max(index - lo), np.max(hi - 1 - index)))
    # Moments of τ = (t_j − t_i)/half (scaled: the 3 × 3 systems stay well conditioned).
    s = np.zeros((5, index.size))
    b = np.zeros((3, index.size))
    for k in range(-reach, reach + 1):
        j = index + k
        ok = (j >= lo) & (j < hi)
        jj = np.clip(j, 0, len(t) - 1)
        tau = np.where(ok, (t[jj] - t[index]) / half, 0.0)
        p = ok.astype(float)
        for m in range(5):
            s[m] += p
            if m < 3:
                b[m] += p * np.where(ok, y[jj], 0.0)
            p = p * tau
    a = np.stack([np.stack([s[i + j] for j in range(3)], axis=-1) for i in range(3)], axis=-2)
    coef = np.linalg.solve(a, b.T[..., None])[..., 0]
    return coef[:, 1] / half


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def velocities_from_track(log: pd.DataFrame, options: TrackVelocities | None = None,
                          name: str = "log") -> pd.DataFrame:
    """The log with u, v read off its track (x, y) and heading ψ, and r off ψ where the log has
    no r; x, y moved from the antenna to the reference point. Checks that the heading and the
    track share their axes (see the module's docstring)."""
    options = options or TrackVelocities()
    missing = [c for c in ("x", "y", "psi") if c not in log.columns]
    if missing:
        raise ShipidError(f"{name}: u, v are read off the track, which needs the columns x, y and "
                          f"psi; missing {', '.join(missing)}")  # fmt: skip
    t = column_values(log, "t", float)
    x, y = column_values(log, "x", float), column_values(log, "y", float)
    window = options.window(t, x, y)
    step = float(np.median(np.diff(t)))
    if window < 4 * step:
        raise ShipidError(f"{name}: the track's window of {window:g} s holds fewer than 5 samples "
                          f"(Δk {step:g} s); give a longer --track-window")  # fmt: skip
    if t[-1] - t[0] < window:
        raise ShipidError(f"{name}: {t[-1] - t[0]:g} s of track is shorter than its window of "
                          f"{window:g} s (--track-window)")  # fmt: skip
    psi = np.unwrap(column_values(log, "psi", float))
    xdot, ydot = local_slope(t, x, window), local_slope(t, y, window)
    return _body_velocities(log, t, psi, xdot, ydot, options, name,
                            {"from": "track", "window_s": window})


def _body_velocities(log: pd.DataFrame, t: np.ndarray, psi: np.ndarray, xdot: np.ndarray,
                     ydot: np.ndarray, options: TrackVelocities, name: str,
                     how: dict) -> pd.DataFrame:  # fmt: skip
    """The log with u, v of the earth-fixed velocity (ẋ, ẏ) at the antenna turned by ψ and
    moved to the reference point, r off ψ where not logged, x, y moved there too; the heading
    checked against the course; ``how`` and the rest in ``attrs["velocities"]``."""
    heading_window = None
    if "r" in log.columns:
        r = column_values(log, "r", float)
    else:
        # A compass's heading is far less noisy for the ship's turn than a receiver's track
        # for its headway: its own window (a 0.2° compass on CyberShip II's zig-zag: 0.0069
        # rad/s rms error in r at the track's 4.1 s window).
        heading_window = options.window(t, psi)
        r = local_slope(t, psi, heading_window)
    _check_heading_scale(t, xdot, ydot, psi, name)
    _check_axes(xdot, ydot, psi, name)
    c, s = np.cos(psi), np.sin(psi)
    fore, starboard = options.antenna
    out = log.drop(columns=[col for col in GROUND_VELOCITY_COLUMNS if col in log.columns])
    out.attrs = dict(log.attrs)
    out["u"] = xdot * c + ydot * s + r * starboard
    out["v"] = -xdot * s + ydot * c - r * fore
    out["r"] = r
    if {"x", "y"} <= set(out.columns):
        out["x"] = column_values(out, "x", float) - (fore * c - starboard * s)
        out["y"] = column_values(out, "y", float) - (fore * s + starboard * c)
    out.attrs["velocities"] = frozen({**how, "antenna": list(options.antenna),
                                      "r_from_heading": heading_window is not None,
                                      "heading_window_s": heading_window})  # fmt: skip
    return out


def _check_heading_scale(t, xdot, ydot, psi, name: str) -> None:
    """Refuse a heading in degrees read as radians: it turns some 57 times as far as the track.

    Over windows of ``HEADING_SCALE_WINDOW_S`` where the ship makes way, the heading's changes
    against the course's (the track's direction): their rms ratio is near 1 (the drift angle
    changes too, within a factor of a few), 57 for degrees. A log whose ψ̇ is checked against a
    logged r is checked again there (``shipid.data.checks``); without r this is the only check.
    """
    speed = np.hypot(xdot, ydot)
    typical = float(np.percentile(speed, 90))
    running = speed >= RUNNING_SHARE * typical
    step = float(np.median(np.diff(t)))
    k = int(round(HEADING_SCALE_WINDOW_S / step))
    if not typical > 0 or k < 1 or len(t) <= k + 10:
        return
    course = np.unwrap(np.arctan2(ydot, xdot))
    both = running[k:] & running[:-k]
    if both.sum() < 10:
        return
    turned = (psi[k:] - psi[:-k])[both]
    steered = (course[k:] - course[:-k])[both]
    ratio = float(np.sqrt(np.mean(turned**2) / max(np.mean(steered**2), 1e-12)))
    if ratio > MAX_HEADING_TO_COURSE:
        raise ShipidError(f"{name}: the heading 'psi' turns {ratio:.0f} times as far as the track "
                          f"does (rms over {HEADING_SCALE_WINDOW_S:g} s windows): it looks like "
                          "degrees; give --degrees psi or 'psi [deg]' in the header")  # fmt: skip


def velocities_from_ground_velocity(log: pd.DataFrame, options: TrackVelocities | None = None,
                                    name: str = "log") -> pd.DataFrame:
    """The log with u, v from a GNSS's speed and course over ground (columns ``sog`` [m/s],
    ``cog`` [rad], clockwise from north) turned by the heading ψ, and r off ψ where the log has
    no r:

        u = SOG cos(COG − ψ),   v = SOG sin(COG − ψ)

    A receiver reads them off the carrier's Doppler shift, far less noisy than its positions'
    slope, so nothing is differentiated but ψ (for r). The antenna's lever is corrected as for a
    track (``options.antenna``; ``window_s`` applies to ψ's slope), and the heading is checked
    against the course as against a track's (degrees, axes, an offset).
    """
    options = options or TrackVelocities()
    t = column_values(log, "t", float)
    sog, cog = column_values(log, "sog", float), column_values(log, "cog", float)
    peak = float(np.max(np.abs(cog)))
    if peak > 2.0 * math.pi + 0.01:
        raise ShipidError(f"{name}: column 'cog' reaches {peak:.3g}, which looks like degrees; "
                          "give --degrees cog or 'cog [deg]' in the header")  # fmt: skip
    psi = np.unwrap(column_values(log, "psi", float))
    return _body_velocities(log, t, psi, sog * np.cos(cog), sog * np.sin(cog), options, name,
                            {"from": "ground velocity"})


def _median_drift_deg(xdot, ydot, psi, running) -> float:
    u = xdot * np.cos(psi) + ydot * np.sin(psi)
    v = -xdot * np.sin(psi) + ydot * np.cos(psi)
    return float(np.median(np.degrees(np.abs(np.arctan2(v[running], u[running])))))


def _check_axes(xdot, ydot, psi, name: str) -> None:
    speed = np.hypot(xdot, ydot)
    typical = float(np.percentile(speed, 90))
    running = speed >= RUNNING_SHARE * typical
    if not typical > 0 or running.sum() < 10:
        return
    given = _median_drift_deg(xdot, ydot, psi, running)
    if given <= MIN_DRIFT_TO_JUDGE_DEG:
        return
    others = {"x and y swapped (x east, y north)": _median_drift_deg(ydot, xdot, psi, running),
              "psi counter-clockwise": _median_drift_deg(xdot, ydot, -psi, running)}
    label = min(others, key=others.get)
    alternative = f"{others[label]:.0f}° with {label}"
    if given > MAX_MEDIAN_DRIFT_DEG:
        raise ShipidError(
            f"{name}: the track runs {given:.0f}° from the heading 'psi' (median where the ship "
            f"makes way; {alternative}): psi looks offset (measured from east? or astern?), or "
            "its axes are not the track's; canonical: x north, y east, psi the bow's direction "
            "clockwise from north")
    if others[label] < ALTERNATIVE_SHARE * given:
        raise ShipidError(
            f"{name}: the track runs {given:.0f}° from the heading 'psi' (median where the ship "
            f"makes way), {alternative}: canonical is x north, y east and psi clockwise from "
            "north (swap x and y: --columns x=y,y=x; or negate psi)")
