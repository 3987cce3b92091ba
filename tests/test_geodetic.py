"""A GNSS's latitude and longitude read as the log's x (north), y (east) in metres. Truths: the
published lengths of a degree on the WGS84 ellipsoid, the meridian arc integrated from its
radius of curvature, and a simulated ship whose track, put into latitude and longitude, must come
back as its own x, y, u, v."""

import math

import numpy as np
import pandas as pd
import pytest
from cli_helpers import run

from shipid.data.geodetic import WGS84_A, WGS84_E2, local_track
from shipid.data.io import read_log, write_log
from shipid.errors import ShipidError
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import cybership2

# Length of one degree of latitude and of longitude [m] at a latitude, on WGS84 (the table in
# Wikipedia's "Latitude" article, rounded to the metre; a degree of latitude there is the arc
# from half a degree below to half above, which at 45° is 1.2 m longer than the local rate).
DEGREE_LENGTHS = [(0, 110_574, 111_320), (15, 110_649, 107_551), (30, 110_852, 96_486),
                  (45, 111_133, 78_847), (60, 111_412, 55_800), (75, 111_618, 28_902)]  # fmt: skip


@pytest.mark.parametrize(("lat", "north_per_deg", "east_per_deg"), DEGREE_LENGTHS)
@pytest.mark.parametrize("hemisphere", [1, -1])
def test_a_hundredth_of_a_degree_has_the_published_length(lat, north_per_deg, east_per_deg,
                                                          hemisphere):
    lat0, lon0, step = hemisphere * lat, 10.0, 0.01
    north, east = local_track(np.array([lat0, lat0 + hemisphere * step, lat0]),
                              np.array([lon0, lon0, lon0 + step]))  # fmt: skip
    assert hemisphere * north[1] / step == pytest.approx(north_per_deg, abs=1.5)
    assert abs(east[1]) < 1e-6
    assert east[2] / step == pytest.approx(east_per_deg, abs=1.0)
    # The parallel curves poleward of the plane's east axis by y² tanφ / 2N.
    prime = WGS84_A / math.sqrt(1 - WGS84_E2 * math.sin(math.radians(lat0)) ** 2)
    assert north[2] == pytest.approx(east[2] ** 2 * math.tan(math.radians(lat0)) / (2 * prime),
                                     abs=1e-4)  # fmt: skip


def test_a_kilometre_north_is_the_meridian_arc():
    """The meridian arc integrated from its radius of curvature M(φ) = a(1 − e²)/(1 − e² sin²φ)^1.5
    (a formula of its own, not the earth-centred one): the plane's x differs from the arc by the
    chord's and projection's R·θ³/6, under 0.1 mm at 1 km."""
    from scipy.integrate import quad  # here: 0.2 s of every worker's collection at the top

    lat0 = 63.43  # Trondheim, where CyberShip II sails

    def radius(phi):
        return WGS84_A * (1 - WGS84_E2) / (1 - WGS84_E2 * math.sin(phi) ** 2) ** 1.5

    for dlat in (0.001, 0.009):
        arc = quad(radius, math.radians(lat0), math.radians(lat0 + dlat))[0]
        north, _ = local_track(np.array([lat0, lat0 + dlat]), np.array([10.39, 10.39]))
        assert north[1] == pytest.approx(arc, abs=1e-4)


def test_the_antimeridian_is_crossed_without_a_jump():
    lon = np.array([179.999, 180.0, -179.999, -179.998])
    _, east = local_track(np.full(4, -15.0), lon)
    np.testing.assert_allclose(np.diff(east), np.diff(east)[0], rtol=1e-6)
    assert np.diff(east)[0] == pytest.approx(107_551 * 0.001, abs=0.01)


def _gnss_csv(log, path, origin=(63.43, 10.39), **names):
    """The simulated log as a GNSS and compass give it: latitude and longitude of its x, y (the
    ellipsoid's local radii, first order: off the plane by x·y/R, 1 mm over 100 m), heading
    in degrees, no u, v."""
    lat0 = math.radians(origin[0])
    s = math.sin(lat0)
    meridian = WGS84_A * (1 - WGS84_E2) / (1 - WGS84_E2 * s * s) ** 1.5
    prime = WGS84_A / math.sqrt(1 - WGS84_E2 * s * s)
    lat = origin[0] + np.degrees(log["x"].to_numpy() / meridian)
    lon = origin[1] + np.degrees(log["y"].to_numpy() / (prime * math.cos(lat0)))
    frame = pd.DataFrame({"t": log["t"], "delta [deg]": np.degrees(log["delta"]),
                          "r": log["r"], "psi [deg]": np.degrees(log["psi"]),
                          names.get("lat", "lat"): lat, names.get("lon", "lon"): lon})  # fmt: skip
    frame.to_csv(path, index=False)
    return path


@pytest.fixture(scope="module")
def cs2_zigzag():
    return zigzag(cybership2(), 20, 20, duration=60, dt=0.1, approach=5.0).log


def test_a_gnss_log_in_degrees_is_the_ships_track_and_velocities(cs2_zigzag, tmp_path):
    path = _gnss_csv(cs2_zigzag, tmp_path / "gnss.csv")
    with pytest.warns(UserWarning, match="read off the track"):
        log = read_log(path)
    truth = cs2_zigzag
    x, y = truth["x"].to_numpy(), truth["y"].to_numpy()
    reach = float(np.max(np.hypot(x - x[0], y - y[0])))
    assert reach > 10.0
    np.testing.assert_allclose(log["x"], x - x[0], atol=2e-3)
    np.testing.assert_allclose(log["y"], y - y[0], atol=2e-3)
    # u, v as read off the metric track itself (tests/test_track_velocities.py judges those).
    direct = truth[["t", "delta", "r", "psi", "x", "y"]].copy()
    direct.attrs = dict(truth.attrs)
    with pytest.warns(UserWarning):
        metric = read_log(write_log(direct, tmp_path / "metric.csv"))
    for c in ("u", "v"):
        np.testing.assert_allclose(log[c], metric[c], atol=2e-4)
        assert float(np.std(log[c].to_numpy() - truth[c].to_numpy())) < 0.01
    first = pd.read_csv(path).iloc[0]
    assert log.attrs["track_origin"] == {"lat": first["lat"], "lon": first["lon"]}
    again = read_log(write_log(log, tmp_path / "canonical.csv"))
    assert again.attrs["track_origin"] == log.attrs["track_origin"]


def test_the_command_line_identifies_from_latitude_and_longitude(cs2_zigzag, tmp_path, capsys):
    path = _gnss_csv(cs2_zigzag, tmp_path / "gnss.csv", lat="Latitude", lon="Longitude")
    out = tmp_path / "model.json"
    code, text, err = run(["identify", path, "--columns", "lat=Latitude,lon=Longitude",
                           "--model", "blanke-speed", "-o", out], capsys)  # fmt: skip
    assert code == 0, err
    assert "read off the track" in err
    assert out.exists()


@pytest.mark.parametrize(("column", "value", "needle"), [
    ("lat", 6325.8, "e.g. 63.430000"),  # NMEA ddmm.mmmm
    ("lat", -91.0, "beyond ±90°"),
    ("lon", 1000.0, "beyond ±360°"),
])  # fmt: skip
def test_coordinates_that_are_not_degrees_are_refused(cs2_zigzag, tmp_path, capsys, column,
                                                      value, needle):
    path = _gnss_csv(cs2_zigzag, tmp_path / "gnss.csv")
    frame = pd.read_csv(path)
    frame.loc[7, column] = value
    frame.to_csv(path, index=False)
    with pytest.raises(ShipidError, match=rf"gnss.csv: column '{column}' is .* at data row 8"):
        read_log(path)
    out = tmp_path / "log.csv"
    code, _, err = run(["import", path, "-o", out], capsys)
    assert code == 1 and needle in err and "Traceback" not in err
    assert not out.exists()


def test_latitude_in_radians_by_its_header_is_converted(cs2_zigzag, tmp_path):
    path = _gnss_csv(cs2_zigzag, tmp_path / "gnss.csv")
    frame = pd.read_csv(path)
    frame["lat"], frame["lon"] = np.radians(frame["lat"]), np.radians(frame["lon"])
    frame = frame.rename(columns={"lat": "lat [rad]", "lon": "lon [rad]"})
    frame.to_csv(tmp_path / "radians.csv", index=False)
    with pytest.warns(UserWarning):
        in_degrees, in_radians = read_log(path), read_log(tmp_path / "radians.csv")
    np.testing.assert_allclose(in_radians["x"], in_degrees["x"], atol=1e-6)
    np.testing.assert_allclose(in_radians["y"], in_degrees["y"], atol=1e-6)


def test_a_gap_in_the_fixes_is_named_and_filled_on_request(cs2_zigzag, tmp_path):
    path = _gnss_csv(cs2_zigzag, tmp_path / "gnss.csv")
    frame = pd.read_csv(path)
    frame.loc[100:104, "lon"] = np.nan
    frame.to_csv(path, index=False)
    with pytest.raises(ShipidError, match="column 'lon' has 5 missing values at data rows 101–105"):
        read_log(path)
    with pytest.warns(UserWarning):
        log = read_log(path, fill_gaps=True)
    assert np.isfinite(log["y"]).all()


def test_a_bad_track_origin_in_a_files_metadata_is_named(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text('# shipid-log: {"track_origin": {"lat": "north"}}\nt,delta,u,v,r\n'
                    "0,0,1,0,0\n1,0,1,0,0\n2,0,1,0,0\n")
    with pytest.raises(ShipidError, match="metadata track_origin"):
        read_log(path)
