"""Readers of known trial formats into the canonical log (SI units, radians, body-fixed velocities).

* ``simman-marin``: KVLCC2 free-running tests by MARIN (SIMMAN 2008), full scale, 11 tab-separated
  columns printed with three significant digits after two header lines. The time column repeats at
  that precision, so time is rebuilt as uniform, t_i = t_0 + i·(t_end − t_0)/(N − 1); velocities
  are earth-fixed and are rotated to body axes; degrees become radians; positive rudder turns the
  ship to port. With ``scale`` (λ) the log is Froude-scaled to model scale: lengths ÷ λ, times
  and speeds ÷ √λ, rates and revolutions × √λ.
* ``simman-hsva``: KVLCC2 free-running tests by HSVA (SIMMAN 2008), model scale, four Latin-1 header
  lines then 12 whitespace-separated columns t, x0, y0, ψ [deg], ẋ0, ẏ0 (earth-fixed, rotated to body
  axes here), r [deg/s], roll [deg], δ [deg], n [rps], thrust [N], torque [N·m]; positive rudder
  turns the ship to port. ``scale`` is the model's λ (45.7 for the SIMMAN KVLCC2) and is only
  recorded: the data are already at model scale.
* ``osaka-frt``: Esso Osaka free-running tests (Osaka University), CSV with units in the header,
  body-fixed velocities at midship, ψ wrapped (unwrapped here), empty trailing rows (dropped);
  positive rudder turns the ship to starboard. The relative wind at midship becomes the canonical
  ``wind_speed`` and ``wind_angle`` (the direction the apparent wind comes from, clockwise from the
  bow: the same convention as the file's, checked against its true wind and the ship's velocity).
  The model's particulars (``ESSO_OSAKA_MODEL``, from the dataset's publication) come with it.

``detect_format`` recognises each layout from the first lines of a file, so that reading one
without ``--format`` can say which ``--format`` it needs.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd

from shipid.data.log import make_log
from shipid.errors import ShipidError

FORMATS = ("canonical", "simman-marin", "simman-hsva", "osaka-frt")
MARIN_COLUMNS = ("t", "x0", "y0", "phi", "psi", "xdot", "ydot", "p", "r", "delta", "n")
HSVA_COLUMNS = ("t", "x0", "y0", "psi", "xdot", "ydot", "r", "roll", "delta", "n", "thrust",
                "torque")  # fmt: skip
OSAKA_COLUMNS = {"t [s]": "t", "x_position_mid [m]": "x", "u_velo [m/s]": "u",
                 "y_position_mid [m]": "y", "vm_velo [m/s]": "v", "psi_hat [rad]": "psi",
                 "r_angvelo [rad/s]": "r", "n_prop [rps]": "n",
                 "delta_rudder [rad]": "delta"}  # fmt: skip
OSAKA_WIND = {"wind_velo_relative_mid [m/s]": "wind_speed",
              "wind_dir_relative_mid [rad]": "wind_angle"}  # fmt: skip
# The Esso Osaka 3 m model of the Osaka University free-running tests (FRT-DS-ESSO; Wakita et al.
# 2022, J. Mar. Sci. Technol. 27:772–785), in the fresh water of Inukai pond: what its files do not
# carry and every model of them needs for ship lengths, the prime form, --prior clarke and
# --crossflow. The files do not say which full-scale ship it is of: no scale.
ESSO_OSAKA_MODEL = {"length": 3.0, "beam": 0.489, "draught": 0.201, "block_coefficient": 0.830,
                    "mass": 244.6, "rudder_area": 0.0106, "propeller_diameter": 0.084,
                    "xg": 0.094, "rho": 1000.0}  # fmt: skip
_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def _header_length(lines: list[str], count: int, limit: int = 12) -> int | None:
    """How many lines head a SIMMAN file: those before the first of ``count`` numbers, or None
    where none of the first ``limit`` lines is one. The shared files have two (MARIN) and four
    (HSVA); a file of another run titled in one more or one fewer line is still that layout."""
    for k, line in enumerate(lines[:limit]):
        if _all_numbers(line, count):
            return k
    return None


def _numeric_rows(path: Path, lines: list[str], columns: tuple, fmt: str) -> np.ndarray:
    first = _header_length(lines, len(columns))
    if first is None:
        raise ShipidError(f"{path}: no line of {len(columns)} numbers among its first lines "
                          f"(--format {fmt}; truncated or not a {fmt} file?)")  # fmt: skip
    rows = []
    for i, line in enumerate(lines[first:], start=first + 1):
        fields = line.split()
        if not fields:
            continue
        if len(fields) != len(columns):
            raise ShipidError(f"{path}: line {i} has {len(fields)} values, --format {fmt} "
                              f"expects {len(columns)} (truncated or not a {fmt} file?)")
        try:
            rows.append([float(f) for f in fields])
        except ValueError:
            raise ShipidError(f"{path}: line {i} is not numeric (--format {fmt})") from None
    if len(rows) < 3:
        raise ShipidError(f"{path}: {len(rows)} data rows, too short (--format {fmt})")
    return np.array(rows)


def _body_velocities(xdot: np.ndarray, ydot: np.ndarray, psi: np.ndarray):
    c, s = np.cos(psi), np.sin(psi)
    return xdot * c + ydot * s, -xdot * s + ydot * c


def _check_scale(scale: float | None) -> float:
    if scale is None:
        return 1.0
    if not (isinstance(scale, int | float) and math.isfinite(scale) and scale > 0):
        raise ShipidError(f"--scale must be a number > 0, got {scale!r}")
    return float(scale)


def read_simman_marin(path: str | Path, scale: float | None = None) -> pd.DataFrame:
    """A MARIN SIMMAN .dat file as a canonical log (full scale, or model scale with ``scale``)."""
    path = Path(path)
    lam = _check_scale(scale)
    try:
        lines = path.read_text(encoding="ascii").splitlines()
    except UnicodeDecodeError:
        raise ShipidError(f"{path}: not a text file (--format simman-marin expects a MARIN .dat)"
                          ) from None
    d = dict(zip(MARIN_COLUMNS, _numeric_rows(path, lines, MARIN_COLUMNS, "simman-marin").T,
                 strict=True))  # fmt: skip
    n = len(d["t"])
    t0, t_end = d["t"][0], d["t"][-1]
    if not t_end > t0:
        raise ShipidError(f"{path}: time runs from {t0:g} to {t_end:g} s, not forward "
                          f"(--format simman-marin)")  # fmt: skip
    # From the first time, not from 0: a record cut from a longer one would otherwise be
    # stretched over its own end time.
    t = t0 + np.arange(n) * ((t_end - t0) / (n - 1))
    psi = np.radians(d["psi"])
    u, v = _body_velocities(d["xdot"], d["ydot"], psi)
    cols = {"t": t, "delta": np.radians(d["delta"]), "u": u, "v": v, "r": np.radians(d["r"]),
            "psi": psi, "x": d["x0"], "y": d["y0"], "n": d["n"] / 60.0}  # fmt: skip
    if scale is not None:
        root = math.sqrt(lam)
        for k in ("t", "u", "v"):
            cols[k] = cols[k] / root
        for k in ("x", "y"):
            cols[k] = cols[k] / lam
        for k in ("r", "n"):
            cols[k] = cols[k] * root
    return make_log(cols, name=path.name, ship="KVLCC2", source=f"MARIN SIMMAN 2008: {path}",
                    rudder_positive="port", scale=lam)  # fmt: skip


def read_simman_hsva(path: str | Path, scale: float | None = None) -> pd.DataFrame:
    """An HSVA SIMMAN .dat file (model scale) as a canonical log."""
    path = Path(path)
    lam = _check_scale(scale if scale is not None else 45.7)
    raw = path.read_bytes()
    if b"\x00" in raw[:4096]:
        raise ShipidError(f"{path}: binary file, not an HSVA .dat (--format simman-hsva)")
    lines = raw.decode("latin-1").splitlines()
    d = dict(zip(HSVA_COLUMNS, _numeric_rows(path, lines, HSVA_COLUMNS, "simman-hsva").T,
                 strict=True))  # fmt: skip
    psi = np.radians(d["psi"])
    u, v = _body_velocities(d["xdot"], d["ydot"], psi)
    cols = {"t": d["t"], "delta": np.radians(d["delta"]), "u": u, "v": v,
            "r": np.radians(d["r"]), "psi": psi, "x": d["x0"], "y": d["y0"], "n": d["n"],
            "thrust": d["thrust"]}  # fmt: skip
    title = lines[2].strip() if len(lines) > 2 else ""
    return make_log(cols, name=path.name, ship="KVLCC2",
                    source=f"HSVA SIMMAN 2008 ({title}): {path}", rudder_positive="port",
                    scale=lam)  # fmt: skip


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
    mapping = dict(OSAKA_COLUMNS)
    mapping.update({k: v for k, v in OSAKA_WIND.items() if k in df.columns})
    df = df[list(mapping)].rename(columns=mapping).dropna(how="all")
    if len(df) < 3:
        raise ShipidError(f"{path}: {len(df)} data rows, too short (--format osaka-frt)")
    source = {v: k for k, v in mapping.items()}
    cols = {}
    for c in df.columns:
        values = pd.to_numeric(df[c], errors="coerce")
        text = (values.isna() & df[c].notna()).to_numpy()
        if text.any():
            row = int(np.argmax(text))
            raise ShipidError(f"{path}: column {source[c]!r} is not numeric at data row "
                              f"{row + 1} ({df[c].iloc[row]!r}; --format osaka-frt)")  # fmt: skip
        cols[c] = values.to_numpy(dtype=float)
    # An empty cell (a sensor's dropout) stays missing: every reader's check then refuses it by
    # its rows and times, or --fill-gaps interpolates it. The heading unwrapped around it.
    psi = cols["psi"].copy()
    known = np.isfinite(psi)
    psi[known] = np.unwrap(psi[known])
    cols["psi"] = psi
    if "wind_angle" in cols:
        cols["wind_angle"] = np.angle(np.exp(1j * cols["wind_angle"]))  # (−π, π]
    # No scale: the files do not give the ship the model is of, and 1 would say full scale.
    return make_log(cols, name=path.name, ship="Esso Osaka 3 m model",
                    source=f"Osaka University FRT: {path}", rudder_positive="starboard",
                    particulars=dict(ESSO_OSAKA_MODEL))  # fmt: skip


def read_format(path: str | Path, fmt: str, scale: float | None = None) -> pd.DataFrame:
    """Read ``path`` with the reader of ``fmt`` (see the module docstring)."""
    if fmt == "simman-marin":
        return read_simman_marin(path, scale)
    if fmt == "simman-hsva":
        return read_simman_hsva(path, scale)
    if fmt == "osaka-frt":
        return read_osaka_frt(path)
    raise ShipidError(f"unknown --format {fmt!r}; use one of {', '.join(FORMATS)}")


def _all_numbers(line: str, count: int) -> bool:
    fields = line.split()
    return len(fields) == count and all(_NUMBER.match(f) for f in fields)


# The first line a SIMMAN file starts with, beside its layout: a tab-separated log of eleven
# numeric columns under a header has MARIN's layout, and was read (or hinted) as MARIN's.
SIGNATURES = {"simman-marin": "MARIN", "simman-hsva": "HSVA"}


def detect_format(path: str | Path) -> str | None:
    """The known format whose layout and first line the file's first lines match, or None."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(8192)
    except OSError:
        return None
    lines = head.decode("latin-1").splitlines()
    if lines and all(c in lines[0] for c in ("u_velo [m/s]", "delta_rudder [rad]")):
        return "osaka-frt"
    data = [ln for ln in lines[:12] if ln.strip()]
    fmt = None
    # A header (one line or more) over rows of eleven (MARIN) or twelve (HSVA) numbers.
    marin, hsva = _header_length(data, 11), _header_length(data, 12)
    if marin and len(data) >= marin + 2:
        fmt = "simman-marin"
    elif hsva and len(data) >= hsva + 2:
        fmt = "simman-hsva"
    return fmt if fmt and data[0].strip().startswith(SIGNATURES[fmt]) else None
