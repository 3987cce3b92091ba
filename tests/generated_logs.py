"""Small generated logs shared by test modules."""

from shipid.data.preprocess import lowpass
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, scale_ship


def noisy_zigzags(seed: int) -> list:
    """Three 60 s zig-zags of the paper's scale ship (20° port, 15° starboard, 25° port first),
    with the paper's IMU noise (seeds ``seed``, +1, +2) and the 0.5 Hz prefilter."""
    ship = scale_ship(rudder_rate_deg=9.6)
    out = []
    for i, (a, first) in enumerate(((20, "port"), (15, "starboard"), (25, "port"))):
        log = zigzag(ship, a, a, duration=60, dt=0.2, method="euler", approach=2.0,
                     first=first).log  # fmt: skip
        out.append(lowpass(PAPER_IMU.apply(log, seed=seed + i), 0.5))
    return out


# A ship whose yaw is damped by u·r (< 0 stable; det A = 0.6·0.8 − 0.45 > 0 at u·r = −0.8) and
# held by |r|·r where it is not: the truth of the stability and replicate tests.
YAW_DAMPED_STRUCTURE = "u: |u|*u, 1; v: u*v, u*r, u^2*delta; r: u*v, u*r, |r|*r, u^2*delta"


def yaw_damped_ship(yaw_damping: float):
    """The ship of ``YAW_DAMPED_STRUCTURE`` with ``u*r`` = ``yaw_damping`` in its yaw equation."""
    from shipid.dynamics.model import ManoeuvringModel

    return ManoeuvringModel(YAW_DAMPED_STRUCTURE, {
        "u": {"|u|*u": -0.05, "1": 0.05},
        "v": {"u*v": -0.6, "u*r": -0.3, "u^2*delta": 0.01},
        "r": {"u*v": -1.5, "u*r": yaw_damping, "|r|*r": -5.0, "u^2*delta": -0.008}})  # fmt: skip
