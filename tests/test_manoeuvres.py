"""Reference ships against the computed check values of reference-ships.md (±5 %), and IMO indices
against synthetic logs of known geometry."""

import dataclasses
import math

import numpy as np
import pytest

from shipid.data.log import make_log
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.simulate import simulate, simulate_log
from shipid.dynamics.steering import SteeringMachine
from shipid.trials.indices import detect_manoeuvre, turning_indices, zigzag_indices
from shipid.trials.manoeuvres import pull_out, turning_circle, zigzag
from shipid.vessels import PAPER_IMU, get_vessel, kvlcc2, mariner, scale_ship
from shipid.vessels.kvlcc2 import KVLCC2Dynamics

TOL = 0.05  # "agreement to about ±5 % is the expected level"


@pytest.fixture(scope="module")
def scale_ship_at_2ms():
    # reference-ships.md §7.3: u0 = 2 m/s with the surge constant that trims it there, 0.1284.
    return dataclasses.replace(scale_ship(surge_constant=0.1284), approach_speed=2.0)


@pytest.mark.parametrize(("side", "advance", "tactical"), [("port", 3.0, 4.4),
                                                            ("starboard", 3.1, 4.6)])
def test_scale_ship_turning_circle(scale_ship_at_2ms, side, advance, tactical):
    # δ = +20° turns this ship to port.
    ind = turning_circle(scale_ship_at_2ms, 20, side=side, duration=40, dt=0.02).indices
    assert ind["advance_L"] == pytest.approx(advance, rel=TOL)
    assert ind["tactical_diameter_L"] == pytest.approx(tactical, rel=TOL)


@pytest.mark.parametrize(
    ("angle", "rate", "first", "second"),
    [(10, None, 1.8, 2.1), (20, None, 4.2, 6.5), (10, 20, 4.4, 4.9), (20, 20, 15.6, 21.1)],
)
def test_scale_ship_zigzag_overshoots(scale_ship_at_2ms, angle, rate, first, second):
    steering = SteeringMachine(math.radians(35), None if rate is None else math.radians(rate))
    ind = zigzag(scale_ship_at_2ms, angle, angle, first="port", duration=40, dt=0.01,
                 steering=steering).indices  # fmt: skip
    # Absolute floor of 0.1° for the small overshoots (5 % of 1.8° is below the event resolution).
    assert ind["first_overshoot_deg"] == pytest.approx(first, rel=TOL, abs=0.1)
    assert ind["second_overshoot_deg"] == pytest.approx(second, rel=TOL, abs=0.1)


def test_mariner_turning_circle_and_zigzag():
    m = mariner()
    ind = turning_circle(m, 35, side="port", duration=300, dt=0.2).indices  # δ = +35° → port
    assert ind["advance_L"] == pytest.approx(3.71, rel=TOL)
    assert ind["transfer_L"] == pytest.approx(2.73, rel=TOL)
    assert ind["tactical_diameter_L"] == pytest.approx(6.65, rel=TOL)
    assert ind["time_to_90"] == pytest.approx(122, rel=TOL)
    zz = zigzag(m, 20, 20, first="port", duration=150, dt=0.2).indices
    assert zz["first_overshoot_deg"] == pytest.approx(6.8, rel=TOL)
    assert zz["second_overshoot_deg"] == pytest.approx(7.4, rel=TOL)


def test_kvlcc2_trim_turning_circle_and_zigzag():
    k = kvlcc2()
    assert k.dynamics.n_prop == pytest.approx(11.85, abs=0.01)
    ind = turning_circle(k, 35, side="starboard", duration=60, dt=0.05).indices
    assert ind["advance_L"] == pytest.approx(3.085, rel=TOL)
    assert ind["transfer_L"] == pytest.approx(1.33, rel=TOL)
    assert ind["tactical_diameter_L"] == pytest.approx(3.11, rel=TOL)
    zz = zigzag(k, 20, 20, first="starboard", duration=80, dt=0.05).indices
    assert zz["first_overshoot_deg"] == pytest.approx(10.5, rel=TOL)
    assert zz["second_overshoot_deg"] == pytest.approx(15.7, rel=TOL)


@pytest.mark.parametrize("name", ["scale-ship", "mariner", "kvlcc2"])
def test_straight_run_holds_the_trimmed_speed(name):
    v = get_vessel(name)
    t = np.arange(0, 60, 0.1)
    log = simulate(v.dynamics, t, np.zeros(t.size), {"u": v.approach_speed}).log
    assert np.max(np.abs(log["u"] / v.approach_speed - 1)) < 0.01


def test_pull_out_of_a_stable_ship_returns_to_a_straight_course():
    # The scale ship's linearisation at 2 m/s (reference-ships.md §7.2).
    linear = ManoeuvringModel("linear-sway-yaw", {
        "v": {"v": -1.0568, "r": -0.9062, "delta": 0.052},
        "r": {"v": -1.3392, "r": -2.3398, "delta": -0.5503}})
    res = pull_out(linear, 20, hold=20, release=20, dt=0.05, speed=2.0)
    # Starboard means r > 0 whatever the rudder sign; steady r/δ = −0.517 (rad/s per rad).
    assert res.indices["yaw_rate_at_release"] == pytest.approx(0.517 * math.radians(20), rel=0.01)
    slowest = max(np.linalg.eigvals([[-1.0568, -0.9062], [-1.3392, -2.3398]]).real)  # −0.42
    assert abs(res.indices["residual_fraction"]) < 3 * math.exp(slowest * 20)


def test_manoeuvre_log_replays_exactly_with_simulate_log():
    ship = scale_ship(rudder_rate_deg=9.6)
    res = zigzag(ship, 20, 20, duration=30, dt=0.1, method="euler")
    again = simulate_log(ship.dynamics, res.log, "euler")
    np.testing.assert_allclose(again.log.to_numpy(), res.log.to_numpy(), rtol=1e-12, atol=1e-12)


def test_a_turn_without_its_indices_is_the_same_run():
    """``indices=False``, for checks that read only a held turn's states (and a zig-zag's, for
    validate's replicas): the same run to the bit, no indices; without a duration it would not
    know when to stop, and says so."""
    from shipid.errors import ShipidError

    ship = scale_ship()
    full = turning_circle(ship, 35, duration=120, dt=0.1)
    bare = turning_circle(ship, 35, duration=120, dt=0.1, indices=False)
    assert full.indices["tactical_diameter"] > 0 and bare.indices == {}
    np.testing.assert_array_equal(bare.log.to_numpy(), full.log.to_numpy())
    with pytest.raises(ShipidError, match="needs a duration"):
        turning_circle(ship, 35, indices=False)
    # The zig-zag too (validate's replicas, whose indices are read as the log's).
    full = zigzag(ship, 20, 20, duration=60, dt=0.1)
    bare = zigzag(ship, 20, 20, duration=60, dt=0.1, indices=False)
    assert full.indices["second_overshoot_deg"] > 0 and bare.indices == {}
    np.testing.assert_array_equal(bare.log.to_numpy(), full.log.to_numpy())
    with pytest.raises(ShipidError, match="needs a duration"):
        zigzag(ship, 20, 20, indices=False)


def test_a_model_s_manoeuvre_says_no_scale_it_does_not_know():
    # Bug: a model (which carries no scale) wrote its runs at scale 1, read back as full scale.
    ship = scale_ship()
    log = zigzag(ship.dynamics, 20, 20, duration=30, speed=1.9).log
    assert "scale" not in log.attrs and log.attrs["rudder_positive"] == ship.rudder_positive
    assert zigzag(ship, 20, 20, duration=30).log.attrs["scale"] == ship.scale


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"heading_deg": 0.0}, "heading switch"), ({"rudder_deg": 40.0}, "beyond the steering"),
     ({"first": "left"}, "starboard")],
)
def test_bad_manoeuvre_parameters(kwargs, match):
    with pytest.raises(ValueError, match=match):
        zigzag(scale_ship(), **({"duration": 5.0} | kwargs))


def test_turning_indices_of_a_circle_of_known_radius():
    R, w = 50.0, 0.02
    t = np.arange(0, 800, 0.5)
    psi = w * t
    log = make_log({"t": t, "delta": np.full(t.size, 0.3), "u": np.full(t.size, w * R),
                    "v": np.zeros(t.size), "r": np.full(t.size, w), "psi": psi,
                    "x": R * np.sin(psi), "y": R * (1 - np.cos(psi))})  # fmt: skip
    ind = turning_indices(log, t_order=0.0, length=10.0)
    # Events are interpolated linearly between samples 0.5 s (0.57°) apart: ~1e-5 of R.
    assert ind["advance"] == pytest.approx(R, rel=1e-4)
    assert ind["transfer"] == pytest.approx(R, rel=1e-4)
    assert ind["tactical_diameter"] == pytest.approx(2 * R, rel=1e-4)
    assert ind["steady_turning_diameter"] == pytest.approx(2 * R, rel=1e-9)
    assert ind["steady_yaw_rate"] == pytest.approx(w)
    assert ind["time_to_90"] == pytest.approx(math.pi / 2 / w, abs=1e-6)
    assert all(type(v) in (float, str) for v in ind.values())  # plain JSON-ready values
    assert ind["advance_L"] == pytest.approx(R / 10, rel=1e-4)
    # Without x, y the track is dead-reckoned from u, v, ψ.
    ind2 = turning_indices(log.drop(columns=["x", "y"]), t_order=0.0)
    assert ind2["tactical_diameter"] == pytest.approx(2 * R, rel=1e-4)
    assert detect_manoeuvre(log) == "turning"


def test_zigzag_indices_of_a_heading_trace_with_known_extrema():
    # Δψ = 25° sin(ωt): with a 20° switch, the executes are where |Δψ| = 20° and each overshoot
    # is 5°, the time to check yaw is from asin(0.8)/ω to the extremum at π/(2ω).
    w = 2 * math.pi / 60
    t = np.arange(0, 130, 0.01)
    dpsi = math.radians(25) * np.sin(w * t)
    rudder = np.where(np.sin(w * t - math.asin(0.8)) > 0, -0.35, 0.35)
    rudder[0] = 0.0
    log = make_log({"t": t, "delta": rudder, "u": np.ones(t.size), "v": np.zeros(t.size),
                    "r": np.gradient(dpsi, t), "psi": dpsi})  # fmt: skip
    ind = zigzag_indices(log, heading_deg=20, t_order=0.0)
    assert ind["first_overshoot_deg"] == pytest.approx(5.0, abs=1e-4)
    assert ind["second_overshoot_deg"] == pytest.approx(5.0, abs=1e-4)
    assert ind["initial_turning_time"] == pytest.approx(math.asin(0.8) / w, abs=1e-3)
    assert ind["time_to_check_yaw"] == pytest.approx((math.pi / 2 - math.asin(0.8)) / w, abs=0.02)
    inferred = zigzag_indices(log, t_order=0.0)  # switch heading inferred from rudder reversals
    assert inferred["switch_heading_deg"] == pytest.approx(20.0, abs=0.05)
    # Read without being told its order, the trace turns at its largest rate at its first
    # sample: a log cut inside a zig-zag, whose approach heading it does not hold.
    assert detect_manoeuvre(log) == "other"


def test_sensor_model_is_seeded_and_has_the_stated_noise():
    t = np.arange(0, 2000, 0.2)
    clean = make_log({"t": t, "delta": np.zeros(t.size), "u": np.ones(t.size),
                      "v": np.zeros(t.size), "r": np.zeros(t.size), "psi": np.zeros(t.size)})
    a, b = PAPER_IMU.apply(clean, seed=3), PAPER_IMU.apply(clean, seed=3)
    assert a.equals(b) and not a.equals(PAPER_IMU.apply(clean, seed=4))
    assert np.std(a["u"] - 1) == pytest.approx(0.04, rel=0.05)
    assert np.std(a["psi"]) == pytest.approx(math.radians(0.05), rel=0.05)
    assert np.all(a["delta"] == 0)


@pytest.mark.parametrize("cut", [0.0, 1.0, 3.0, 4.0, 4.5, 5.0, 5.5, 8.0])
def test_a_zigzag_cut_inside_its_manoeuvre_reads_as_none(cut):
    """A log that starts inside a zig-zag holds no approach heading, which its overshoots are
    measured from. Cut 3–8 s into the scale ship's 30/30 (after its first reversal, the rudder
    at −30°, the ship turning or, at 4 s, at the heading's extreme and drifting), it read as a
    zig-zag whose execute was its next reversal: overshoots 1.2°–9.0° and 22.0°–30.0° against
    the whole run's 7.0° and 17.3°; cut 1 s in, 18.6° and none. It reads as none now, and
    where the ship turns at its first sample, that is the reason; from its order (cut 0, the
    rudder over from the first sample, the ship straight) it is the zig-zag it was."""
    from shipid.trials.trial import describe_trial

    res = zigzag(scale_ship(), 30, 30, duration=60, dt=0.1)
    whole = zigzag_indices(res.log)
    late = res.log[res.log["t"] >= cut].reset_index(drop=True)
    late.attrs = dict(res.log.attrs)
    trial = describe_trial(late)
    r = np.abs(late["r"].to_numpy())
    if cut == 0.0:
        assert trial.kind == "zigzag" and trial.turning_at_order is None
        assert zigzag_indices(late)["first_overshoot_deg"] == whole["first_overshoot_deg"]
        return
    assert trial.kind == "other", trial
    if r[0] > 0.1 * r.max():
        assert trial.turning_at_order == pytest.approx(r[0] / r.max())
        assert trial.reason.startswith(f"it starts inside its manoeuvre, the ship turning at "
                                       f"{100 * r[0] / r.max():.0f} %")  # fmt: skip


# Accelerations of the NumPy implementation the compiled physics replaced (commit af37349), at
# states off the trimmed run: the compiled scalar code must give the same numbers.
MARINER_STATES = [[7.71873, -0.363737, -0.004922, 0.031624], [8.016246, -0.793317, -0.006205, -0.27914],
                  [7.443362, 0.048115, 0.004898, -0.008776], [6.826908, 1.072172, 0.003569, 0.208591]]
MARINER_ACC = [[0.000788394334601078, 0.026719857496448073, 0.000854151808363587],
               [-0.005273783491688095, 0.02444288351031545, 0.003016670696314775],
               [0.003007075159495063, -0.014636573101747694, -0.0004036829538022366],
               [0.0037709256067353382, -0.02966623373182463, -0.0017005374771294297]]
KVLCC2_STATES = [[0.910157, -0.184174, 0.007838, -0.0194], [1.087477, -0.023509, -0.009347, 0.045324],
                 [0.798755, -0.126745, -0.125838, -0.612054], [0.921092, 0.027126, -0.026935, -0.191101]]
KVLCC2_ACC = [[0.0031363064071741344, 0.017375056741102537, 0.008704520767722048],
              [0.002925331828450515, 0.004515277393921785, 0.0067415615778668985],
              [0.03870451447915523, 0.06768165027370017, 0.032378439938102306],
              [0.005401192685838309, 0.011791988894091013, 0.0004852666520730444]]  # fmt: skip


@pytest.mark.parametrize(("dynamics", "states", "expected"), [
    (lambda: mariner().dynamics, MARINER_STATES, MARINER_ACC),
    (lambda: KVLCC2Dynamics(11.85), KVLCC2_STATES, KVLCC2_ACC)])  # fmt: skip
def test_compiled_ship_physics_equals_the_numpy_formulas(dynamics, states, expected):
    s = np.array(states)
    acc = dynamics().derivatives(s[:, :3], s[:, 3])
    np.testing.assert_allclose(acc, expected, rtol=1e-12)


class _DerivativesOnly:
    """A reference ship seen through ``derivatives`` only: the NumPy RK4 path of the simulator."""

    uses_thrust = False

    def __init__(self, dynamics):
        self.dynamics = dynamics

    def derivatives(self, nu, delta, thrust=None):
        return self.dynamics.derivatives(nu, delta)


@pytest.mark.parametrize("name", ["mariner", "kvlcc2"])
def test_compiled_closed_and_open_loops_equal_the_numpy_path(name):
    ship = get_vessel(name)
    numpy_ship = dataclasses.replace(ship, dynamics=_DerivativesOnly(ship.dynamics))
    dt = 0.5 if name == "mariner" else 0.1
    fast = zigzag(ship, 20, 20, duration=60, dt=dt).log
    slow = zigzag(numpy_ship, 20, 20, duration=60, dt=dt).log
    np.testing.assert_allclose(fast.to_numpy(), slow.to_numpy(), rtol=1e-10, atol=1e-12)
    again = simulate_log(numpy_ship.dynamics, fast, "rk4").log
    replay = simulate_log(ship.dynamics, fast, "rk4").log
    np.testing.assert_allclose(replay.to_numpy(), again.to_numpy(), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(replay[["u", "v", "r"]], fast[["u", "v", "r"]], rtol=1e-10,
                               atol=1e-12)  # fmt: skip


def test_the_spiral_runs_to_the_largest_rudder_the_gear_allows(tmp_path, capsys):
    """``manoeuvre tanker spiral`` stopped on its default 25°: the tanker's gear stops at 10°.
    The default angles now run to the gear's limit (the standard sequence where it allows
    25°), the same spiral as the angles given by hand, and the command says so."""
    import json

    from cli_helpers import run

    from shipid.trials.manoeuvres import spiral, spiral_angles

    assert spiral_angles() == (25, 15, 10, 5, 2, 0, -2, -5, -10, -15, -25, -15, -10, -5, -2, 0,
                               2, 5, 10, 15, 25)  # fmt: skip
    assert spiral_angles(10.0) == (10, 5, 2, 0, -2, -5, -10, -5, -2, 0, 2, 5, 10)
    assert spiral_angles(7.5)[:4] == (7.5, 5, 2, 0) and spiral_angles(40.0) == spiral_angles()
    tanker = get_vessel("tanker")
    by_hand = spiral(tanker, spiral_angles(10.0), hold=600.0).indices["table"]
    assert spiral(tanker, hold=600.0).indices["table"] == by_hand
    code, _, err = run(["manoeuvre", "tanker", "spiral", "--duration", "600", "--json",
                        tmp_path / "s.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "largest rudder is 10°: the spiral's angles run to it instead of 25°" in err
    table = json.loads((tmp_path / "s.json").read_text())["indices"]["table"]
    assert [row["rudder_deg"] for row in table] == [row["rudder_deg"] for row in by_hand]
