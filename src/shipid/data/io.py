"""Trial logs in and out: canonical CSV/Parquet with column mapping, degree conversion, resampling
and trimming, and checks that name the file, column and row of bad input.

Logs are written with every float at full precision (so times and Δk survive exactly) and with
their metadata (ship, source, rudder convention, scale): Parquet in its schema metadata, CSV in a
first comment line ``# shipid-log: {...}``. A log written by shipid reads back as it was.
"""

from __future__ import annotations

import dataclasses
import math
import mmap
import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from shipid.data.checks import (
    ANGLE_COLUMNS,
    check_log,
    check_propulsion,
    check_rudder_convention,
    check_units,
)
from shipid.data.formats import FORMATS, detect_format, read_format
from shipid.data.geodetic import GEODETIC_COLUMNS, check_geodetic, local_track
from shipid.data.header_units import si_factors, split_units
from shipid.data.log import (
    COLUMNS,
    REQUIRED,
    column_values,
    csv_metadata_line,
    frozen,
    metadata,
    parse_csv_metadata,
)
from shipid.data.preprocess import resample
from shipid.data.track_velocities import (
    GROUND_VELOCITY_COLUMNS,
    TrackVelocities,
    velocities_from_ground_velocity,
    velocities_from_track,
)
from shipid.data.trim import DEFAULT_LEAD_S, trim
from shipid.data.yaw_rate import correct_yaw_rate
from shipid.errors import ShipidError, ShipidWarning
from shipid.outputs import atomic_write

# No log line comes near this: a canonical row is ~200 characters. Longer lines are not logs, and
# parsing a line of millions of fields takes minutes.
MAX_LINE_BYTES = 65_536


@dataclass(frozen=True)
class ReadOptions:
    """How to read a trial log.

    Attributes
    ----------
    fmt : 'canonical' (CSV/Parquet) or a known format (``shipid.data.formats.FORMATS``).
    columns : file column name → canonical name (canonical format).
    degrees : canonical angle columns given in degrees (delta, psi, wind_angle in deg; r in deg/s).
    dt : resample to this Δk [s].
    start, end : trim [s], or 'auto'; end also 'dropout' (``shipid.data.trim.trim``).
    lead : with ``start='auto'``, seconds kept before the rudder execute.
    rudder_positive : overrides the file's rudder convention ('port' or 'starboard').
    scale : Froude scale λ (simman formats).
    fill_gaps : interpolate missing values inside signals, and with ``dt`` across gaps in time,
        instead of refusing the log.
    yaw_rate_offset : a gyro's offset to subtract from r [rad/s], or 'auto' for each log's own,
        read off its heading (``shipid.data.yaw_rate``); None leaves r as measured.
    velocities : 'auto': u, v as logged, or read off the track (x, y, psi) where the log has
        neither; 'track': read off the track even where logged (``shipid.data.track_velocities``).
    track : how they are read off the track (window, the antenna's place).
    """

    fmt: str = "canonical"
    columns: Mapping[str, str] = field(default_factory=dict)
    degrees: tuple[str, ...] = ()
    dt: float | None = None
    start: float | str | None = None
    end: float | str | None = None
    lead: float = DEFAULT_LEAD_S
    rudder_positive: str | None = None
    scale: float | None = None
    fill_gaps: bool = False
    yaw_rate_offset: float | str | None = None
    velocities: str = "auto"
    track: TrackVelocities = field(default_factory=TrackVelocities)

    def __post_init__(self) -> None:
        if self.velocities not in ("auto", "track"):
            raise ShipidError(f"velocities must be 'auto' or 'track', got {self.velocities!r}")
        if not (self.yaw_rate_offset in (None, "auto") or (
                isinstance(self.yaw_rate_offset, int | float)
                and math.isfinite(self.yaw_rate_offset))):
            raise ShipidError(f"yaw_rate_offset must be None, 'auto' or a finite number "
                              f"[rad/s], got {self.yaw_rate_offset!r}")  # fmt: skip
        if self.fmt not in FORMATS:
            raise ShipidError(f"unknown --format {self.fmt!r}; use one of {', '.join(FORMATS)}")
        object.__setattr__(self, "degrees", tuple(self.degrees))
        for c in self.degrees:
            if c not in ANGLE_COLUMNS:
                raise ShipidError(f"--degrees: {c!r} is not an angle column "
                                  f"({', '.join(ANGLE_COLUMNS)})")  # fmt: skip
        if self.rudder_positive not in (None, "port", "starboard"):
            raise ShipidError(f"--rudder-positive must be port or starboard, got "
                              f"{self.rudder_positive!r}")  # fmt: skip


def parse_column_map(spec: str | None) -> dict[str, str]:
    """'t=time,delta=rudder' → {'time': 't', 'rudder': 'delta'} (file name → canonical name)."""
    if not spec:
        return {}
    out = {}
    for item in spec.split(","):
        if "=" not in item:
            raise ShipidError(f"--columns expects canonical=file pairs like t=time, got {item!r}")
        canon, name = (s.strip() for s in item.split("=", 1))
        known = COLUMNS + GEODETIC_COLUMNS + GROUND_VELOCITY_COLUMNS
        if canon not in known:
            raise ShipidError(f"--columns: {canon!r} is not a canonical column "
                              f"({', '.join(known)})")  # fmt: skip
        out[name] = canon
    return out


def _mapped_from_nothing(columns, mapping: Mapping[str, str], name: str) -> None:
    """A warning where ``--columns`` maps a column the file lacks onto one it has: the file's
    own column is read instead, which a misspelt ``delta=rudr`` left unsaid. (Where the file
    has neither, the missing column's error names both.)"""
    absent = [(canon, source) for source, canon in mapping.items()
              if source not in columns and canon in columns]  # fmt: skip
    for canon, source in absent:
        warnings.warn(f"{name}: --columns {canon}={source}: the file has no column {source!r}, "
                      f"so its own {canon!r} is read", ShipidWarning, stacklevel=3)  # fmt: skip


def _check_file(path: Path) -> None:
    if not path.exists():
        raise ShipidError(f"{path}: no such file")
    if path.is_dir():
        raise ShipidError(f"{path}: is a directory, not a log file")
    if path.stat().st_size == 0:
        raise ShipidError(f"{path}: the file is empty")


def longest_line(path: Path) -> tuple[int, int]:
    """(length in bytes, 1-based line number) of the longest line, in one pass over the file."""
    with open(path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as mm:
        ends = np.flatnonzero(np.frombuffer(mm, dtype=np.uint8) == 10)
        size = len(mm)
    bounds = np.concatenate([[-1], ends, [size] if (ends.size == 0 or ends[-1] != size - 1) else []])
    lengths = np.diff(bounds) - 1
    k = int(np.argmax(lengths))
    return int(lengths[k]), k + 1


DECIMAL_COMMA = re.compile(r"^-?\d+,\d+([eE][-+]?\d+)?$")


def _separators(lines: Sequence[str]) -> tuple[str, str]:
    """Field separator and decimal mark of a CSV from its first lines: commas, or the
    semicolons (with decimal commas where its numbers have them) or tabs that spreadsheets in
    many locales write."""
    rows = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
    if not rows or "," in rows[0]:
        return ",", "."
    for sep in (";", "\t"):
        if sep in rows[0]:
            fields = [f.strip() for f in rows[1].split(sep)] if len(rows) > 1 else []
            comma = sep == ";" and any(DECIMAL_COMMA.match(f) for f in fields)
            return sep, "," if comma else "."
    return ",", "."


def _read_table(path: Path) -> tuple[pd.DataFrame, dict]:
    """The raw table of a canonical CSV/Parquet log and the metadata the file carries."""
    _check_file(path)
    if path.suffix.lower() in (".parquet", ".pq"):
        try:
            df = pd.read_parquet(path)
        except Exception as exc:  # pyarrow raises several types for a bad file
            raise ShipidError(f"{path}: not a readable Parquet file "
                              f"({str(exc).splitlines()[0][:200]})") from None  # fmt: skip
        from shipid.data.log import check_metadata

        return df, check_metadata(dict(df.attrs), str(path))
    with open(path, "rb") as fh:
        head = fh.read(4096)
    if b"\x00" in head:
        raise ShipidError(f"{path}: binary file, not a CSV log (use .parquet for Parquet)")
    length, line = longest_line(path)
    if length > MAX_LINE_BYTES:
        raise ShipidError(f"{path}: line {line} is {length} characters long; a log line is a few "
                          "hundred: not a CSV log (or a broken one)")  # fmt: skip
    first_lines = head.decode("utf-8", errors="replace").splitlines()[:5]
    meta = parse_csv_metadata(first_lines, str(path))
    sep, decimal = _separators(head.decode("utf-8", errors="replace").splitlines())
    try:
        df = pd.read_csv(path, skip_blank_lines=True, comment="#", sep=sep, decimal=decimal)
    except UnicodeDecodeError:
        raise ShipidError(f"{path}: not a text CSV file") from None
    except pd.errors.EmptyDataError:
        raise ShipidError(f"{path}: the file has no header and no rows") from None
    except pd.errors.ParserError as exc:
        raise ShipidError(f"{path}: not a valid CSV file ({str(exc).splitlines()[0]})") from None
    _refuse_repeated_columns(path, sep, decimal, df)
    return df, meta


def _refuse_repeated_columns(path: Path, sep: str, decimal: str, df: pd.DataFrame) -> None:
    """One line where the header names a column twice: pandas reads the second 'u' as 'u.1',
    and the log's u was then the first of two without a word."""
    if not any("." in str(c) for c in df.columns):  # pandas marks a repeat 'name.k'
        return
    header = pd.read_csv(path, skip_blank_lines=True, comment="#", sep=sep, decimal=decimal,
                         header=None, nrows=1, dtype=str).iloc[0]  # fmt: skip
    names = [str(c).strip() for c in header]
    repeated = next((c for c in names if names.count(c) > 1), None)
    if repeated is not None:
        where = ", ".join(str(i + 1) for i, c in enumerate(names) if c == repeated)
        raise ShipidError(f"{path}: column {repeated!r} appears more than once in the header "
                          f"(columns {where}): which is the log's is not known")  # fmt: skip


def _hint_format(path: Path, exc: ShipidError) -> ShipidError:
    fmt = detect_format(path)
    if fmt is None:
        return exc
    return ShipidError(f"{path}: not a canonical log, but its layout is that of {fmt}: read it "
                       f"with --format {fmt}")


def _known_format(path: Path, options: ReadOptions) -> str | None:
    """The known format (``detect_format``) of a file that is not a canonical log, where it can
    be read as that without --format: no option of the canonical reader (--columns,
    --degrees) was given. None otherwise."""
    return None if options.columns or options.degrees else detect_format(path)


def _as_known_format(path: Path, options: ReadOptions, fmt: str) -> pd.DataFrame:
    """``path`` read as ``fmt`` (``_known_format``), saying so."""
    warnings.warn(f"{path}: not a canonical log; read as {fmt}, whose layout it has (--format "
                  f"{fmt} says so)", ShipidWarning, stacklevel=3)  # fmt: skip
    return read_log(path, dataclasses.replace(options, fmt=fmt))


def read_log(path: str | Path, options: ReadOptions | None = None, **overrides) -> pd.DataFrame:
    """Read a trial log: canonical CSV/Parquet, or a known format (see ``shipid.data.formats``).

    ``options`` (a ``ReadOptions``) or its fields as keywords, e.g.
    ``read_log(p, fmt="osaka-frt", start="auto", end="auto")``.
    """
    options = options or ReadOptions()
    if overrides:
        unknown = set(overrides) - {f.name for f in dataclasses.fields(ReadOptions)}
        if unknown:
            raise TypeError(f"read_log: unknown option(s) {sorted(unknown)}")
        options = dataclasses.replace(options, **overrides)
    path = Path(path)
    name = str(path)
    if options.scale is not None and options.fmt == "canonical":
        # A SIMMAN file given its scale without --format.
        fmt = _known_format(path, options) if path.is_file() else None
        if fmt in ("simman-marin", "simman-hsva"):
            return _as_known_format(path, options, fmt)
    if options.scale is not None and options.fmt in ("canonical", "osaka-frt"):
        # It was ignored: a user who gave it believed the log Froude-scaled.
        raise ShipidError(f"{name}: --scale applies to the SIMMAN files (MARIN's are full scale, "
                          f"Froude-scaled by it); a {options.fmt} log is read at its own scale "
                          "(to carry a model to another scale: shipid rescale)")  # fmt: skip
    converted: set[str] = set()  # angle columns read in degrees, for check_units' messages
    if options.fmt != "canonical":
        _check_file(path)
        mapped = ",".join(f"{canon}={source}" for source, canon in options.columns.items())
        given = [f"--{option} {value}" for option, value
                 in (("columns", mapped), ("degrees", ",".join(options.degrees))) if value]  # fmt: skip
        if given:
            warnings.warn(f"{name}: {' and '.join(given)} not applied: --format {options.fmt} "
                          "reads the file's own columns and units", ShipidWarning, stacklevel=2)
        log = read_format(path, options.fmt, options.scale)
        check_log(log, name, fill_gaps=options.fill_gaps)
        if _from_track(log.columns, options):
            log = _read_off_track(log, options, name)
        meta = {}
        stated = True
    else:
        try:
            df, meta = _read_table(path)
        except ShipidError as exc:
            fmt = _known_format(path, options) if path.is_file() else None
            if fmt is not None:
                return _as_known_format(path, options, fmt)
            raise _hint_format(path, exc) from None
        # "r [deg/s]" → "r" in °/s: a canonical column's unit is converted, others' are notes.
        bare, units = split_units(df.columns)
        df.columns = bare
        factors = si_factors(units, dict(options.columns), options.degrees, name)
        _mapped_from_nothing(df.columns, options.columns, name)
        df = df.rename(columns=dict(options.columns))
        dup = df.columns[df.columns.duplicated()].tolist()
        if dup:
            raise ShipidError(f"{path}: column {dup[0]!r} appears twice (after --columns)")
        df = df.dropna(how="all").reset_index(drop=True)
        have = set(df.columns)
        geodetic = set(GEODETIC_COLUMNS) <= have and not {"x", "y"} & have
        position = GEODETIC_COLUMNS if geodetic else ("x", "y")
        # A GNSS's speed and course over ground give u, v where the log has neither.
        ground = (set(GROUND_VELOCITY_COLUMNS) <= have and not {"u", "v"} & have
                  and options.velocities == "auto")  # fmt: skip
        from_track = not ground and _from_track(df.columns, options, geodetic)
        required = (("t", "delta", *position, "psi") if from_track
                    else ("t", "delta", *GROUND_VELOCITY_COLUMNS, "psi") if ground
                    else REQUIRED)  # fmt: skip
        extra = (GEODETIC_COLUMNS if geodetic else ()) + (GROUND_VELOCITY_COLUMNS if ground else ())
        try:
            check_log(df, name, fill_gaps=options.fill_gaps, required=required, extra=extra)
        except ShipidError as exc:
            if any(c not in df.columns for c in required):
                fmt = _known_format(path, options)
                if fmt is not None:
                    return _as_known_format(path, options, fmt)
                raise _hint_format(path, exc) from None
            raise
        if "t" in factors and "time_origin" in df.attrs:
            # Dates and clock times are already seconds; a [ms] would have scaled them again.
            raise ShipidError(f"{path}: column 't' holds dates or times of day, which carry "
                              "their own unit: drop the unit from its header")  # fmt: skip
        # Header units and --degrees (si_factors leaves a column --degrees names to it).
        factors.update({c: math.pi / 180.0 for c in options.degrees})
        converted = {c for c, factor in factors.items() if factor == math.pi / 180.0}
        for c, factor in factors.items():
            if c in df.columns:
                df[c] = column_values(df, c) * factor
        if geodetic:
            lat, lon = (column_values(df, c, float) for c in GEODETIC_COLUMNS)
            check_geodetic(lat, lon, name)
            df["x"], df["y"] = local_track(lat, lon)
            meta = {**meta, "track_origin": frozen({"lat": float(lat[0]), "lon": float(lon[0])})}
        if ground:
            df = _read_off_ground_velocity(df, options, name)
            meta = {**meta, "velocities": df.attrs["velocities"]}
        log = df[[c for c in COLUMNS if c in df.columns]].copy()
        if from_track:
            log = _read_off_track(log, options, name)
        log.attrs.update({"source": str(path), "rudder_positive": "port"})
        log.attrs.update(meta)
        stated = "rudder_positive" in meta
        log.attrs.update({k: df.attrs[k] for k in ("time_origin",) if k in df.attrs})
    check_units(log, name, options.degrees, offset_given=options.yaw_rate_offset is not None,
                converted=converted)
    log.attrs["name"] = path.name
    if options.rudder_positive:
        log.attrs["rudder_positive"] = options.rudder_positive
        stated = True
    if options.start is not None or options.end is not None:
        log = trim(log, options.start, options.end, name, options.lead)
    if options.yaw_rate_offset is not None:
        log = correct_yaw_rate(log, options.yaw_rate_offset, name)
    check_propulsion(log, name)
    check_rudder_convention(log, name, stated)
    if options.dt is not None:
        log = resample(log, options.dt, name, fill_gaps=options.fill_gaps)
    return log


def _from_track(columns, options: ReadOptions, geodetic: bool = False) -> bool:
    """Whether u, v are read off the track: asked for, or the log has neither but x, y (or
    lat, lon: ``geodetic``) and psi."""
    if options.velocities == "track":
        return True
    have = set(columns) | ({"x", "y"} if geodetic else set())
    derive = not have & {"u", "v"} and {"x", "y", "psi"} <= have
    if not derive and options.track != TrackVelocities():
        raise ShipidError("--antenna and --track-window apply where u, v are read off the track: "
                          "the log has u, v (give --velocities-from-track to read them off the "
                          "track instead)")  # fmt: skip
    return derive


def _read_off_ground_velocity(df: pd.DataFrame, options: ReadOptions, name: str) -> pd.DataFrame:
    out = velocities_from_ground_velocity(df, options.track, name)
    how = out.attrs["velocities"]
    fore, starboard = how["antenna"]
    where = (f"the antenna {fore:g} m forward, {starboard:g} m to starboard" if fore or starboard
             else "the antenna taken at the reference point (--antenna FORWARD,STARBOARD "
             "otherwise)")
    also = (f"; r read off psi over a {how['heading_window_s']:.2g} s window"
            if how["r_from_heading"] else "")
    warnings.warn(f"{name}: no u, v in the log: read off its speed and course over ground (sog, "
                  f"cog) turned by psi, {where}{also}", ShipidWarning, stacklevel=3)  # fmt: skip
    return out


def _read_off_track(log: pd.DataFrame, options: ReadOptions, name: str) -> pd.DataFrame:
    attrs = dict(log.attrs)
    derived = velocities_from_track(log, options.track, name)
    out = derived[[c for c in COLUMNS if c in derived.columns]].copy()
    out.attrs = {**attrs, **derived.attrs}
    if options.velocities == "auto":
        how = out.attrs["velocities"]
        fore, starboard = how["antenna"]
        where = (f"the antenna {fore:g} m forward, {starboard:g} m to starboard" if fore or starboard
                 else "the position taken at the reference point (--antenna FORWARD,STARBOARD "
                 "otherwise)")
        also = ", and r off psi," if how["r_from_heading"] else ""
        warnings.warn(f"{name}: no u, v in the log: read off the track (x, y) and psi{also} over "
                      f"a {how['window_s']:.2g} s window (--track-window), {where}",
                      ShipidWarning, stacklevel=3)  # fmt: skip
    return out


def read_logs(paths: Sequence[str | Path], options: ReadOptions | None = None) -> list[pd.DataFrame]:
    """``read_log`` of several paths with one set of options."""
    return [read_log(p, options) for p in paths]


def write_log(log: pd.DataFrame, path: str | Path, out=None) -> Path:
    """Write a canonical log atomically (CSV, or Parquet by extension) with its metadata.

    ``out``: an ``OutputSet`` to stage the file in (written with the set), else written at once.
    """
    from shipid.data.log import require_frame

    path = Path(path)
    frame = require_frame(log, "log to write").copy()
    frame.attrs = metadata(log)
    if path.suffix.lower() in (".parquet", ".pq"):
        def writer(p: Path) -> None:
            frame.to_parquet(p, index=False)
    else:
        def writer(p: Path) -> None:
            with open(p, "w", encoding="utf-8", newline="") as fh:
                fh.write(csv_metadata_line(frame))
                # Default float format: repr, the shortest string that reads back bit for bit.
                frame.to_csv(fh, index=False)
    if out is not None:
        return out.write(path, writer)
    return atomic_write(path, writer)


def write_table(table: pd.DataFrame, path: str | Path, out=None) -> Path:
    """Write a results table (CSV, or Parquet by extension), atomically or staged in ``out``."""
    path = Path(path)
    if path.suffix.lower() in (".parquet", ".pq"):
        def writer(p: Path) -> None:
            table.to_parquet(p, index=False)
    else:
        def writer(p: Path) -> None:
            table.to_csv(p, index=False)
    return out.write(path, writer) if out is not None else atomic_write(path, writer)
