"""Checks of a log at the boundary: types, missing values, time, and units that look wrong.

Every check names the file, the column and where possible the row. Units cannot be read off a
number, but they can be read off how signals relate: the heading's rate of change must equal the
yaw rate (ψ̇ = r), which tells degrees from radians and milliseconds from seconds; a rudder beyond
60° or a yaw rate beyond 3 rad/s is not in radians. Sign conventions can be read off the track:
the positions must move as u, v turned by ψ say (ẋ = u cos ψ − v sin ψ, ẏ = u sin ψ + v cos ψ),
which tells a sway positive to port, or x and y swapped (east, north), from the canonical axes,
and by how far it moves, knots or feet from m/s and metres. The heading also tells a gyro's
offset: ψ − ∫r dt drifts at it. And the rudder convention can be read off the response: where
the ship runs ahead, ṙ follows δ with the sign of the side a positive angle turns it to.
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shipid.data.log import COLUMNS, REQUIRED, column_values
from shipid.data.preprocess import cumulative_integral
from shipid.data.yaw_rate import heading_drift
from shipid.errors import ShipidError, ShipidWarning

ANGLE_COLUMNS = ("delta", "psi", "r", "wind_angle", "cog")
# A rudder beyond 60° or a yaw rate beyond 3 rad/s (172 °/s) is not radians.
# A relative wind's angle is a direction: within a turn either way of 0 in radians (a file in
# degrees, up to 180° or 360°, was read as radians without a word).
RADIAN_PLAUSIBLE = {"delta": math.radians(60.0), "r": 3.0, "wind_angle": 2.0 * math.pi + 0.01}
SPEED_PLAUSIBLE = 40.0  # m/s on |u| and |v|: 78 kn, beyond any displacement ship
# No manoeuvre can be identified from samples this far apart: the time is not in seconds.
MAX_SAMPLING_S = 30.0
DEG = 180.0 / math.pi
# Propulsion dropouts: the propeller at most this share of its largest |n| (stopped or astern)...
STOPPED_SHARE = 0.05
# ... while the speed, median-smoothed over this window (GNSS jumps are not headway) ...
DROPOUT_SMOOTH_S = 5.0
# ... rises by this share of its largest value: no ship gains that much headway without thrust
# (the Esso Osaka's random runs: 0.05 m/s of 0.28 with a stern wind of 3-5 m/s; 0.19 of 0.25 at
# the end of 31-Jul 14_52_18, where n and δ read 0 while the ship sped up and turned).
DROPOUT_GAIN_SHARE = 0.3
# The track is compared with u, v and ψ as displacements over this window (positions are noisy
# and, in the MARIN files, quantised to 10 m full scale), less their mean (a current).
TRACK_WINDOW_S = 10.0
# Another convention is named when its track error is below this share of the given one's. On
# the real logs here the given conventions are 6.8-1500 times better than either alternative.
# On the paper ship's trials with 0.5 m of position noise (10 seeds), the right sway scores
# 0.25-0.27 of the wrong one's in a 20° turn and 0.37-0.39 in a 20/20 zig-zag; in a 10/10
# zig-zag, 0.73-0.75: too little sway to tell for certain, so below ``TRACK_CONVENTION_WARN``
# a warning says which fits better (a correct 10/10's alternatives score 1.3-1.4 of it).
TRACK_CONVENTION_SHARE = 0.6
TRACK_CONVENTION_WARN = 0.8
# The rudder's yaw response is fitted on means over bins of this length: ṙ from a differenced
# yaw rate is noise at a fine sampling, and per sample its residuals are correlated (lag-1
# correlation 0.73 in MARIN's KVLCC2 zig-zag at 50 Hz, 1.00 in HSVA's at 20 Hz).
RUDDER_BIN_S = 1.0
# Bins with u above this share of the log's 90th percentile of u (and the propeller ahead):
# astern, or creeping, the rudder turns the ship the other way or hardly at all.
RUDDER_AHEAD_SHARE = 0.5
# A convention is read off the log only at |t| of ṙ's gain on δ at least this (its residuals'
# lag-1 correlation allowed for). The real logs here: 4.2-45 in the zig-zags and three of the
# four Esso random runs, all with the stated sign; a turning circle, one step of the rudder,
# 0.6-2.0, which says nothing.
RUDDER_CONVENTION_T = 4.0
# ... and only where the rudder reverses at least ``RUDDER_REVERSALS`` times by this share of its
# range: with one step (a turning circle) or one step and back (a pull-out) the gain rests on the
# few seconds the rudder moves, in which the ship's lag and its loss of speed confound it. The
# Mariner's full-scale 35° turn at Δk 0.5 s (its rudder ordered from the log's start, paper
# noise × 0.1) read t = +4.3 to starboard, and a plain CSV of it was negated.
RUDDER_REVERSAL_SHARE = 0.25
RUDDER_REVERSALS = 2
# Such a log names its convention by the turn it holds: the rudder held this far [deg] from where
# it started, to the end of the log (within this share of the step, at least 1°), and the heading
# turned this far [deg] meanwhile, the yaw rate on one side throughout. The Esso Osaka's 35°
# turns, the reference ships' 20° and 35° turns: their stated sides, at the paper's noise too.
RUDDER_HELD_DEG = 10.0
HELD_TOLERANCE = 0.05
HELD_TURN_DEG = 90.0


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) indices of the runs of True in a boolean array."""
    edges = np.diff(np.concatenate([[0], np.asarray(mask, dtype=np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1, strict=True))


# Clock times of day as loggers write them: 12:00:00, 12:00:00.1, 9:05:07,25.
CLOCK_TIME = re.compile(r"^\d{1,2}:\d{2}:\d{2}([.,]\d+)?$")
# A clock time that falls back by more than this has passed midnight.
MIDNIGHT_FALL_S = 12 * 3600.0


def _times_from_text(col: pd.Series, name: str) -> tuple[pd.Series, str | None]:
    """A ``t`` a CSV gives as text: ISO dates and times (2026-05-01T12:00:00.1Z, with or without
    the date's T, the zone or an offset) as datetimes; times of day (12:00:00.1) as seconds from
    the first, with the first as the origin; numbers are left to the numeric check. A value that
    is neither is named with its row."""
    text = col.astype("string").str.strip()
    present = text.notna().to_numpy()
    if not present.any() or pd.to_numeric(text[present], errors="coerce").notna().all():
        return col, None
    first = str(text[present].iloc[0])
    if CLOCK_TIME.match(first):
        parsed = pd.to_timedelta(text.str.replace(",", ".", regex=False), errors="coerce")
        kind = "a time of day (hh:mm:ss)"
    else:
        parsed = pd.to_datetime(text, errors="coerce", utc=True, format="ISO8601")
        kind = "an ISO date and time"
    bad = present & parsed.isna().to_numpy()
    if bad.any():
        row = int(np.argmax(bad))
        raise ShipidError(f"{name}: column 't' is {kind} at data row {int(np.argmax(present)) + 1} "
                          f"({first!r}) but not at data row {row + 1} ({str(text.iloc[row])[:40]!r})")
    if CLOCK_TIME.match(first):
        # Seconds from the first sample, as a date's are; where the clock passes midnight a day
        # is added (it fell by half a day or more between two samples).
        # In integer nanoseconds: 43200.1 − 43200 in floats is 0.0999999999985.
        ns = parsed.to_numpy().astype("timedelta64[ns]").astype(np.int64)[present]
        passed = np.cumsum(np.concatenate([[0], np.diff(ns) < -MIDNIGHT_FALL_S * 1e9]))
        seconds = np.full(len(col), np.nan)
        seconds[present] = (ns + 86_400 * 10**9 * passed - ns[0]) / 1e9
        return pd.Series(seconds, index=col.index), first
    return parsed, None


def convert_types(df: pd.DataFrame, name: str) -> pd.DataFrame:
    """Refuse boolean columns; a datetime or timedelta ``t`` (or one a CSV writes as ISO dates or
    times of day) becomes seconds from its first sample (the datetime origin is kept in
    ``attrs["time_origin"]``)."""
    if "t" in df.columns and (pd.api.types.is_object_dtype(df["t"])
                              or pd.api.types.is_string_dtype(df["t"])):
        df["t"], origin = _times_from_text(df["t"], name)
        if origin is not None:
            df.attrs["time_origin"] = origin
    for c in [c for c in COLUMNS if c in df.columns]:
        col = df[c]
        if pd.api.types.is_bool_dtype(col):
            raise ShipidError(f"{name}: column {c!r} holds true/false values, not numbers")
        if pd.api.types.is_datetime64_any_dtype(col) or pd.api.types.is_timedelta64_dtype(col):
            if c != "t":
                raise ShipidError(f"{name}: column {c!r} holds dates or durations, not numbers")
            if col.isna().any():
                row = int(np.argmax(col.isna().to_numpy()))
                raise ShipidError(f"{name}: column 't' is missing at data row {row + 1}")
            if pd.api.types.is_datetime64_any_dtype(col):
                df.attrs["time_origin"] = str(col.iloc[0])
                seconds = (col - col.iloc[0]).dt.total_seconds()
            else:
                seconds = col.dt.total_seconds()
            df[c] = seconds.to_numpy(dtype=float)
    return df


def _stamp(value: float) -> str:
    """A time stamp as the file gives it (before any unit in its header is applied), with every
    digit that tells rows apart: ``:g`` printed an epoch time in ms as 1.7e+12 for every row."""
    return f"{value:.15g}"


def check_log(df: pd.DataFrame, name: str, min_samples: int = 3, fill_gaps: bool = False,
              required: tuple[str, ...] = REQUIRED, extra: tuple[str, ...] = ()) -> None:
    """Required columns, finite numbers, strictly increasing time, enough samples.

    Missing values (empty cells, NaN) inside a signal are reported with their span and refused,
    or, with ``fill_gaps``, interpolated linearly in time. Text and infinities are always refused.
    ``extra``: columns beyond the canonical ones checked alike (a track's lat, lon).
    """
    if len(df) == 0:
        raise ShipidError(f"{name}: the header has no rows")
    missing = [c for c in required if c not in df.columns]
    if missing:
        have = ", ".join(map(str, df.columns[:20])) + (" ..." if len(df.columns) > 20 else "")
        raise ShipidError(f"{name}: missing column(s) {', '.join(missing)} (columns found: {have}); "
                          "map other names with --columns, e.g. --columns delta=rudder")  # fmt: skip
    convert_types(df, name)
    gaps: dict[str, np.ndarray] = {}
    for c in [c for c in (*COLUMNS, *extra) if c in df.columns]:
        raw = df[c]
        values = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)
        gap = raw.isna().to_numpy()
        bad = ~np.isfinite(values) & ~gap
        if bad.any():
            row = int(np.argmax(bad))
            raise ShipidError(f"{name}: column {c!r} has a non-numeric or non-finite value "
                              f"({str(raw.iloc[row])[:40]!r}) at data row {row + 1}")  # fmt: skip
        if gap.any():
            gaps[c] = gap
        df[c] = values
    if "t" in gaps:
        first, last = true_runs(gaps["t"])[0]
        raise ShipidError(f"{name}: column 't' is missing at data rows {first + 1}–{last + 1}; "
                          "a log needs a time stamp on every row")  # fmt: skip
    t = column_values(df, "t")
    for c, gap in gaps.items():
        runs = true_runs(gap)
        first, last = runs[0]
        if np.all(gap):
            raise ShipidError(f"{name}: column {c!r} is empty")
        if not fill_gaps:
            more = f" and {len(runs) - 1} more gap(s)" if len(runs) > 1 else ""
            span = (f"1 missing value at data row {first + 1} (t = {_stamp(t[first])})" if first == last
                    else f"{last - first + 1} missing values at data rows {first + 1}–{last + 1} "
                    f"(t = {_stamp(t[first])}–{_stamp(t[last])})")
            raise ShipidError(f"{name}: column {c!r} has {span}{more}; trim them off with "
                              "--start/--end or interpolate with --fill-gaps")  # fmt: skip
        good = ~gap
        df[c] = np.interp(t, t[good], column_values(df, c)[good])
    dt = np.diff(t)
    if np.any(dt == 0):
        row = int(np.argmax(dt == 0)) + 1
        raise ShipidError(f"{name}: duplicate time stamp t = {_stamp(t[row])} "
                          f"at data rows {row} and {row + 1}")
    if np.any(dt < 0):
        row = int(np.argmax(dt < 0)) + 1
        raise ShipidError(f"{name}: time is not increasing at data row {row + 1} "
                          f"(t = {_stamp(t[row])} after {_stamp(t[row - 1])})")  # fmt: skip
    if len(df) < min_samples:
        raise ShipidError(f"{name}: {len(df)} samples, too short (at least {min_samples} needed)")


def check_units(df: pd.DataFrame, name: str, degrees=(), offset_given: bool = False,
                converted=()) -> None:  # fmt: skip
    """Refuse signals whose units are evidently not the canonical ones (after ``--degrees``);
    name a gyro's offset on r unless one is to be subtracted (``offset_given``). ``converted``:
    the angle columns read in degrees (their header's unit, or ``--degrees``), which a heading
    and a yaw rate that disagree by 180/π then name as the likelier culprit."""
    for c, limit in RADIAN_PLAUSIBLE.items():
        if c in df.columns and c not in degrees:
            peak = float(np.max(np.abs(column_values(df, c))))
            if peak > limit:
                raise ShipidError(f"{name}: column {c!r} reaches {peak:.3g}, which looks like "
                                  f"degrees; give --degrees {c} (angles are radians inside)")
    for c in ("u", "v"):
        peak = float(np.max(np.abs(column_values(df, c))))
        if peak > SPEED_PLAUSIBLE:
            raise ShipidError(f"{name}: column {c!r} reaches {peak:.3g}, not a ship speed in m/s "
                              "(knots or km/h? convert to m/s)")  # fmt: skip
    t = column_values(df, "t")
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    if dt > MAX_SAMPLING_S:
        raise ShipidError(f"{name}: samples are {dt:g} apart in 't'; that is not seconds "
                          "(milliseconds?): give t in seconds, or its unit in the header: "
                          "'time [ms]'")  # fmt: skip
    if "psi" in df.columns:
        _check_heading_against_yaw_rate(df, name, converted)
        if not offset_given:
            _check_yaw_rate_offset(df, name)
        if {"x", "y"} <= set(df.columns):
            _check_track_against_velocities(df, name)


def _displacements(t, x, y, psi, u, v, window_s: float, sway_sign: float = 1.0,
                   east_first: bool = False) -> tuple[np.ndarray, np.ndarray] | None:
    """The track's displacements over ``window_s`` (north and east stacked) and those of u, v
    turned by ψ and integrated, each less its mean (a current), under a convention; None when
    the log is shorter than a few windows."""
    h = np.diff(t)
    k = int(round(window_s / float(np.median(h)))) if h.size else 0
    if k < 1 or len(t) < k + 10:
        return None
    # Windows across a gap in time are left out: the velocities' integral draws a straight line
    # over it, which told a log with a 20 s gap that its sway looked positive to port.
    whole = (t[k:] - t[:-k]) <= 1.5 * k * float(np.median(h))
    if np.count_nonzero(whole) < 10:
        return None
    north, east = (y, x) if east_first else (x, y)
    c, s = np.cos(psi), np.sin(psi)
    sway = sway_sign * v
    measured_out, predicted_out = [], []
    for measured, rate in ((north, u * c - sway * s), (east, u * s + sway * c)):
        integral = cumulative_integral(rate, t)
        dm = (measured[k:] - measured[:-k])[whole]
        dp = (integral[k:] - integral[:-k])[whole]
        measured_out.append(dm - dm.mean())
        predicted_out.append(dp - dp.mean())
    return np.concatenate(measured_out), np.concatenate(predicted_out)


CONVENTIONS = (("given", 1.0, False), ("v to port", -1.0, False), ("x east, y north", 1.0, True),
               ("both", -1.0, True))  # (label, sway sign, x and y swapped)


def _rms(parts: tuple[np.ndarray, np.ndarray]) -> float:
    return float(np.sqrt(2.0 * np.mean((parts[0] - parts[1]) ** 2)))


def _scale(parts: tuple[np.ndarray, np.ndarray]) -> tuple[float, float] | None:
    measured, predicted = parts
    pp, mm = float(predicted @ predicted), float(measured @ measured)
    if pp <= 0 or mm <= 0:
        return None
    mp = float(measured @ predicted)
    return mp / pp, mp / math.sqrt(pp * mm)


def track_errors(t: np.ndarray, x: np.ndarray, y: np.ndarray, psi: np.ndarray, u: np.ndarray,
                 v: np.ndarray, window_s: float = TRACK_WINDOW_S) -> dict[str, float] | None:
    """RMS error [m] of the track's displacements over ``window_s`` against u, v turned by ψ and
    integrated (their mean difference, a current, removed), as given and under the two usual
    mistakes: ``"given"``, ``"v to port"`` (v negated), ``"x east, y north"`` (x and y swapped)
    and both. None when the log is shorter than a few windows."""
    parts = _all_displacements(t, x, y, psi, u, v, window_s)
    return None if parts is None else {label: _rms(p) for label, p in parts.items()}


def _all_displacements(t, x, y, psi, u, v, window_s: float = TRACK_WINDOW_S):
    out = {}
    for label, sway, east_first in CONVENTIONS:
        parts = _displacements(t, x, y, psi, u, v, window_s, sway, east_first)
        if parts is None:
            return None
        out[label] = parts
    return out


def track_scale(t, x, y, psi, u, v, window_s: float = TRACK_WINDOW_S
                ) -> tuple[float, float] | None:  # fmt: skip
    """(k, ρ): the least-squares factor k by which the track's displacements exceed those u, v
    say (1 when both are in metres and m/s), and their correlation ρ (how far k can be trusted).
    On the real logs here k is 0.995-1.014."""
    parts = _displacements(t, x, y, psi, u, v, window_s)
    return None if parts is None else _scale(parts)


# Unit mistakes the track's scale tells: (how many times as far the track moves as u, v say,
# what it means and the remedy).
TRACK_SCALES = ((1.852 / 3.6, "u, v look like knots: convert them to m/s (× 0.5144)"),
                (1 / 3.6, "u, v look like km/h: convert them to m/s (÷ 3.6)"),
                (0.44704, "u, v look like mph: convert them to m/s (× 0.44704)"),
                (1 / 0.3048, "x, y look like feet: convert them to metres (× 0.3048)"),
                (1e-3, "x, y look like kilometres: convert them to metres"))
TRACK_SCALE_TOLERANCE = 0.2  # |k − 1| within it: metres and m/s


def _check_track_against_velocities(df: pd.DataFrame, name: str) -> None:
    parts = _all_displacements(*(column_values(df, c, float)
                                 for c in ("t", "x", "y", "psi", "u", "v")))  # fmt: skip
    if parts is None:
        return
    errors = {label: _rms(p) for label, p in parts.items()}
    if not errors["given"] > 0:
        return
    label = min(errors, key=errors.get)
    what = {"given": "",
            "v to port": "the sway 'v' looks positive to port: negate v",
            "x east, y north": "x and y look swapped (x east, y north): swap them "
                               "(--columns x=y,y=x)",
            "both": "the sway 'v' looks positive to port and x, y swapped (x east, y north): "
                    "negate v and swap x and y"}[label]  # fmt: skip
    if label == "given" or errors[label] >= TRACK_CONVENTION_SHARE * errors["given"]:
        if label != "given" and errors[label] < TRACK_CONVENTION_WARN * errors["given"]:
            warnings.warn(f"{name}: the track (x, y) moves more as u, v and psi say with {label} "
                          f"({errors[label]:.3g} m rms over {TRACK_WINDOW_S:g} s against "
                          f"{errors['given']:.3g} m as given), though the log's drift is too "
                          f"small to be sure: {what} if so (canonical: x north, y east, v "
                          "positive to starboard)", ShipidWarning, stacklevel=4)  # fmt: skip
        _check_track_scale(_scale(parts["given"]), name)
        return
    raise ShipidError(f"{name}: the track (x, y) does not move as u, v and psi say "
                      f"({errors['given']:.3g} m rms over {TRACK_WINDOW_S:g} s; "
                      f"{errors[label]:.3g} m with {label}): {what} (canonical: x north, y east, "
                      "v positive to starboard)")  # fmt: skip


def _check_track_scale(scale: tuple[float, float] | None, name: str) -> None:
    if scale is None:
        return
    k, rho = scale
    if rho < 0.9 or abs(k - 1.0) <= TRACK_SCALE_TOLERANCE:
        return
    for factor, what in TRACK_SCALES:
        if abs(k / factor - 1.0) <= 0.05:
            raise ShipidError(f"{name}: the track (x, y) moves {k:.3g} times as far as u, v say: "
                              f"{what}")  # fmt: skip
    warnings.warn(f"{name}: the track (x, y) moves {k:.3g} times as far as u, v say (expected 1): "
                  "check the units of u, v and x, y", ShipidWarning, stacklevel=4)


# A yaw rate whose offset against the heading's rate exceeds both (the real logs here: at most
# 0.07 °/s and 3.7 % of their rms r) is named: on the paper ship's training zig-zag an offset of
# 0.57 °/s (6 % of its rms r) made a held-out turn's r error 1.8 times as large.
YAW_RATE_OFFSET_DEG_S = 0.1
YAW_RATE_OFFSET_SHARE = 0.05
# So is a smaller one that moves the heading: where ∫r ends this far from ψ over the log, on a
# straight line standing this many times its scatter (a gyro's steady offset, not noise). MARIN's
# KVLCC2 zig-zags: 3.5°, 73–112 times; the paper's sensors on a 90 s zig-zag or a 200 s turn put
# at most 5° and 11.5 times (30 seeds each; ``tests/test_yaw_rate_offset.py``), but over 150
# seeds of the demo's four trials up to 18.4 times, in 6 of 600 logs. So the drift must also
# stand this many times the std of the drift the white noise of r and ψ would give alone (the
# random walk of ∫r; ``HeadingDrift.noise_drift``): at most 3.4 times in those 600 logs, MARIN's
# zig-zags 209–210 times (at Δk 0.2 s), the Esso Osaka's named turns 1800–2300 times.
HEADING_DRIFT_DEG = 2.0
HEADING_DRIFT_LINEAR = 15.0
HEADING_DRIFT_BEYOND_NOISE = 5.0


def material_yaw_rate_offset(df: pd.DataFrame):
    """The ``HeadingDrift`` of a log with a heading whose yaw rate runs off the heading's rate
    by as much as the checks name (see the constants above); None where it does not."""
    if "psi" not in df.columns:
        return None
    r = column_values(df, "r", float)
    drift = heading_drift(column_values(df, "t", float), column_values(df, "psi", float), r)
    if drift is None:
        return None
    b = drift.offset
    rms = float(np.sqrt(np.mean(r**2)))
    large = abs(b) > math.radians(YAW_RATE_OFFSET_DEG_S) and abs(b) > YAW_RATE_OFFSET_SHARE * rms
    moves = (drift.drift > math.radians(HEADING_DRIFT_DEG) and drift.linear > HEADING_DRIFT_LINEAR
             and drift.beyond_noise > HEADING_DRIFT_BEYOND_NOISE)
    return drift if large or moves else None


def _check_yaw_rate_offset(df: pd.DataFrame, name: str) -> None:
    drift = material_yaw_rate_offset(df)
    if drift is None:
        return
    b = drift.offset
    rms = float(np.sqrt(np.mean(column_values(df, "r", float) ** 2)))
    warnings.warn(f"{name}: the yaw rate 'r' runs {math.degrees(b):+.3g} °/s off the heading's "
                  f"rate ({100 * abs(b) / rms:.1f} % of its rms), so ∫r dt ends "
                  f"{math.degrees(drift.drift):.2g}° from psi over the log's "
                  f"{drift.duration:.0f} s: a gyro's offset (or, in a turn, its scale) biases "
                  "the fit and every heading a model of it runs (overshoots); --yaw-rate-offset "
                  "auto subtracts it (or check psi)", ShipidWarning, stacklevel=4)


def heading_rate_ratio(t: np.ndarray, psi: np.ndarray, r: np.ndarray) -> float | None:
    """Least-squares ratio ψ̇ / r over the samples turning fastest, or None when the log does not
    turn enough to tell (or the ratio is not defined)."""
    d = np.diff(psi)
    h = np.diff(t)
    r_mid = 0.5 * (r[1:] + r[:-1])
    peak = float(np.max(np.abs(r_mid))) if r_mid.size else 0.0
    # Wraps (±π in radians, ±180 in degrees) are jumps far beyond one sample's turn.
    keep = (np.abs(d) < math.pi) & (np.abs(r_mid) >= 0.3 * peak) & (h > 0)
    if peak <= 0 or keep.sum() < 10:
        return None
    rate, rr = d[keep] / h[keep], r_mid[keep]
    # Enough turning to judge: at least 5° of heading change (in r's units) over the kept samples.
    if np.sum(np.abs(rr) * h[keep]) < math.radians(5.0):
        return None
    denom = float(rr @ rr)
    return float(rate @ rr) / denom if denom > 0 else None


def _check_heading_against_yaw_rate(df: pd.DataFrame, name: str, converted=()) -> None:
    ratio = heading_rate_ratio(column_values(df, "t"), column_values(df, "psi"), column_values(df, "r"))
    if ratio is None or 0.5 <= ratio <= 2.0:
        return
    # Where the column the ratio would blame was read as radians, the other one, read from
    # degrees, is the likelier: a header '[deg]' over radians had the right column named wrong.
    if DEG / 2 <= ratio <= DEG * 2:
        if "r" in converted and "psi" not in converted:
            raise ShipidError(f"{name}: the heading 'psi' changes {ratio:.3g} times faster than "
                              "the yaw rate 'r', read in degrees per second (its header or "
                              "--degrees r), turns: r looks like radians per second already")
        raise ShipidError(f"{name}: the heading 'psi' changes {ratio:.3g} times faster than the "
                          "yaw rate 'r' turns: psi looks like degrees; give --degrees psi")
    if 1 / (2 * DEG) <= ratio <= 2 / DEG:
        if "psi" in converted and "r" not in converted:
            raise ShipidError(f"{name}: the heading 'psi', read in degrees (its header or "
                              f"--degrees psi), changes {1 / ratio:.3g} times slower than the "
                              "yaw rate 'r' says: psi looks like radians already")  # fmt: skip
        raise ShipidError(f"{name}: the heading 'psi' changes {1 / ratio:.3g} times slower than "
                          "the yaw rate 'r' says: r looks like degrees per second; give --degrees r")
    if 0.5e-3 <= ratio <= 2e-3:
        raise ShipidError(f"{name}: the heading 'psi' changes 1000 times slower than the yaw "
                          "rate 'r' says: 't' looks like milliseconds; give t in seconds, or its "
                          "unit in the header: 'time [ms]'")
    if -2.0 <= ratio <= -0.5:
        raise ShipidError(f"{name}: the heading 'psi' decreases while the yaw rate 'r' is "
                          "positive: psi and r have opposite sign conventions (canonical: both "
                          "positive turning to starboard); negate one of them")  # fmt: skip
    warnings.warn(f"{name}: the heading 'psi' changes {ratio:.3g} times as fast as the yaw rate "
                  "'r' says (expected 1): check their units", ShipidWarning, stacklevel=3)


@dataclass(frozen=True)
class RudderResponse:
    """How the yaw rate answers the rudder in a log: ṙ ≈ gain·δ + a·r + c where it runs ahead,
    or, where the rudder does not reverse, the turn it holds (``held_turn``)."""

    side: str  # 'port' or 'starboard': where a positive rudder angle turns the ship in the log
    gain: float  # ∂ṙ/∂δ [1/s²]; for a held turn Δr/Δδ [1/s]
    t_score: float  # gain over its standard error, widened for the residuals' correlation
    held_turn: str | None = None  # the held turn in words, where it decided

    @property
    def evidence(self) -> str:
        """What the data show, in words."""
        if self.held_turn:
            return f"{self.held_turn}, as if a positive angle turned it to {self.side}"
        return (f"where it runs ahead the yaw rate answers the rudder as if a positive angle "
                f"turned it to {self.side} (ṙ/δ {self.gain:+.3g} 1/s², t = {self.t_score:+.1f})")

    @property
    def decisive(self) -> bool:
        """Whether the response is firm enough to name a convention (``RUDDER_CONVENTION_T``)."""
        return abs(self.t_score) >= RUDDER_CONVENTION_T


def rudder_reversals(delta: np.ndarray, share: float = RUDDER_REVERSAL_SHARE) -> int:
    """How many times the rudder ``delta`` turns back by at least ``share`` of its range from the
    furthest it had moved (a hysteresis, so noise and small corrections do not count): 0 for a
    turning circle, 1 for a pull-out, one per execute after the first in a zig-zag."""
    delta = np.asarray(delta, dtype=float)
    step = share * float(np.ptp(delta)) if delta.size else 0.0
    if not step > 0:
        return 0
    low = high = delta[0]
    direction, reversals = 0, 0
    for d in delta[1:]:
        if direction == 0:
            low, high = min(low, d), max(high, d)
            if high - low >= step:
                direction = 1 if d == high else -1
                low = high = d
        elif direction > 0:
            if d > high:
                high = d
            elif high - d >= step:
                direction, low, reversals = -1, d, reversals + 1
        elif d < low:
            low = d
        elif d - low >= step:
            direction, high, reversals = 1, d, reversals + 1
    return reversals


def rudder_response(log: pd.DataFrame) -> RudderResponse | None:
    """Least-squares ṙ ≈ gain·δ + a·r + c on ``RUDDER_BIN_S`` means of the samples running ahead
    (u above ``RUDDER_AHEAD_SHARE`` of its 90th percentile, n > 0 where logged). The r term takes
    the yaw damping, which would otherwise hide the rudder in a zig-zag, where r lags δ. None
    when fewer than 20 bins run ahead; where their rudder reverses fewer than
    ``RUDDER_REVERSALS`` times (``rudder_reversals``), the turn it holds (``_held_turn``) or
    None."""
    t = column_values(log, "t", float)
    if len(t) < 3:
        return None
    dt = float(np.median(np.diff(t)))
    per_bin = max(1, int(round(RUDDER_BIN_S / dt)))
    cols = [c for c in ("t", "delta", "u", "r", "n") if c in log.columns]
    bins = log[cols].groupby(np.arange(len(log)) // per_bin).mean()
    if len(bins) < 20:
        return None
    tb, r = column_values(bins, "t"), column_values(bins, "r")
    r_dot = np.gradient(r, tb)
    u = column_values(bins, "u")
    top = float(np.quantile(u, 0.9))
    ahead = u > RUDDER_AHEAD_SHARE * top if top > 0 else np.zeros(len(u), bool)
    if "n" in bins.columns:
        ahead &= column_values(bins, "n") > 0
    delta = column_values(bins, "delta")[ahead]
    if ahead.sum() < 20 or not np.ptp(delta) > 0:
        return None
    if rudder_reversals(delta) < RUDDER_REVERSALS:
        return _held_turn(tb[ahead], delta, r[ahead])
    x = np.column_stack([delta, r[ahead], np.ones(delta.size)])
    y = r_dot[ahead]
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    e = y - x @ coef
    xtx = x.T @ x
    if np.linalg.cond(xtx) > 1e12:
        return None
    var = float(e @ e) / (y.size - 3) * float(np.linalg.inv(xtx)[0, 0])
    rho = float(np.corrcoef(e[1:], e[:-1])[0, 1]) if np.std(e) > 0 else 0.0
    rho = min(max(rho, 0.0), 0.95) if math.isfinite(rho) else 0.0
    se = math.sqrt(var * (1 + rho) / (1 - rho)) if var > 0 else 0.0
    gain = float(coef[0])
    t_score = gain / se if se > 0 else math.copysign(math.inf, gain)
    return RudderResponse("starboard" if gain > 0 else "port", gain, t_score)


def _held_turn(t: np.ndarray, delta: np.ndarray, r: np.ndarray) -> RudderResponse | None:
    """The convention of a log whose rudder does not reverse (a turning circle), read off the
    turn it holds: the rudder held ``RUDDER_HELD_DEG`` or more from where it started, to the end
    (within ``HELD_TOLERANCE``), and in that span the heading turned ``HELD_TURN_DEG`` at least,
    the yaw rate on one side of its start throughout. A ship turns to the side its held rudder
    turns it to, stable or not (an unstable ship's loop is a few degrees wide). None where the
    log holds no such turn."""
    end, start = float(np.median(delta[-3:])), float(delta[0])
    step = end - start
    if abs(step) < math.radians(RUDDER_HELD_DEG):
        return None
    off = np.abs(delta - end) > max(math.radians(1.0), HELD_TOLERANCE * abs(step))
    first = int(np.flatnonzero(off)[-1]) + 1 if off.any() else 0
    if len(t) - first < 3:
        return None
    r0 = float(r[0])
    turned = float(np.sum(r[first:-1] * np.diff(t[first:])))
    if abs(turned) < math.radians(HELD_TURN_DEG) or not np.all(
            np.sign(r[first:] - r0) == np.sign(turned)):  # fmt: skip
        return None
    side = "starboard" if turned * step > 0 else "port"
    turn = "starboard" if turned > 0 else "port"
    words = (f"held at {math.degrees(end):+.0f}° ahead (from {math.degrees(start):+.0f}°) it turns "
             f"to {turn} through {math.degrees(abs(turned)):.0f}°")  # fmt: skip
    gain = (float(np.mean(r[first:])) - r0) / step
    return RudderResponse(side, gain, math.copysign(math.inf, 1.0 if side == "starboard"
                                                    else -1.0), words)  # fmt: skip


def check_rudder_convention(log: pd.DataFrame, name: str, stated: bool) -> None:
    """Warn where the log's rudder response contradicts its stated convention (metadata,
    the format, or --rudder-positive): the sign constraints, the prior and the closed-loop
    replica of a zig-zag use the convention, so they would be mirrored. A log that states none
    (a canonical file without the metadata, taken as port-positive) whose response says
    starboard is taken so, and a warning says it."""
    found = rudder_response(log)
    side = log.attrs.get("rudder_positive", "port")
    if found is None or not found.decisive or found.side == side:
        return
    evidence = found.evidence
    if stated:
        warnings.warn(f"{name}: {evidence}, but the log says rudder_positive={side}: the sign "
                      f"constraints, the prior and the zig-zag replica would be mirrored; give "
                      f"--rudder-positive {found.side} if the data are right, else check the "
                      "signs of delta and r", ShipidWarning, stacklevel=3)  # fmt: skip
        return
    log.attrs["rudder_positive"] = found.side
    warnings.warn(f"{name}: states no rudder convention; {evidence}: taken as "
                  f"rudder_positive={found.side} (--rudder-positive to state it)",
                  ShipidWarning, stacklevel=3)  # fmt: skip


@dataclass(frozen=True)
class Dropout:
    """A span in which the logged propeller speed cannot be the one that drove the ship."""

    start: float  # [s] first sample with the propeller stopped or astern
    end: float  # [s] last such sample
    gain: float  # [m/s] the speed gained meanwhile
    share: float  # gain over the log's largest (smoothed) speed
    before: float | None  # [s] the last sample before the span (None: the log starts in it)


def propulsion_dropouts(log: pd.DataFrame) -> list[Dropout]:
    """Spans where the propeller is stopped or astern (n ≤ ``STOPPED_SHARE`` of the largest |n|)
    yet the ship gains headway: the median-smoothed u rises, while ahead, by more than
    ``DROPOUT_GAIN_SHARE`` of its largest value. The inputs do not describe the motion there, as
    when their logging drops out. Empty without columns n and u, or without an ahead propeller."""
    if "n" not in log.columns or len(log) < 3:
        return []
    t, n = column_values(log, "t", float), column_values(log, "n", float)
    top = float(np.max(np.abs(n)))
    if not top > 0 or not np.any(n > STOPPED_SHARE * top):
        return []
    stopped = true_runs(n <= STOPPED_SHARE * top)
    if not stopped:
        return []
    dt = float(np.median(np.diff(t)))
    window = max(1, int(round(DROPOUT_SMOOTH_S / dt)))
    u = log["u"].rolling(window, center=True, min_periods=1).median().to_numpy(dtype=float)
    largest = float(np.max(np.abs(u)))
    out = []
    for a, b in stopped:
        ahead = np.maximum(u[a:b + 1], 0.0)
        gain = float(np.max(ahead - np.minimum.accumulate(ahead)))
        if largest > 0 and gain > DROPOUT_GAIN_SHARE * largest:
            out.append(Dropout(float(t[a]), float(t[b]), gain, gain / largest,
                               float(t[a - 1]) if a > 0 else None))  # fmt: skip
    return out


def check_propulsion(log: pd.DataFrame, name: str) -> None:
    """Warn of every propulsion dropout (``propulsion_dropouts``), naming the file and times."""
    for d in propulsion_dropouts(log):
        cut = (f"end the log before it (--end {d.before:g}, or --end dropout)"
               if d.before is not None else "start the log after it (--start)")
        warnings.warn(f"{name}: the propeller is stopped or astern from t = {d.start:g} s to "
                      f"{d.end:g} s, yet the ship gains {d.gain:.3g} m/s of headway "
                      f"({100 * d.share:.0f} % of its largest speed): the logged n (and δ) "
                      f"cannot have driven it there, as when their logging drops out; {cut}",
                      ShipidWarning, stacklevel=3)  # fmt: skip
