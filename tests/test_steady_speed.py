"""Where a model's surge balances is what the logs determine least (issue #10): the Esso Osaka's
zig-zags and random runs never run steady, and the default fit at their 0.1 s balances at
0.52 m/s at 10 rps, where the ship holds 0.35 m/s. `--steady-speed U@N` says where the ship runs
steady (a straight run's speed); the steady-speed constraint no longer takes the start of a log
that speeds up there for a steady state."""

import pytest
from cli_helpers import run
from test_equilibrium import PROPELLED, steady
from test_turning_replica import turning_log

from shipid.data.io import write_log
from shipid.data.log import steady_start
from shipid.dynamics.equilibrium import surge_equilibrium
from shipid.errors import ShipidError
from shipid.identification.identify import identify
from shipid.identification.physics import PhysicsOptions
from shipid.reporting.modelfile import load_model

SPEC = "u: |u|u, pos(n)^2; v: u*r, u*v, delta; r: u*r, u*v, delta"


def speeding_up(rps: float, side: str = "starboard"):
    """A 35° turn at ``rps`` entered at 60 % of the steady speed: the approach speeds up."""
    return turning_log(side, speed=0.6 * steady(rps), rps=rps)


def test_a_log_that_speeds_up_is_told_from_one_that_runs_steady():
    assert steady_start(speeding_up(10.0)).steady is False
    start = steady_start(turning_log("port"))
    assert start.steady is True and start.speed == pytest.approx(steady(10.0), rel=1e-6)
    # A log whose rudder is hard over from its first sample has no approach to judge.
    hard_over = turning_log("port").iloc[101:].reset_index(drop=True)
    assert steady_start(hard_over).steady is None


def test_the_constraint_leaves_out_starts_that_speed_up_and_refuses_when_none_is_left():
    logs = [speeding_up(8.0), turning_log("port", rps=14.0)]
    fit = identify(logs, PROPELLED.structure, force=True,
                   physics=PhysicsOptions(steady_speed=True))  # fmt: skip
    (note,) = [w for w in fit.warnings if "steady speed imposed" in w]
    assert f"{steady(14.0):.4g} m/s at 14 rps" in note and " at 8 rps" not in note
    # u̇ = 0 where the steady log starts: the fit's balance there is exact.
    assert surge_equilibrium(fit.model, steady(14.0), 14.0) == pytest.approx(steady(14.0),
                                                                              rel=1e-3)
    with pytest.raises(ShipidError, match="no training log starts on a steady straight"):
        identify([speeding_up(8.0), speeding_up(14.0, "port")], PROPELLED.structure,
                 force=True, physics=PhysicsOptions(steady_speed=True))  # fmt: skip


def test_a_given_steady_speed_sets_where_the_surge_balances(tmp_path, capsys):
    paths = [write_log(speeding_up(n, side), tmp_path / f"{side}.csv")
             for n, side in ((8.0, "port"), (14.0, "starboard"))]  # fmt: skip
    args = ["identify", *paths, "--model", SPEC]
    assert run([*args, "-o", tmp_path / "free.json"], capsys)[0] == 0
    free = load_model(tmp_path / "free.json")
    assert surge_equilibrium(free, 0.3, 10.0) == pytest.approx(steady(10.0), rel=0.02)
    # A speed 20 % above what the logs' surge gives: the fit balances there.
    given = 1.2 * steady(10.0)
    code, out, err = run([*args, "--steady-speed", f"{given}@10", "-o", tmp_path / "g.json"],
                         capsys)  # fmt: skip
    assert code == 0, err
    fitted = load_model(tmp_path / "g.json")
    assert surge_equilibrium(fitted, given, 10.0) == pytest.approx(given, rel=1e-3)
    assert "steady speed imposed on the approach" in err
    # With |u|u and n⁺² alone, a balance at one rps is one at every rps: u ∝ n.
    assert surge_equilibrium(fitted, given, 14.0) == pytest.approx(given * 1.4, rel=1e-3)


@pytest.mark.parametrize(("value", "message"), [
    ("abc", "--steady-speed expects U@N"), ("0.3@x", "--steady-speed expects U@N"),
    ("-0.3@10", "the speed must be > 0"), ("nan@10", "the speed must be > 0")])
def test_a_bad_steady_speed_is_one_clear_error(tmp_path, capsys, value, message):
    path = write_log(speeding_up(10.0), tmp_path / "a.csv")
    code, _, err = run(["identify", path, "--model", SPEC, f"--steady-speed={value}",
                        "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 1 and message in err and "Traceback" not in err
    assert not (tmp_path / "m.json").exists()
