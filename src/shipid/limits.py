"""Guards against requests that would not fit in memory: refused with the number of samples asked
for, instead of a MemoryError after minutes of work."""

from __future__ import annotations

import math

from shipid.errors import ShipidError

# Fraction of the available memory one request may take.
MEMORY_FRACTION = 0.5
# A request this small is not checked: any machine that runs this gives it, and reading the
# available memory cost the plausibility checks' held turns a twentieth of their time.
UNCHECKED_BYTES = 64 * 2**20


def available_memory_bytes() -> int | None:
    """MemAvailable from /proc/meminfo, or None where it cannot be read."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


def check_samples(n_samples: float, bytes_per_sample: int, what: str) -> int:
    """``n_samples`` as an int, or an error when that many samples of ``bytes_per_sample`` would
    not fit in memory (``what`` says what was asked for, e.g. '--duration 1e7 at --step 0.05')."""
    if not math.isfinite(n_samples) or n_samples < 0:
        raise ShipidError(f"{what}: asks for {n_samples} samples")
    need = float(n_samples) * bytes_per_sample
    if need <= UNCHECKED_BYTES:
        return int(round(n_samples))
    avail = available_memory_bytes()
    if avail is not None and need > MEMORY_FRACTION * avail:
        raise ShipidError(f"{what}: {n_samples:.3g} samples would need {need / 2**30:.3g} GiB, "
                          f"more than this machine can give ({avail / 2**30:.3g} GiB available)")
    return int(round(n_samples))
