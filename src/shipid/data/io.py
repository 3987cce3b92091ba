"""Trial logs in and out: canonical CSV/Parquet with column mapping, degree conversion, resampling
and trimming, and checks that name the file, column and row of bad input."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from shipid.data.formats import read_format
from shipid.data.log import COLUMNS, REQUIRED
from shipid.data.preprocess import resample
from shipid.data.trim import trim, true_runs
from shipid.errors import ShipidError
from shipid.outputs import atomic_write

ANGLE_COLUMNS = ("delta", "psi", "r")
UNIT_SUFFIX = re.compile(r"\s*\[[^\]]*\]\s*$")
# A rudder beyond 60° or a yaw rate beyond 3 rad/s (172 °/s) is not radians.
RADIAN_PLAUSIBLE = {"delta": math.radians(60.0), "r": 3.0}


def parse_column_map(spec: str | None) -> dict[str, str]:
    """'t=time,delta=rudder' → {'time': 't', 'rudder': 'delta'} (file name → canonical name)."""
    if not spec:
        return {}
    out = {}
    for item in spec.split(","):
        if "=" not in item:
            raise ShipidError(f"--columns expects canonical=file pairs like t=time, got {item!r}")
        canon, name = (s.strip() for s in item.split("=", 1))
        if canon not in COLUMNS:
            raise ShipidError(f"--columns: {canon!r} is not a canonical column ({', '.join(COLUMNS)})")
        out[name] = canon
    return out


def _check_file(path: Path) -> None:
    if not path.exists():
        raise ShipidError(f"{path}: no such file")
    if path.is_dir():
        raise ShipidError(f"{path}: is a directory, not a log file")
    if path.stat().st_size == 0:
        raise ShipidError(f"{path}: the file is empty")


def _read_table(path: Path) -> pd.DataFrame:
    _check_file(path)
    if path.suffix.lower() in (".parquet", ".pq"):
        try:
            return pd.read_parquet(path)
        except Exception as exc:  # pyarrow raises several types for a bad file
            raise ShipidError(f"{path}: not a readable Parquet file ({exc})") from None
    head = path.read_bytes()[:4096]
    if b"\x00" in head:
        raise ShipidError(f"{path}: binary file, not a CSV log (use .parquet for Parquet)")
    try:
        return pd.read_csv(path, skip_blank_lines=True, comment="#")
    except UnicodeDecodeError:
        raise ShipidError(f"{path}: not a text CSV file") from None
    except pd.errors.EmptyDataError:
        raise ShipidError(f"{path}: the file has no header and no rows") from None
    except pd.errors.ParserError as exc:
        raise ShipidError(f"{path}: not a valid CSV file ({str(exc).splitlines()[0]})") from None


def check_log(df: pd.DataFrame, name: str, min_samples: int = 3, fill_gaps: bool = False) -> None:
    """Required columns, finite numbers, strictly increasing time, enough samples.

    Missing values (empty cells, NaN) inside a signal are reported with their span and refused,
    or, with ``fill_gaps``, interpolated linearly in time. Text and infinities are always refused.
    """
    if len(df) == 0:
        raise ShipidError(f"{name}: the header has no rows")
    missing = [c for c in REQUIRED if c not in df.columns]
    if missing:
        have = ", ".join(map(str, df.columns))
        raise ShipidError(f"{name}: missing column(s) {', '.join(missing)} (columns found: {have}); "
                          "map other names with --columns, e.g. --columns delta=rudder")  # fmt: skip
    gaps: dict[str, np.ndarray] = {}
    for c in [c for c in COLUMNS if c in df.columns]:
        raw = df[c]
        values = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)
        gap = raw.isna().to_numpy()
        bad = ~np.isfinite(values) & ~gap
        if bad.any():
            row = int(np.argmax(bad))
            raise ShipidError(f"{name}: column {c!r} has a non-numeric or non-finite value "
                              f"({raw.iloc[row]!r}) at data row {row + 1}")  # fmt: skip
        if gap.any():
            gaps[c] = gap
        df[c] = values
    if "t" in gaps:
        first, last = true_runs(gaps["t"])[0]
        raise ShipidError(f"{name}: column 't' is missing at data rows {first + 1}–{last + 1}; "
                          "a log needs a time stamp on every row")  # fmt: skip
    t = df["t"].to_numpy()
    for c, gap in gaps.items():
        runs = true_runs(gap)
        first, last = runs[0]
        if np.all(gap):
            raise ShipidError(f"{name}: column {c!r} is empty")
        if not fill_gaps:
            more = f" and {len(runs) - 1} more gap(s)" if len(runs) > 1 else ""
            span = (f"1 missing value at data row {first + 1} (t = {t[first]:g} s)" if first == last
                    else f"{last - first + 1} missing values at data rows {first + 1}–{last + 1} "
                    f"(t = {t[first]:g}–{t[last]:g} s)")
            raise ShipidError(f"{name}: column {c!r} has {span}{more}; trim them off with "
                              "--start/--end or interpolate with --fill-gaps")  # fmt: skip
        good = ~gap
        df[c] = np.interp(t, t[good], df[c].to_numpy()[good])
    dt = np.diff(t)
    if np.any(dt == 0):
        row = int(np.argmax(dt == 0)) + 1
        raise ShipidError(f"{name}: duplicate time stamp t = {t[row]:g} "
                          f"at data rows {row} and {row + 1}")
    if np.any(dt < 0):
        row = int(np.argmax(dt < 0)) + 1
        raise ShipidError(f"{name}: time is not increasing at data row {row + 1} "
                          f"(t = {t[row]:g} after {t[row - 1]:g})")  # fmt: skip
    if len(df) < min_samples:
        raise ShipidError(f"{name}: {len(df)} samples, too short (at least {min_samples} needed)")


def read_log(
    path: str | Path,
    columns: Mapping[str, str] | None = None,
    degrees: Sequence[str] = (),
    dt: float | None = None,
    start: float | None = None,
    end: float | None = None,
    rudder_positive: str | None = None,
    fmt: str = "canonical",
    scale: float | None = None,
    lead: float = 5.0,
    fill_gaps: bool = False,
) -> pd.DataFrame:
    """Read a trial log: canonical CSV/Parquet, or a known format (see ``shipid.formats``).

    columns : file column name → canonical name. degrees : canonical angle columns given in degrees
    (delta, psi in deg; r in deg/s). dt : resample to this Δk. start/end : trim [s]; start="auto"
    trims to ``lead`` seconds before the detected rudder execute. rudder_positive : overrides the
    format's rudder convention. scale : Froude scale λ (MARIN). fill_gaps : interpolate missing
    values inside signals instead of refusing the log.
    """
    path = Path(path)
    if fmt != "canonical":
        _check_file(path)
        log = read_format(path, fmt, scale)
        check_log(log, str(path), fill_gaps=fill_gaps)
        if rudder_positive:
            log.attrs["rudder_positive"] = rudder_positive
        return _trim_resample(log, dt, start, end, path, lead)
    df = _read_table(path)
    # "u_velo [m/s]" → "u_velo": units in brackets are documentation, not part of the name.
    df.columns = [UNIT_SUFFIX.sub("", str(c)).strip() for c in df.columns]
    df = df.rename(columns=dict(columns or {}))
    df = df.dropna(how="all").reset_index(drop=True)
    check_log(df, str(path), fill_gaps=fill_gaps)
    for c in degrees:
        if c not in ANGLE_COLUMNS:
            raise ShipidError(f"--degrees: {c!r} is not an angle column ({', '.join(ANGLE_COLUMNS)})")
        if c in df.columns:
            df[c] = np.radians(df[c].to_numpy())
    for c, limit in RADIAN_PLAUSIBLE.items():
        if c not in degrees and np.max(np.abs(df[c].to_numpy())) > limit:
            peak = np.max(np.abs(df[c]))
            raise ShipidError(f"{path}: column {c!r} reaches {peak:.3g}, which looks like degrees; "
                              f"give --degrees {c} (angles are radians inside)")
    log = df[[c for c in COLUMNS if c in df.columns]].copy()
    log.attrs.update({"name": path.name, "source": str(path),
                      "rudder_positive": rudder_positive or "port"})  # fmt: skip
    return _trim_resample(log, dt, start, end, path, lead)


def _trim_resample(log: pd.DataFrame, dt, start, end, path: Path, lead: float) -> pd.DataFrame:
    if start is not None or end is not None:
        log = trim(log, start, end, str(path), lead)
    if dt is not None:
        log = resample(log, dt, str(path))
    return log


def write_log(log: pd.DataFrame, path: str | Path) -> Path:
    """Write a canonical log atomically (CSV, or Parquet by extension)."""
    path = Path(path)
    if path.suffix.lower() in (".parquet", ".pq"):
        return atomic_write(path, lambda p: log.to_parquet(p, index=False))
    return atomic_write(path, lambda p: log.to_csv(p, index=False, float_format="%.9g"))
