"""A GNSS track in latitude and longitude as the log's x (north) and y (east) in metres.

A receiver reports WGS84 latitude and longitude in degrees; the model's kinematics want metres
in a local earth-fixed frame, x north and y east (ψ clockwise from north). Each fix is turned
into earth-centred coordinates on the ellipsoid and those into the local north-east plane
tangent at the origin (the first fix):

    X = (N + h) cos φ cos λ,   Y = (N + h) cos φ sin λ,   Z = (N (1 − e²) + h) sin φ
    x = −sin φ₀ cos λ₀ ΔX − sin φ₀ sin λ₀ ΔY + cos φ₀ ΔZ,   y = −sin λ₀ ΔX + cos λ₀ ΔY

with N = a / √(1 − e² sin² φ) the prime-vertical radius and h = 0 (a ship sits on the sea). Over
the few kilometres of a trial the plane departs from the ellipsoid by d²/(2R) in height only: a
distance of 5 km is foreshortened by 0.1 mm. The longitude's wrap at ±180° needs no care: the
earth-centred coordinates are continuous across it.

Latitudes beyond ±90°, longitudes beyond ±360° and the NMEA habit of writing degrees and minutes
together (5957.1234 for 59° 57.1234′) are refused with the row named.
"""

from __future__ import annotations

import math

import numpy as np

from shipid.errors import ShipidError

# WGS84 (NIMA TR8350.2): semi-major axis [m] and flattening.
WGS84_A = 6_378_137.0
WGS84_F = 1.0 / 298.257223563
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)

GEODETIC_COLUMNS = ("lat", "lon")
LIMITS_DEG = {"lat": 90.0, "lon": 360.0}


def _earth_centred(lat: np.ndarray, lon: np.ndarray) -> tuple[np.ndarray, ...]:
    sin_lat = np.sin(lat)
    prime_vertical = WGS84_A / np.sqrt(1.0 - WGS84_E2 * sin_lat**2)
    return (prime_vertical * np.cos(lat) * np.cos(lon),
            prime_vertical * np.cos(lat) * np.sin(lon),
            prime_vertical * (1.0 - WGS84_E2) * sin_lat)  # fmt: skip


def check_geodetic(lat_deg: np.ndarray, lon_deg: np.ndarray, name: str) -> None:
    """Refuse latitudes and longitudes that are not degrees, naming the column and data row."""
    for column, values in (("lat", lat_deg), ("lon", lon_deg)):
        limit = LIMITS_DEG[column]
        beyond = np.abs(values) > limit
        if beyond.any():
            row = int(np.argmax(beyond))
            value = float(values[row])
            nmea = abs(value) <= 100 * limit and abs(value) % 100 < 60
            hint = (f"; NMEA writes degrees and minutes together (ddmm.mmmm): convert to degrees, "
                    f"e.g. {math.copysign(abs(value) // 100 + abs(value) % 100 / 60, value):.6f}"
                    if nmea else "")  # fmt: skip
            what = "latitude" if column == "lat" else "longitude"
            raise ShipidError(f"{name}: column {column!r} is {value:g} at data row {row + 1}, "
                              f"beyond ±{limit:g}°: not a {what} in degrees{hint}")  # fmt: skip


def local_track(lat_deg: np.ndarray, lon_deg: np.ndarray,
                origin_deg: tuple[float, float] | None = None,
                ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """x (north) and y (east) [m] of WGS84 fixes in the plane tangent at ``origin_deg``.

    Parameters
    ----------
    lat_deg, lon_deg : the fixes' latitude and longitude [deg].
    origin_deg : (latitude, longitude) of the plane's origin [deg]; the first fix by default.
    """
    lat = np.radians(np.asarray(lat_deg, dtype=float))
    lon = np.radians(np.asarray(lon_deg, dtype=float))
    if origin_deg is None:
        origin = (float(lat[0]), float(lon[0]))
    else:
        origin = (math.radians(origin_deg[0]), math.radians(origin_deg[1]))
    lat0, lon0 = origin
    # Differences of the earth-centred coordinates, taken before the rotation: each is some
    # 6.4e6 m, and their difference keeps its millimetres in float64 (resolution 1e-9 m).
    x0, y0, z0 = _earth_centred(np.array([lat0]), np.array([lon0]))
    ex, ey, ez = _earth_centred(lat, lon)
    dx, dy, dz = ex - x0[0], ey - y0[0], ez - z0[0]
    north = (-math.sin(lat0) * math.cos(lon0) * dx - math.sin(lat0) * math.sin(lon0) * dy
             + math.cos(lat0) * dz)  # fmt: skip
    east = -math.sin(lon0) * dx + math.cos(lon0) * dy
    return north, east
