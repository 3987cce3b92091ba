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
