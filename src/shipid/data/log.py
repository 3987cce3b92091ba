"""The canonical trial log: a DataFrame in SI units and radians with its metadata in ``attrs``.

Columns: ``t`` [s], ``delta`` [rad], ``u``, ``v`` [m/s], ``r`` [rad/s]; optional ``psi`` [rad],
``x``, ``y`` [m], ``n`` [rps], ``thrust`` [N], and the relative wind ``wind_speed`` [m/s] and
``wind_angle`` [rad] (see ``shipid.dynamics.wind`` for the convention).

Metadata keys (``METADATA_KEYS``): ``ship``, ``source``, ``rudder_positive`` ('port' or
'starboard': where a positive rudder angle turns the ship), ``scale`` (λ = ship length / model
length, 1 at full scale), ``manoeuvre``, ``time_origin``, ``yaw_rate_offset`` (a gyro's offset
already subtracted from r, rad/s) and ``velocities`` (where u, v were read off the track: its
window and the antenna's place; ``shipid.data.track_velocities``), ``track_origin`` (where x, y
were read off a GNSS's latitude and longitude: the first fix's, in degrees;
``shipid.data.geodetic``), ``integrator`` (a simulated log's: its integration ``method`` and
``step`` [s], which a closed-loop replica of it runs at). They survive a round trip through
files: Parquet keeps them in its schema metadata, CSV in a first comment line
``# shipid-log: {...JSON...}`` (pandas reads such a file with ``comment="#"``).
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from os import PathLike

import numpy as np
import pandas as pd

from shipid.data.preprocess import cumulative_integral
from shipid.errors import ShipidError

REQUIRED = ("t", "delta", "u", "v", "r")
OPTIONAL = ("psi", "x", "y", "n", "thrust", "wind_speed", "wind_angle")
COLUMNS = REQUIRED + OPTIONAL
RUDDER_SIDES = ("port", "starboard")
METADATA_KEYS = ("ship", "source", "rudder_positive", "scale", "manoeuvre", "time_origin",
                 "particulars", "yaw_rate_offset", "velocities", "track_origin", "integrator")
CSV_METADATA_PREFIX = "# shipid-log: "


class FrozenMapping(dict):
    """A read-only mapping of log metadata (the particulars, the sensor noise, ...), which pandas
    hands on by reference. pandas deep-copies a frame's ``attrs`` into every column it hands out
    (``log["u"]``): with the particulars as a dict that took 22 µs a column, 17 µs with them
    shared (11 µs without metadata); 4–5 % of the CPU time of three test files, measured with the
    copy made shallow. A mapping that cannot change is its own copy. Replace the whole
    value to change it (``log.attrs["particulars"] = frozen({...})``)."""

    __slots__ = ()

    def __deepcopy__(self, memo) -> FrozenMapping:
        return self

    def __reduce__(self):
        return FrozenMapping, (dict(self),)

    def _read_only(self, *args, **kwargs):
        """Refused: log metadata is read-only (replace the whole value)."""
        raise TypeError("log metadata is read-only: replace the whole value instead")

    __setitem__ = __delitem__ = __ior__ = _read_only
    clear = pop = popitem = setdefault = update = _read_only


def frozen(value: object) -> object:
    """``value`` with its mappings made ``FrozenMapping`` and its lists tuples, all the way
    down: metadata that logs share by reference."""
    if isinstance(value, Mapping):
        return value if isinstance(value, FrozenMapping) else \
            FrozenMapping({k: frozen(v) for k, v in value.items()})  # fmt: skip
    if isinstance(value, list | tuple):
        return tuple(frozen(v) for v in value)
    return value


def make_log(columns: Mapping[str, np.ndarray], **meta: object) -> pd.DataFrame:
    """A canonical log from column arrays (canonical names only) and metadata."""
    unknown = set(columns) - set(COLUMNS)
    if unknown:
        raise ValueError(f"not canonical log columns: {sorted(unknown)}; use {COLUMNS}")
    arrays = {c: np.asarray(columns[c], dtype=float) for c in COLUMNS if c in columns}
    lengths = {a.shape for a in arrays.values()}
    if len(lengths - {()}) > 1:  # a scalar is broadcast
        # pandas' own "All arrays must be of the same length" named none of them.
        raise ValueError("log columns of different lengths: " + ", ".join(
            f"{c} {len(a)}" for c, a in arrays.items() if a.ndim))
    if len(lengths) == 1 and len(next(iter(lengths))) == 1:
        # One (columns, samples) block handed over whole: a dict of columns is copied and
        # stacked by pandas, 80 µs of a held turn's 180 µs log (a search builds thousands).
        block = np.empty((len(arrays), *next(iter(lengths))))
        for i, a in enumerate(arrays.values()):
            block[i] = a
        df = pd.DataFrame(block.T, columns=_column_index(tuple(arrays)), copy=False)
    else:
        df = pd.DataFrame(arrays)
    df.attrs.update({k: frozen(v) for k, v in meta.items() if v is not None})
    return df


@functools.lru_cache(maxsize=64)
def _column_index(names: tuple[str, ...]) -> pd.Index:
    """The columns' index of a log with ``names``, made once: pandas builds a string index
    from a list anew each time (29 µs of a held turn's log), and an index never changes."""
    return pd.Index(names)


def column_values(frame: pd.DataFrame, name: str, dtype=None) -> np.ndarray:
    """``frame[name].to_numpy(dtype)``, read-only as pandas' own, without the Series: pandas
    builds a Series for every column taken (and deep-copies the frame's metadata into it),
    13–15 µs against about 1 µs for the column's stored values. Columns are taken millions of
    times over the commands and tests (11 % of the test suite's time, sampled). A frame that
    stores the column otherwise (an extension array, a repeated name) or is no DataFrame
    goes the Series' way."""
    get = getattr(frame, "_get_column_array", None)
    if get is not None:
        loc = frame.columns.get_loc(name)
        if isinstance(loc, int):
            values = get(loc)
            if isinstance(values, np.ndarray):
                if dtype is not None and np.dtype(dtype) != values.dtype:
                    return values.astype(dtype)  # a copy, writable as pandas' is
                out = values.view()
                out.flags.writeable = False
                return out
    return frame[name].to_numpy(dtype=dtype)


def column_array(log: pd.DataFrame, names: Sequence[str]) -> np.ndarray:
    """``log``'s columns ``names`` as one (samples, columns) float array: the columns taken one
    by one and stacked, 40 µs for three of a 3000-sample log, where ``log[names].to_numpy()``
    builds a frame first (260 µs, in every free run's score)."""
    return np.column_stack([column_values(log, c, float) for c in names]) if len(names) else \
        np.empty((len(log), 0))  # fmt: skip


def rudder_reach_deg(logs) -> float:
    """The largest |δ| of ``logs`` [deg]."""
    return max(math.degrees(float(np.nanmax(np.abs(log["delta"].to_numpy(dtype=float)))))
               for log in logs)  # fmt: skip


def log_name(log: pd.DataFrame, default: str = "log") -> str:
    """The log's name (its file name when read from a file)."""
    return str(log.attrs.get("name", default))


def require_columns(log: pd.DataFrame, columns, name: str | None = None, why: str = "") -> None:
    """One line naming the log and the ``columns`` it lacks (a DataFrame handed to the Python
    API: the command line's reader checks its files, the functions raised a KeyError), or
    naming what was handed instead of a log (``require_frame``)."""
    require_frame(log)
    missing = [c for c in columns if c not in log.columns]
    if missing:
        raise ShipidError(f"{name or log_name(log)}: missing column(s) {', '.join(missing)}"
                          + (f" ({why})" if why else ""))


STATE_COLUMNS = ("t", "delta", "u", "v", "r")


def require_frame(log, what: str = "log") -> pd.DataFrame:
    """``log`` itself where it is a DataFrame, else one line naming what it is (a path handed to
    ``simulate_log``, ``lowpass`` or ``manoeuvre_indices`` raised an AttributeError or a
    TypeError deep inside)."""
    if isinstance(log, pd.DataFrame):
        return log
    raise ShipidError(_not_a_frame(log, what))


def _not_a_frame(obj, what: str) -> str:
    """The message for ``obj`` handed where a ``what`` (a log) belongs: a path, or its type."""
    if isinstance(obj, str | bytes | PathLike):
        given = f"the path {str(obj)!r}"
    else:
        kind = type(obj).__name__
        given = f"{'an' if kind[0].lower() in 'aeiou' else 'a'} {kind}"
    return f"a {what} is a pandas DataFrame (shipid.read_log reads a file into one), got {given}"


def require_frames(logs, names=None, what: str = "log") -> list[pd.DataFrame]:
    """``logs`` (a DataFrame or several) as a list, each a DataFrame, else one line naming it
    (a path handed to ``identify`` or ``validate`` raised an AttributeError)."""
    if isinstance(logs, str | bytes | PathLike) or not isinstance(logs, pd.DataFrame | Iterable):
        require_frame(logs, what)
    logs = [logs] if isinstance(logs, pd.DataFrame) else list(logs)
    if names is not None and not isinstance(names, str) and len(names) != len(logs):
        # zip(strict=True) said "argument 2 is shorter than argument 1", deep inside.
        raise ShipidError(f"names: {len(names)} given for {len(logs)} logs, one per log")
    for i, log in enumerate(logs):
        if not isinstance(log, pd.DataFrame):
            name = names[i] if names and i < len(names) else f"{what} {i + 1}"
            raise ShipidError(f"{name}: {_not_a_frame(log, what)}")
    return logs


def require_states(logs, names=None, what: str = "log") -> None:
    """``require_columns`` of t, δ, u, v and r on each of ``logs`` (a DataFrame or several),
    named by ``names`` where given: what a fit or a free run of every state reads; and samples
    (an empty log raised NumPy's "zero-size array")."""
    for i, log in enumerate(require_frames(logs, names, what)):
        name = names[i] if names and i < len(names) else None
        require_columns(log, STATE_COLUMNS, name, f"a {what} has t, delta, u, v and r")
        if log.empty:
            raise ShipidError(f"{name or log_name(log)}: the {what} has no samples")


# A log whose first 2 % run slower than this share of its typical speed (the 90th percentile of
# u) starts without headway (a random run from rest): its running condition is then the median
# over the samples ahead at RUNNING_SHARE of the typical speed or more.
STANDSTILL_SHARE = 0.3
RUNNING_SHARE = 0.5


# Why a log given twice is refused: fitted twice as hard, and where logs are held out in turn
# (select, --cv, the error band), a fold that holds one copy out still fits the other, and
# scores the fit on its own samples as if they were unseen.
GIVEN_TWICE = (": a held-out fold of it would score a fit of its own samples as a prediction; "
               "give each log once")


def refuse_copies(logs: Sequence[pd.DataFrame], names: Sequence[str] | None = None) -> None:
    """A one-line error where two logs hold the same samples (t, δ, u, v, r): a copy under
    another name is the same log given twice."""
    import hashlib

    seen: dict[str, int] = {}
    for i, log in enumerate(logs):
        digest = hashlib.sha256()
        for column in ("t", "delta", "u", "v", "r"):
            if column in log:
                digest.update(np.ascontiguousarray(log[column].to_numpy(float)).tobytes())
        j = seen.setdefault(digest.hexdigest(), i)
        if j != i:
            name, first = (names[k] if names is not None else log_name(logs[k], f"log {k + 1}")
                           for k in (i, j))  # fmt: skip
            same = "is given twice" if first == name else f"holds the same samples as {first}"
            raise ShipidError(f"{name} {same}{GIVEN_TWICE}")


# The main dimensions two logs' particulars must share to be one ship's, and how closely (the
# particulars of one ship are written to a few digits).
SHIP_DIMENSIONS = ("length", "beam", "draught", "mass")
SHIP_DIMENSION_SLACK = 0.01
ONE_SHIP = "the logs of one fit must be of one ship (a model is one ship's); fit each ship apart"


def dimension_apart(first: Mapping, second: Mapping) -> tuple[str, float, float] | None:
    """(key, first's value, second's) of the first main dimension (``SHIP_DIMENSIONS``) the two
    particulars (mappings) both give and that differ by more than ``SHIP_DIMENSION_SLACK``, or
    None: particulars of one ship."""
    for key in SHIP_DIMENSIONS:
        a, b = (first or {}).get(key), (second or {}).get(key)
        if a is None or b is None:
            continue
        a, b = float(a), float(b)
        if abs(a - b) > SHIP_DIMENSION_SLACK * max(abs(a), abs(b)):
            return key, a, b
    return None


def same_ship_key(name: object) -> str | None:
    """A ship's name with case and spacing evened out, to compare (None for no name)."""
    return " ".join(str(name or "").split()).casefold() or None


def ship_name(log: pd.DataFrame) -> str | None:
    """The ship a log names (its metadata's ``ship``) as ``same_ship_key`` compares it."""
    return same_ship_key(log.attrs.get("ship"))


def refuse_other_ships(logs: Sequence[pd.DataFrame], names: Sequence[str] | None = None) -> None:
    """A one-line error where the logs are not of one ship at one scale: two ship names, two
    scales (``scale``), or particulars whose main dimensions differ. A fit of the KVLCC2's 7 m
    model and the Esso Osaka's 3 m model together was written without a word, with the first
    log's particulars for both."""
    label = [names[k] if names is not None else log_name(log, f"log {k + 1}")
             for k, log in enumerate(logs)]  # fmt: skip
    first: dict[str, int] = {}  # what each check compares with: the first log that has it
    for i, log in enumerate(logs):
        if ship_name(log) is not None:
            j = first.setdefault("ship", i)
            if ship_name(log) != ship_name(logs[j]):
                raise ShipidError(f"{label[i]} is a log of ship {log.attrs['ship']!r} and "
                                  f"{label[j]} of {logs[j].attrs['ship']!r}: {ONE_SHIP}")
        if log.attrs.get("scale") is not None:
            j = first.setdefault("scale", i)
            scale, other = float(log.attrs["scale"]), float(logs[j].attrs["scale"])
            if scale != other:
                raise ShipidError(f"{label[i]} is at scale 1:{scale:g} and {label[j]} at "
                                  f"1:{other:g}: the logs of one fit must be at one scale (read "
                                  "the trial files with the same --scale)")  # fmt: skip
        if log.attrs.get("particulars"):
            j = first.setdefault("particulars", i)
            apart = dimension_apart(log.attrs["particulars"], logs[j].attrs["particulars"])
            if apart:
                key, value, other = apart
                raise ShipidError(f"{label[i]}'s particulars give a {key} of {value:g} and "
                                  f"{label[j]}'s {other:g}: {ONE_SHIP}")


# The inputs a fit can hold only where every training log has them: (columns, what they are).
PARTLY_LOGGED = ((("n",), "the propeller speed n"), (("thrust",), "the thrust"),
                 (("wind_speed", "wind_angle"), "the relative wind"))  # fmt: skip


def partly_logged(logs: Sequence[pd.DataFrame], names: Sequence[str]) -> list[str]:
    """One note per input (``PARTLY_LOGGED``) some training logs have and others lack: a term of
    it cannot be fitted where it is missing, so a fit leaves it out. One Esso Osaka file read
    without its propeller speed beside one with it was fitted by the paper's structure without
    n, unsaid, though the two ran at 15 and 16.7 rps."""
    out = []
    every_rps = all("n" in log.columns for log in logs)
    for columns, what in PARTLY_LOGGED:
        if columns == ("thrust",) and every_rps:
            continue  # the propeller is held by its rps; the thrust is then no input of a fit
        lacking = [name for log, name in zip(logs, names, strict=True)
                   if not set(columns) <= set(log.columns)]  # fmt: skip
        if lacking and len(lacking) < len(logs):
            shown = ", ".join(lacking[:3]) + (", …" if len(lacking) > 3 else "")
            out.append(f"{what} is logged in {len(logs) - len(lacking)} of the {len(logs)} "
                       f"training logs, not in {shown}: no term of it can be fitted to those, so "
                       "the model leaves it out and cannot follow a change of it; log it in "
                       "every training log, or fit those logs apart")  # fmt: skip
    return out


def _running_samples(log: pd.DataFrame) -> np.ndarray | None:
    """Where a log that starts without headway runs ahead (None: it starts running)."""
    u = log["u"].to_numpy(dtype=float)
    typical = float(np.percentile(u, 90)) if u.size else 0.0
    start = float(u[: max(1, len(u) // 50)].mean()) if u.size else 0.0
    if not typical > 0 or start >= STANDSTILL_SHARE * typical:
        return None
    return u >= RUNNING_SHARE * typical


def approach(log: pd.DataFrame, column: str) -> float | None:
    """The log's approach condition of a column (None if absent): its mean over the first 2 % of
    the log; for a log that starts without headway, its median where the ship runs ahead
    (``approach_note`` says so). The plausibility checks and the manoeuvres run on a model start
    from it: from 0.02 m/s they said nothing of the ship (a random run begun at rest)."""
    if column not in log.columns:
        return None
    running = _running_samples(log)
    if running is not None:
        return float(np.median(log[column].to_numpy(dtype=float)[running]))
    return float(log[column].iloc[: max(1, len(log) // 50)].mean())


def relative_wind(u, v, psi, wind: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The relative wind (``wind_speed`` [m/s], ``wind_angle`` [rad]: where it comes from,
    clockwise from the bow) an anemometer on the ship reads in a constant true ``wind`` (speed,
    the direction it blows from [rad]): the air over the ground less the ship's velocity, in the
    body frame, as the compiled closed loop turns it (``shipid.dynamics.kernel``);
    ``mean_true_wind`` reverses it."""
    u, v, psi = (np.asarray(x, dtype=float) for x in (u, v, psi))
    c, s = np.cos(psi), np.sin(psi)
    ax = -wind[0] * math.cos(wind[1]) - (u * c - v * s)
    ay = -wind[0] * math.sin(wind[1]) - (u * s + v * c)
    bx, by = ax * c + ay * s, -ax * s + ay * c
    return np.hypot(bx, by), np.arctan2(-by, -bx)


def true_air_velocity(log: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """The air's velocity over the ground in the body frame [m/s] from a log's relative wind:
    the relative air, −U_A (cos γ_A, sin γ_A), plus the ship's (u, v)."""
    U, g = log["wind_speed"].to_numpy(dtype=float), log["wind_angle"].to_numpy(dtype=float)
    return (log["u"].to_numpy(dtype=float) - U * np.cos(g),
            log["v"].to_numpy(dtype=float) - U * np.sin(g))


def mean_true_wind(log: pd.DataFrame) -> tuple[float, float] | None:
    """The log's mean true wind (speed [m/s], the direction it blows from [rad], clockwise from
    north: the constant wind a closed-loop manoeuvre takes, ``shipid.dynamics.kernel``), from
    its relative wind, velocity and heading: the air's velocity over the ground, averaged as a
    vector. None without a relative wind or a heading."""
    if not {"wind_speed", "wind_angle", "psi"} <= set(log.columns):
        return None
    bx, by = true_air_velocity(log)
    psi = log["psi"].to_numpy(dtype=float)
    c, s = np.cos(psi), np.sin(psi)
    wx, wy = float(np.nanmean(bx * c - by * s)), float(np.nanmean(bx * s + by * c))
    if not (math.isfinite(wx) and math.isfinite(wy)):
        return None
    return math.hypot(wx, wy), math.atan2(-wy, -wx)


def starts_without_headway(log: pd.DataFrame) -> bool:
    """Whether ``approach`` takes the log's running condition instead of its start."""
    return _running_samples(log) is not None


def approach_note(log: pd.DataFrame, name: str) -> str | None:
    """What ``approach`` did for a log that starts without headway (None: nothing to say)."""
    if not starts_without_headway(log):
        return None
    start = float(log["u"].iloc[: max(1, len(log) // 50)].mean())
    rps = approach(log, "n")
    at = f"{approach(log, 'u'):.3g} m/s" + (f" at {rps:.3g} rps" if rps is not None else "")
    return (f"{name} starts without headway ({start:.2g} m/s): the checks, and the manoeuvres "
            f"run on the model, start from its running condition, {at} (the median where it "
            f"runs ahead at half its typical speed or more; --speed and --rps to choose)")


# A run is steady when its speed changes by less than this share of it in STEADY_WINDOW s (the
# rule a model's approach is held to too, ``shipid.dynamics.equilibrium``).
STEADY_SHARE = 0.05
STEADY_WINDOW = 10.0
# A log's approach: up to its first rudder order (the rudder this far from its first angle) or
# until its heading has turned by STRAIGHT_RAD, at most STEADY_WINDOW long.
ORDER_RAD = math.radians(5.0)
STRAIGHT_RAD = 0.05


@dataclass(frozen=True)
class SteadyStart:
    """How a log starts: its mean speed over the approach, the speed's change per
    ``STEADY_WINDOW`` s relative to it (a least-squares slope), and whether that is steady:
    True, False (it clearly speeds up or slows down, or turns), or None (too short or too noisy
    to tell)."""

    speed: float
    change: float
    steady: bool | None


def steady_start(log: pd.DataFrame, end_index: int | None = None) -> SteadyStart:
    """Whether ``log`` starts on a steady straight approach, up to ``end_index`` (default: its
    first rudder order or heading change, or ``STEADY_WINDOW`` s). Unsteady only where the slope
    is clear: beyond ``STEADY_SHARE`` per ``STEADY_WINDOW`` s and three standard errors from
    zero; a short or noisy approach cannot be told (None)."""
    t = log["t"].to_numpy(dtype=float)
    u = log["u"].to_numpy(dtype=float)
    delta = log["delta"].to_numpy(dtype=float)
    largest = float(np.max(np.abs(delta)))
    if end_index is None and largest > ORDER_RAD and abs(delta[0]) >= 0.5 * largest:
        # The rudder is hard over from the first sample: the log has no approach to judge.
        return SteadyStart(float(u[0]), math.nan, None)
    if end_index is None:
        heading = cumulative_integral(log["r"].to_numpy(dtype=float), t)
        moved = np.flatnonzero((np.abs(delta - delta[0]) > ORDER_RAD)
                               | (np.abs(heading) > STRAIGHT_RAD)
                               | (t - t[0] > STEADY_WINDOW))  # fmt: skip
        end_index = int(moved[0]) if moved.size else len(t) - 1
    end = max(int(end_index), 1)
    tt, uu = t[: end + 1] - t[0], u[: end + 1]
    speed = float(np.mean(uu))
    if len(tt) < 3 or not speed > 0:
        return SteadyStart(speed, math.nan, None)
    A = np.column_stack([np.ones_like(tt), tt - tt.mean()])
    coef, *_ = np.linalg.lstsq(A, uu, rcond=None)
    resid = uu - A @ coef
    se = float(np.sqrt(resid @ resid / max(len(tt) - 2, 1) / np.sum((tt - tt.mean()) ** 2)))
    change = float(coef[1]) * STEADY_WINDOW / speed
    if abs(float(np.mean(column_values(log, "r")[: end + 1]))) * tt[-1] > STRAIGHT_RAD:
        return SteadyStart(speed, change, False)
    if abs(change) <= STEADY_SHARE:
        return SteadyStart(speed, change, True)
    return SteadyStart(speed, change, False if abs(coef[1]) > 3 * se else None)


def rudder_positive(log: pd.DataFrame, default: str = "port") -> str:
    """Where a positive rudder angle turns the ship: 'port' or 'starboard'."""
    side = log.attrs.get("rudder_positive", default)
    if side not in RUDDER_SIDES:
        raise ShipidError(f"{log_name(log)}: metadata rudder_positive must be 'port' or "
                          f"'starboard', got {side!r}")  # fmt: skip
    return side


def in_rudder_convention(log: pd.DataFrame, side: str | None) -> tuple[pd.DataFrame, str | None]:
    """``log`` with its rudder angle in ``side``'s convention ('port' or 'starboard': where a
    positive angle turns the ship), and a note when it had to be converted (δ → −δ, the
    metadata with it). A log without the metadata, or no ``side``, is taken as it is: nothing
    says which convention it has."""
    own = log.attrs.get("rudder_positive")
    if side is None or own is None or own == side:
        return log, None
    rudder_positive(log)  # a malformed value is an error, not a convention
    out = log.copy()
    out["delta"] = -out["delta"]
    out.attrs = {**log.attrs, "rudder_positive": side}
    return out, (f"{log_name(log)}: a positive rudder angle turns it to {own}; its rudder angle "
                 f"is negated to the {side}-positive convention of the "
                 "model/other logs")  # fmt: skip


def common_rudder_convention(logs: list[pd.DataFrame], side: str | None = None
                             ) -> tuple[list[pd.DataFrame], list[str]]:  # fmt: skip
    """Logs in one rudder convention: ``side`` (a model's), else the first log's that states one;
    the notes say which logs were converted. Mixing conventions unconverted mirrors the rudder
    of some logs: a model fitted across them, or run on them, turns the wrong way."""
    if side is None:
        side = next((log.attrs["rudder_positive"] for log in logs
                     if log.attrs.get("rudder_positive")), None)  # fmt: skip
    out, notes = [], []
    for log in logs:
        converted, note = in_rudder_convention(log, side)
        out.append(converted)
        if note:
            notes.append(note)
    return out, notes


def starboard_sign(rudder_positive_turns: str) -> float:
    """Sign of the rudder angle that turns the ship to starboard (r > 0)."""
    return 1.0 if rudder_positive_turns == "starboard" else -1.0


def input_columns(log: pd.DataFrame, columns, name: str | None = None) -> dict[str, np.ndarray]:
    """The input series (e.g. 'thrust', 'n', 'wind_speed') a model needs, or an error naming the
    column."""
    missing = [c for c in columns if c not in log.columns]
    if missing:
        label = name or log_name(log)
        raise ShipidError(f"{label}: the model needs the log column {missing[0]!r} "
                          f"({COLUMN_DESCRIPTIONS.get(missing[0], missing[0])}), which this log "
                          "does not have")  # fmt: skip
    return {c: column_values(log, c) for c in columns}


COLUMN_DESCRIPTIONS = {
    "t": "time [s]", "delta": "rudder angle [rad]", "u": "surge speed [m/s]",
    "v": "sway speed [m/s]", "r": "yaw rate [rad/s]", "psi": "heading [rad]", "x": "north [m]",
    "y": "east [m]", "n": "propeller speed [rps]", "thrust": "thrust [N]",
    "wind_speed": "relative wind speed [m/s]", "wind_angle": "relative wind angle [rad]",
}  # fmt: skip


def metadata(log: pd.DataFrame) -> dict:
    """The metadata of ``log`` that files keep (``METADATA_KEYS``), JSON-safe."""
    out = {}
    for k in METADATA_KEYS:
        v = log.attrs.get(k)
        if v is None:
            continue
        if isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out


def check_metadata(meta: Mapping, name: str) -> dict:
    """Metadata read from a file: known keys with sensible values, or an error naming the key."""
    if not isinstance(meta, Mapping):
        raise ShipidError(f"{name}: log metadata must be a JSON object, got {type(meta).__name__}")
    out = {}
    for k, v in meta.items():
        if k not in METADATA_KEYS:
            continue  # written by a newer shipid: ignored, not an error
        if k == "rudder_positive" and v not in RUDDER_SIDES:
            raise ShipidError(f"{name}: metadata rudder_positive must be 'port' or 'starboard', "
                              f"got {v!r}")  # fmt: skip
        if k == "scale" and not (isinstance(v, int | float) and not isinstance(v, bool)
                                 and math.isfinite(v) and v > 0):
            raise ShipidError(f"{name}: metadata scale must be a number > 0, got {v!r}")
        if k == "yaw_rate_offset" and not (isinstance(v, int | float) and not isinstance(v, bool)
                                           and math.isfinite(v)):
            raise ShipidError(f"{name}: metadata yaw_rate_offset must be a number [rad/s], "
                              f"got {v!r}")  # fmt: skip
        if k == "track_origin" and not (
                isinstance(v, Mapping) and set(v) == {"lat", "lon"}
                and all(isinstance(a, int | float) and not isinstance(a, bool) and math.isfinite(a)
                        for a in v.values())):
            raise ShipidError(f"{name}: metadata track_origin must be {{'lat': deg, 'lon': deg}}, "
                              f"got {v!r}")  # fmt: skip
        if k == "integrator" and not (
                isinstance(v, Mapping) and set(v) == {"method", "step"}
                and v["method"] in ("euler", "rk4") and isinstance(v["step"], int | float)
                and not isinstance(v["step"], bool) and math.isfinite(v["step"]) and v["step"] > 0):
            raise ShipidError(f"{name}: metadata integrator must be {{'method': 'euler' or 'rk4', "
                              f"'step': s > 0}}, got {v!r}")  # fmt: skip
        if k == "particulars":
            from shipid.data.particulars import Particulars

            v = Particulars.from_mapping(v, f"{name} metadata").to_dict()
        out[k] = frozen(v)
    return out


def csv_metadata_line(log: pd.DataFrame) -> str:
    """The ``# shipid-log: {...}`` first line of a CSV log."""
    return CSV_METADATA_PREFIX + json.dumps(metadata(log), ensure_ascii=False) + "\n"


def parse_csv_metadata(first_lines: list[str], name: str) -> dict:
    """The metadata of a CSV log's ``# shipid-log:`` comment line, {} when there is none."""
    for line in first_lines:
        if line.startswith(CSV_METADATA_PREFIX):
            try:
                meta = json.loads(line[len(CSV_METADATA_PREFIX) :])
            except json.JSONDecodeError as exc:
                raise ShipidError(f"{name}: malformed shipid-log metadata line ({exc})") from None
            return check_metadata(meta, name)
    return {}
