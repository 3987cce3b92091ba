"""Reference ships (truth simulators) and the sensor model used to synthesise trials."""

from __future__ import annotations

from .cybership2 import cybership2
from .kvlcc2 import kvlcc2
from .mariner import mariner
from .scale_ship import scale_ship, scale_ship_model
from .sensors import NOISE_FREE, PAPER_IMU, PAPER_IMU_SPEC, SensorModel
from .tanker import tanker
from .vessel import Vessel

VESSELS = {"scale-ship": scale_ship, "mariner": mariner, "kvlcc2": kvlcc2,
           "cybership2": cybership2, "tanker": tanker}


def get_vessel(name: str) -> Vessel:
    """A reference ship by name: 'scale-ship' (the default), 'mariner', 'kvlcc2', 'cybership2'
    or 'tanker'."""
    if name not in VESSELS:
        raise ValueError(f"unknown vessel {name!r}; known vessels: {', '.join(VESSELS)}")
    return VESSELS[name]()


__all__ = ["NOISE_FREE", "PAPER_IMU", "PAPER_IMU_SPEC", "VESSELS", "SensorModel", "Vessel",
           "cybership2", "get_vessel", "kvlcc2", "mariner", "scale_ship", "scale_ship_model",
           "tanker"]
