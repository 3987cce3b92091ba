"""Where a model's surge balances is what the logs determine least (issue #10): the Esso Osaka's
zig-zags and random runs never run steady, and the default fit at their 0.1 s balanced at 0.52 m/s
at 10 rps, where the ship holds 0.35 m/s (0.387 with the hull's resistance in every candidate).
`--steady-speed U@N` says where the ship runs steady (a straight run's speed); the steady-speed
constraint no longer takes the start of a log that speeds up there for a steady state."""

from pathlib import Path

import pytest
from cli_helpers import run
from test_equilibrium import PROPELLED, steady
from test_turning_replica import turning_log

from shipid.data.io import write_log
from shipid.data.log import relative_wind, steady_start
from shipid.dynamics.equilibrium import surge_equilibrium
from shipid.errors import ShipidError
from shipid.identification.beyond_the_logs import missed_steady_speed
from shipid.identification.identify import identify
from shipid.identification.physics import PhysicsOptions, similar_steady_speeds
from shipid.reporting.modelfile import load_model

SPEC = "u: |u|u, pos(n)^2; v: u*r, u*v, delta; r: u*r, u*v, delta"
DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


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


def test_a_turn_that_ends_going_astern_rules_a_model_out():
    """A held-rudder turn entered ahead that ends going astern, the propeller unchanged: the
    Esso zig-zags' fit under --steady-speed 0.35@10 at Δk 0.5 s came out with a negative thrust
    term held up by u·|n|, and at 10 rps its 35° turn ended at −0.74 m/s."""
    from shipid.identification.plausibility import disqualifying, failed_checks

    model = PROPELLED
    report = {"approach_speed": 0.35, "rps": 10.0, "straight_line": None,
              "surge_equilibrium": 0.35, "rudder_deg": 35.0,
              "held_rudder": {"starboard": {"diverged": False, "settled": True,
                                            "steady_yaw_rate": 0.286, "steady_speed": -0.739},
                              "port": {"diverged": False, "settled": True,
                                       "steady_yaw_rate": -0.05, "steady_speed": 0.15}}}
    assert disqualifying(report, model) == ["ends going astern with the rudder held to starboard"]
    (note,) = failed_checks(report, model).values()
    assert "ends the turn going astern" in note[1] and "-0.739" in note[1]


@pytest.mark.parametrize("thrust, advance, astern_below", [
    (8e-5, -1e-3, None),  # thrust falling with the advance: ahead all the way from rest
    (-8.05e-5, 0.0139, "root"),  # the Esso's eight files' fit: riding on u·|n|
])
def test_a_surge_that_pushes_a_ship_at_rest_astern_is_warned_of(thrust, advance, astern_below):
    """u̇ = a n² + b u|n| − c |u|u has two roots where a < 0 < b: the straight speed (the larger)
    and, below it, a speed under which the ship goes astern. ``from_rest`` finds the smaller
    within one step of its grid; the checks warn of it and do not rule the model out (as a
    rule it sent the Esso's zig-zag sets to worse fits)."""
    import numpy as np

    from shipid.dynamics.model import ManoeuvringModel
    from shipid.identification.plausibility import (
        FROM_REST_POINTS,
        FROM_REST_SHARE,
        disqualifying,
        failed_checks,
        from_rest,
        plausibility_at_approach,
    )

    n, c = 16.67, 0.324
    model = ManoeuvringModel("u: |u|u, pos(n)^2, u*|n|; v: v; r: r",
                             {"u": {"|u|u": -c, "pos(n)^2": thrust, "u*|n|": advance},
                              "v": {"v": -1.0}, "r": {"r": -1.0}})  # fmt: skip
    roots = np.sort(np.roots([-c, advance * n, thrust * n**2]).real)
    straight = surge_equilibrium(model, 0.3, n)
    assert straight == pytest.approx(roots[-1], rel=1e-6)
    found = from_rest(model, n, straight)
    if astern_below is None:
        assert found is None
        return
    step = FROM_REST_SHARE * straight / (FROM_REST_POINTS - 1)
    assert roots[0] - step < found <= roots[0]
    report, notes = plausibility_at_approach(model, 0.3, n)
    assert report["from_rest"] == pytest.approx(found)
    assert not any("from rest" in reason for reason in disqualifying(report, model))
    said = (f"from rest, the propeller ahead at 16.67 rps and the rudder amidships, the surge "
            f"pushes astern (below {found:.3g} m/s), short of its straight speed "
            f"{straight:.3g} m/s: it cannot get under way; its thrust rides on the advance, "
            f"u |n| at +0.0139 against pos(n)² at -8.05e-05, a term even in n that pushes "
            "ahead whichever way the propeller turns: --bound 'u: u*|n| <= 0' (or --constraints "
            "signs) holds it to the thrust's fall with the advance")  # fmt: skip
    assert said in notes
    assert failed_checks(report, model)["from_rest"][1] == said


@pytest.mark.parametrize("thrust, advance, warned", [(8e-5, -1e-3, False), (-8.05e-5, 0.0139, True)])
def test_the_commands_that_run_a_model_file_repeat_the_from_rest_warning(
        tmp_path, capsys, thrust, advance, warned):  # fmt: skip
    """``identify`` warned once of a model that cannot get under way; ``manoeuvre``,
    ``criteria`` and ``validate`` of its file said nothing. They check it on the model as they
    run it (the model at its own straight speed, or at the one given)."""
    import json

    from shipid.dynamics.model import ManoeuvringModel
    from shipid.identification.plausibility import from_rest
    from shipid.trials.manoeuvres import zigzag

    n = 16.67
    model = ManoeuvringModel("u: |u|u, pos(n)^2, u*|n|; v: v, delta; r: r, delta",
                             {"u": {"|u|u": -0.324, "pos(n)^2": thrust, "u*|n|": advance},
                              "v": {"v": -1.0, "delta": 0.01}, "r": {"r": -1.0, "delta": -0.05}})
    straight = surge_equilibrium(model, 0.5, n)
    found = from_rest(model, n, straight)
    assert (found is not None) == warned
    path = model.save(tmp_path / "m.json")
    doc = json.loads(path.read_text())
    doc["identification"] = {"preprocessing": {"approach_speed": straight, "approach_rps": n}}
    path.write_text(json.dumps(doc))
    log = tmp_path / "zz.csv"
    write_log(zigzag(model, 20, 20, duration=20, dt=0.2, speed=straight, rps=n).log, log)
    said = (f"plausibility: from rest, the propeller ahead at 16.67 rps and the rudder amidships, "
            f"the surge pushes astern (below {found or 0:.3g} m/s), short of its straight speed "
            f"{straight:.3g} m/s: it cannot get under way; its thrust rides on the advance, "
            f"u |n| at +0.0139 against pos(n)² at -8.05e-05, a term even in n")  # fmt: skip
    for argv in (["manoeuvre", path, "zigzag", "--duration", "20"],
                 ["manoeuvre", path, "turning", "--speed", "0.3", "--rps", str(n),
                  "--duration", "20"],
                 # Begun below the lower root (0.115 m/s): no straight speed within
                 # surge_equilibrium's span of 0.05, and the warning was passed over.
                 ["manoeuvre", path, "turning", "--speed", "0.05", "--rps", str(n),
                  "--duration", "20"],
                 ["criteria", path, "--length", "3", "--scale", "1"],
                 ["validate", path, log, "--no-bands"]):  # fmt: skip
        code, _, err = run(argv, capsys)
        assert code == 0, err
        assert (said in err) == warned, (argv[0], err)


@pytest.mark.skipif(not (DATA / "esso-osaka").is_dir(), reason="../shared/data is not present")
def test_the_search_leaves_out_models_that_end_a_turn_going_astern(tmp_path, capsys):
    """The same fit: a candidate whose held-rudder turn ends going astern is ruled out (from the
    first log's approach, and at the speed given), so the chosen model's 35° turn at 10 rps keeps
    its headway."""
    raw = sorted((DATA / "esso-osaka" / "zigzag").glob("*.csv"))
    code, _, err = run(["import", "--format", "osaka-frt", "--start", "auto", "--end", "auto",
                        *raw, "-o", tmp_path / "zz"], capsys)  # fmt: skip
    assert code == 0, err
    zigzags = sorted((tmp_path / "zz").glob("*.csv"))
    code, _, err = run(["identify", *zigzags, "--dt", "0.5", "--steady-speed", "0.35@10",
                        "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    model = load_model(tmp_path / "m.json")
    assert surge_equilibrium(model, 0.35, 10.0) == pytest.approx(0.35, rel=1e-3)
    from shipid.trials.manoeuvres import turning_circle

    for side in ("starboard", "port"):
        turn = turning_circle(model, 35.0, side, speed=0.35, rps=10.0, dt=0.1, method="euler")
        # (the indices' steady speed is the magnitude: the surge itself says which way)
        assert turn.log["u"].iloc[-1] > 0.05, side


def test_a_manoeuvre_that_ends_astern_is_named_though_its_steady_speed_is_a_magnitude():
    import pandas as pd

    from shipid.evaluation.envelope import implausible_indices

    u = [0.35] * 50 + [-0.74] * 50
    log = pd.DataFrame({"t": range(100), "u": u})
    notes = implausible_indices({"steady_speed": 0.74, "tactical_diameter": 8.1}, 0.35, 3.0, log)
    assert any("ends the turn going astern (u = -0.74 m/s" in n for n in notes)
    ahead = log.assign(u=[0.35] * 50 + [0.15] * 50)
    assert implausible_indices({"steady_speed": 0.15}, 0.35, 3.0, ahead) == []


def test_every_surge_candidate_of_a_propelled_library_holds_the_hull_resistance():
    """A ship whose thrust falls with advance (u·|n|) and whose hull resists as |u|u: on equation
    error the ranking may put u·|n| first and a sparse candidate leave the hull's resistance
    out; at the Esso logs' 0.1 s one did, and balanced 48 % fast at 10 rps. |u|u now leads the
    surge's ranking of a library with propeller terms."""
    from shipid.dynamics.model import ManoeuvringModel, ModelStructure
    from shipid.identification.select import select
    from shipid.trials.manoeuvres import zigzag

    lateral = ("u*r", "u*v", "delta")
    truth = ManoeuvringModel(
        ModelStructure("t", {"u": ("|u|*u", "u*|n|", "pos(n)^2"), "v": lateral, "r": lateral}),
        {"u": {"|u|*u": -0.02, "u*|n|": -0.004, "pos(n)^2": 4e-4},
         "v": PROPELLED.coefficients["v"], "r": PROPELLED.coefficients["r"]})  # fmt: skip
    logs = []
    for n in (8.0, 14.0):
        log = zigzag(truth, 20.0, 20.0, duration=40.0, dt=0.2, approach=5.0, speed=0.05 * n,
                     rps=n, method="euler").log  # fmt: skip
        logs.append(log.assign(n=n))
    library = ModelStructure("lib", {"u": ("u*|n|", "pos(n)^2", "|u|*u", "v*r", "1"),
                                     "v": lateral, "r": lateral})  # fmt: skip
    sel = select(logs, library=library, gammas=(1e4,))
    assert sel.ranking["u"][0][0] == "|u|*u"
    assert "|u|*u" in sel.model.structure.terms["u"]


def test_a_wind_model_holds_the_given_speed_in_still_air():
    """In still air the anemometer reads the ship's own motion (a head wind of its speed), and
    the closed loop runs the wind's terms with it: the equality u̇ = 0 must too. It took the
    wind's terms at 0 and put a wind model's straight run off the speed it was given."""
    logs = []
    for rps, side in ((8.0, "port"), (14.0, "starboard")):
        log = speeding_up(rps, side)
        speed, angle = relative_wind(log["u"], log["v"], log["psi"], (1.5, 0.7))
        logs.append(log.assign(wind_speed=speed, wind_angle=angle))
    given = 1.1 * steady(10.0)
    fit = identify(logs, SPEC.replace("pos(n)^2;", "pos(n)^2, U_A^2*cos(gamma_A);"), force=True,
                   physics=PhysicsOptions(steady_speed=True, approach={"u": given, "n": 10.0}))
    model = fit.model
    assert surge_equilibrium(model, given, 10.0) == pytest.approx(given, rel=1e-9)
    # The wind's term carries part of the balance: taken at 0 it leaves the model's straight run
    # 0.05 % off, 10⁵ times the tolerance above.
    def surge(speed: float, wind: float) -> float:
        return model.accelerations([speed], [0.0], [0.0], [0.0], None, [10.0],
                                   wind_speed=[wind], wind_angle=[0.0])[0, 0]  # fmt: skip

    h = 1e-3 * given
    slope = (surge(given + h, given + h) - surge(given - h, given - h)) / (2 * h)
    assert abs(surge(given, 0.0) / slope) > 1e-4 * given


def test_a_speed_given_at_another_rps_than_the_logs_one_is_held_there(tmp_path, capsys):
    """Logs at one rps: the model file carries the fit to every rps by similarity (speed ∝ rps).
    The equality took the fit's terms at the rps given instead, so a speed given at 14 rps to a
    fit of logs at 10 was held wherever the similarity put it, not at 14."""
    path = write_log(speeding_up(10.0), tmp_path / "a.csv")
    given = 1.1 * steady(14.0)
    # The thrust in the fit's constant, as the paper's surge has it: similarity writes it |n|n.
    unpropelled = SPEC.replace("|u|u, pos(n)^2", "|u|u, 1")
    code, _, err = run(["identify", path, "--model", unpropelled, "--steady-speed",
                        f"{given}@14", "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    model = load_model(tmp_path / "m.json")
    assert surge_equilibrium(model, given, 14.0) == pytest.approx(given, rel=1e-6)
    assert surge_equilibrium(model, given, 10.0) == pytest.approx(given * 10 / 14, rel=1e-6)
    assert f"{given * 10 / 14:.4g} m/s at 10 rps, the logs' one rps" in err
    assert f"puts the {given:.4g} m/s at 14 rps given" in err
    assert "not the speed given" not in err
    # Two speeds similarity cannot both hold: one clear error, no model file.
    code, _, err = run(["identify", path, "--model", SPEC, "--steady-speed", "0.30@10",
                        "--steady-speed", "0.45@14", "-o", tmp_path / "two.json"], capsys)
    assert code == 1 and "which one straight run cannot all hold" in err
    assert "0.3, 0.3214 m/s at 10 rps" in err and not (tmp_path / "two.json").exists()


def test_similar_steady_speeds_carries_them_to_the_logs_rps():
    assert similar_steady_speeds([{"u": 0.42, "n": 12.0}], None) == [{"u": 0.42, "n": 12.0}]
    (one,) = similar_steady_speeds([{"u": 0.42, "n": 12.0}], 10.0)
    assert one == {"u": pytest.approx(0.35), "n": 10.0, "given_u": 0.42, "given_n": 12.0}
    # Given twice, rounded (within 1 %): one speed, their mean.
    (both,) = similar_steady_speeds([{"u": 0.35, "n": 10.0}, {"u": 0.421, "n": 12.0}], 10.0)
    assert both["u"] == pytest.approx((0.35 + 0.421 * 10 / 12) / 2) and both["n"] == 10.0
    with pytest.raises(ShipidError, match="cannot all hold"):
        similar_steady_speeds([{"u": 0.35, "n": 10.0}, {"u": 0.45, "n": 12.0}], 10.0)
    # A speed given without rps to a fit of propelled logs: at their rps.
    assert similar_steady_speeds([{"u": 0.35, "n": 0.0}], 10.0) == [{"u": 0.35, "n": 10.0}]


def test_a_model_that_does_not_hold_a_given_speed_is_named():
    assert missed_steady_speed(PROPELLED, steady(10.0), 10.0) is None
    note = missed_steady_speed(PROPELLED, 1.2 * steady(10.0), 10.0)
    assert note.startswith(f"--steady-speed {1.2 * steady(10.0):.4g}@10: the model holds "
                           f"{steady(10.0):.4g} m/s straight at 10 rps, not the speed given")


@pytest.mark.parametrize("surge, named", [
    ({"u*|n|": 0.0139, "pos(n)^2": -8.05e-5}, "u |n| at +0.0139 against pos(n)² at -8.05e-05"),
    ({"u*pos(n)": 0.01}, "u pos(n) at +0.01 with no thrust in n²"),
    ({"u*|n|": 0.0139, "pos(n)^2": 8e-5}, None),  # a thrust ahead: the advance is not why
    ({"u*|n|": 0.0139, "propeller(0.5)": 8e-5}, None),  # the same, written for going astern
    ({"u*|n|": -0.001, "pos(n)^2": -8e-5}, None),  # the advance falls as it should
])
def test_a_thrust_riding_on_the_advance_is_named_with_the_bound_that_holds_it(surge, named):
    from shipid.dynamics.model import ManoeuvringModel
    from shipid.identification.plausibility import _thrust_on_the_advance

    terms = ", ".join(["|u|u", *surge])
    model = ManoeuvringModel(f"u: {terms}; v: v; r: r",
                             {"u": {"|u|u": -0.3, **surge}, "v": {"v": -1.0}, "r": {"r": -1.0}})
    note = _thrust_on_the_advance(model)
    if named is None:
        assert note == ""
    else:
        term = next(t for t in surge if t.startswith("u*"))
        assert note == (f"; its thrust rides on the advance, {named}, a term even in n that "
                        "pushes ahead whichever way the propeller turns: --bound "
                        f"'u: {term} <= 0' (or --constraints signs) holds it to the thrust's "
                        "fall with the advance")  # fmt: skip
