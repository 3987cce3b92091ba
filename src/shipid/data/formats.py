"""Readers of known trial formats into the canonical log (SI units, radians, body-fixed velocities).

* ``simman-marin``: KVLCC2 free-running tests by MARIN (SIMMAN 2008), full scale, 11 tab-separated
  columns printed with three significant digits after two header lines. The time column repeats at
  that precision, so time is rebuilt as uniform, t_i = i·t_end/(N − 1); velocities are earth-fixed and
  are rotated to body axes; degrees become radians; positive rudder turns the ship to port. With
  ``scale`` (λ) the log is Froude-scaled to model scale: lengths ÷ λ, times and speeds ÷ √λ,
  rates and revolutions × √λ.
* ``osaka-frt``: Esso Osaka free-running tests (Osaka University), CSV with units in the header,
  body-fixed velocities at midship, ψ wrapped (unwrapped here), empty trailing rows (dropped);
  positive rudder turns the ship to starboard.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from shipid.data.log import make_log
from shipid.errors import ShipidError

FORMATS = ("canonical", "simman-marin", "osaka-frt")
MARIN_COLUMNS = ("t", "x0", "y0", "phi", "psi", "xdot", "ydot", "p", "r", "delta", "n")
OSAKA_COLUMNS = {"t [s]": "t", "x_position_mid [m]": "x", "u_velo [m/s]": "u",
                 "y_position_mid [m]": "y", "vm_velo [m/s]": "v", "psi_hat [rad]": "psi",
                 "r_angvelo [rad/s]": "r", "n_prop [rps]": "n",
                 "delta_rudder [rad]": "delta"}  # fmt: skip


def read_simman_marin(path: str | Path, scale: float | None = None) -> pd.DataFrame:
    """A MARIN SIMMAN .dat file as a canonical log (full scale, or model scale with ``scale``)."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="ascii").splitlines()
    except UnicodeDecodeError:
        raise ShipidError(f"{path}: not a text file (--format simman-marin expects a MARIN .dat)"
                          ) from None
    rows = []
    for i, line in enumerate(lines[2:], start=3):
        fields = line.split()
        if not fields:
            continue
        if len(fields) != len(MARIN_COLUMNS):
            raise ShipidError(f"{path}: line {i} has {len(fields)} values, --format simman-marin "
                              f"expects {len(MARIN_COLUMNS)} (truncated or not a MARIN file?)")
        try:
            rows.append([float(f) for f in fields])
        except ValueError:
            raise ShipidError(f"{path}: line {i} is not numeric (--format simman-marin)") from None
    if len(rows) < 3:
        raise ShipidError(f"{path}: {len(rows)} data rows, too short (--format simman-marin)")
    d = dict(zip(MARIN_COLUMNS, np.array(rows).T, strict=True))
    n = len(rows)
    t = np.arange(n) * (d["t"][-1] / (n - 1))
    psi = np.radians(d["psi"])
    c, s = np.cos(psi), np.sin(psi)
    u = d["xdot"] * c + d["ydot"] * s
    v = -d["xdot"] * s + d["ydot"] * c
    cols = {"t": t, "delta": np.radians(d["delta"]), "u": u, "v": v, "r": np.radians(d["r"]),
            "psi": psi, "x": d["x0"], "y": d["y0"], "n": d["n"] / 60.0}  # fmt: skip
    lam = 1.0
    if scale is not None:
        if not scale > 0:
            raise ShipidError(f"--scale must be > 0, got {scale!r}")
        lam = float(scale)
        root = math.sqrt(lam)
        for k in ("t", "u", "v"):
            cols[k] = cols[k] / root
        for k in ("x", "y"):
            cols[k] = cols[k] / lam
        for k in ("r", "n"):
            cols[k] = cols[k] * root
    return make_log(cols, name=path.name, ship="KVLCC2", source=f"MARIN SIMMAN 2008: {path}",
                    rudder_positive="port", scale=1.0 if scale is None else lam)  # fmt: skip


def read_osaka_frt(path: str | Path) -> pd.DataFrame:
    """An Osaka University free-running-test CSV (Esso Osaka) as a canonical log."""
    path = Path(path)
    try:
        df = pd.read_csv(path)
    except (UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise ShipidError(f"{path}: not an Osaka FRT CSV ({str(exc).splitlines()[0]})") from None
    missing = [c for c in OSAKA_COLUMNS if c not in df.columns]
    if missing:
        raise ShipidError(f"{path}: missing column(s) {', '.join(missing)} for --format osaka-frt")
    df = df[list(OSAKA_COLUMNS)].rename(columns=OSAKA_COLUMNS).dropna(how="all")
    if len(df) < 3:
        raise ShipidError(f"{path}: {len(df)} data rows, too short (--format osaka-frt)")
    bad = df.isna().any(axis=1).to_numpy()
    if bad.any():
        row = int(np.argmax(bad))
        col = df.columns[df.iloc[row].isna().to_numpy()][0]
        raise ShipidError(f"{path}: column {col!r} is empty at data row {row + 1}")
    cols = {c: df[c].to_numpy(dtype=float) for c in df.columns}
    cols["psi"] = np.unwrap(cols["psi"])
    return make_log(cols, name=path.name, ship="Esso Osaka 3 m model",
                    source=f"Osaka University FRT: {path}", rudder_positive="starboard", scale=1.0)


def read_format(path: str | Path, fmt: str, scale: float | None = None) -> pd.DataFrame:
    if fmt == "simman-marin":
        return read_simman_marin(path, scale)
    if fmt == "osaka-frt":
        return read_osaka_frt(path)
    raise ShipidError(f"unknown --format {fmt!r}; use one of {', '.join(FORMATS)}")
