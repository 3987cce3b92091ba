"""The KVLCC2's three real zig-zags of ``../shared/data`` at model scale (MARIN's ±20° runs
Froude-scaled by 45.7, HSVA's 20/10 run), by name, as the studies read them."""

from __future__ import annotations

from pathlib import Path

from shipid.data.io import read_log

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


def kvlcc2_logs(dt: float = 0.2) -> dict:
    """{name: log} of the three runs resampled to ``dt`` [s]."""
    marin = DATA / "kvlcc2-marin"
    return {"MARIN zz 20°": read_log(marin / "MARIN_FREE_KVLCC2_zz_20_m.dat", fmt="simman-marin",
                                     scale=45.7, dt=dt),
            "MARIN zz −20°": read_log(marin / "MARIN_FREE_KVLCC2_zz_-20_m.dat",
                                      fmt="simman-marin", scale=45.7, dt=dt),
            "HSVA zz 20/10": read_log(DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                                      fmt="simman-hsva", dt=dt)}  # fmt: skip
