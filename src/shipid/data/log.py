"""The canonical trial log: a DataFrame in SI units and radians with its metadata in ``attrs``.

Columns: ``t`` [s], ``delta`` [rad], ``u``, ``v`` [m/s], ``r`` [rad/s]; optional ``psi`` [rad],
``x``, ``y`` [m], ``n`` [rps], ``thrust`` [N]. Metadata keys: ``ship``, ``source``,
``rudder_positive`` ('port' or 'starboard': where a positive rudder angle turns the ship) and
``scale`` (λ = ship length / model length, 1 at full scale).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from shipid.errors import ShipidError

REQUIRED = ("t", "delta", "u", "v", "r")
OPTIONAL = ("psi", "x", "y", "n", "thrust")
COLUMNS = REQUIRED + OPTIONAL
RUDDER_SIDES = ("port", "starboard")


def make_log(columns: Mapping[str, np.ndarray], **meta: object) -> pd.DataFrame:
    """A canonical log from column arrays (canonical names only) and metadata."""
    unknown = set(columns) - set(COLUMNS)
    if unknown:
        raise ValueError(f"not canonical log columns: {sorted(unknown)}; use {COLUMNS}")
    df = pd.DataFrame({c: np.asarray(columns[c], dtype=float) for c in COLUMNS if c in columns})
    df.attrs.update({k: v for k, v in meta.items() if v is not None})
    return df


def rudder_positive(log: pd.DataFrame, default: str = "port") -> str:
    side = log.attrs.get("rudder_positive", default)
    if side not in RUDDER_SIDES:
        raise ValueError(f"log metadata rudder_positive must be 'port' or 'starboard', got {side!r}")
    return side


def starboard_sign(rudder_positive_turns: str) -> float:
    """Sign of the rudder angle that turns the ship to starboard (r > 0)."""
    return 1.0 if rudder_positive_turns == "starboard" else -1.0


def input_columns(log: pd.DataFrame, columns, name: str | None = None) -> dict[str, np.ndarray]:
    """The propulsion input series ('thrust', 'n') a model needs, or an error naming the column."""
    missing = [c for c in columns if c not in log.columns]
    if missing:
        label = name or log.attrs.get("name", "log")
        raise ShipidError(f"{label}: the model needs the log column {missing[0]!r} "
                          f"({'thrust [N]' if missing[0] == 'thrust' else 'propeller speed [rps]'}),"
                          " which this log does not have")  # fmt: skip
    return {c: log[c].to_numpy() for c in columns}
