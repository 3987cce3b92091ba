"""`validate` runs a turning log's turn on the model as `shipid manoeuvre turning` runs it (issue
#10): from the model's own steady straight speed at the log's propeller speed. Its replay starts
from the measured state, so a model whose surge balances at the wrong speed was never caught:
trained on the Esso Osaka's zig-zags and random runs at their Δk of 0.1 s, the README's terms
reached 0.52 m/s at 10 rps, where the ship's 35° turns approach at 0.35 m/s."""

import math

import numpy as np
import pytest
from test_equilibrium import A_UU, B_NN, PROPELLED, steady

from shipid.data.trim import trim
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.evaluation.validate import (
    APPROACH_LEAD_S,
    free_run,
    steady_log_approach,
    validate,
)
from shipid.trials.manoeuvres import turning_circle
from shipid.trials.trial import describe_trial
from shipid.vessels.sensors import sampled_as_measured

RPS = 10.0


def turning_log(side: str, held: float = 0.0, speed: float | None = None, rps: float = RPS,
                approach: float = 10.0):
    """A 35° turn of ``PROPELLED`` at ``rps``, ``approach`` s of approach with the rudder held at
    ``held`` [rad], from ``speed`` (default: its steady speed)."""
    res = turning_circle(PROPELLED, 35.0, side, duration=140.0 + approach, dt=0.1, approach=approach,
                         speed=speed or steady(rps), rps=rps, method="euler",
                         initial={"delta": held})  # fmt: skip
    log = res.log.copy()
    log["n"] = rps
    return log


def with_thrust(factor: float) -> ManoeuvringModel:
    coefficients = {d: dict(c) for d, c in PROPELLED.coefficients.items()}
    coefficients["u"]["pos(n)^2"] = factor * B_NN
    return ManoeuvringModel(PROPELLED.structure, coefficients)


@pytest.mark.parametrize("side", ["starboard", "port"])
@pytest.mark.parametrize("held", [0.04, -0.04])
def test_the_true_model_predicts_its_own_turn_closed_loop(side, held):
    log = turning_log(side, held)
    (v,) = validate(PROPELLED, log)
    measured, closed = v.indices["measured"], v.indices["closed_loop"]
    assert v.kind == "turning"
    assert measured["approach_speed"] == pytest.approx(steady(RPS), rel=1e-6)
    assert closed["approach_speed"] == pytest.approx(steady(RPS), rel=1e-6)
    # The turn's side: a held approach rudder on either side (the Esso's rests at 2°, then goes
    # to 35°) once put the closed loop on the other side.
    assert np.sign(closed["steady_yaw_rate"]) == np.sign(measured["steady_yaw_rate"])
    for k in ("advance", "transfer", "tactical_diameter", "steady_yaw_rate"):
        assert closed[k] == pytest.approx(measured[k], rel=0.01), k
    assert not any("steady straight speed" in w for w in v.warnings)


def test_a_model_that_runs_too_fast_at_the_rps_is_named_and_turns_from_its_own_speed():
    log = turning_log("starboard")
    fast = with_thrust(2.25)  # u = n √(−b/a): 1.5 times the speed
    (v,) = validate(fast, log)
    own = RPS * math.sqrt(-2.25 * B_NN / A_UU)
    assert v.indices["closed_loop"]["approach_speed"] == pytest.approx(own, rel=1e-3)
    assert v.indices["measured"]["approach_speed"] == pytest.approx(own / 1.5, rel=1e-6)
    (warning,) = [w for w in v.warnings if "steady straight speed" in w]
    assert "+50 %" in warning and f"{own:.4g} m/s" in warning
    # The replay starts from the measured state; the closed loop from the model's approach, so
    # it goes further before the turn settles.
    replay, closed = v.indices["simulated"], v.indices["closed_loop"]
    assert closed["advance"] > replay["advance"] * 1.05


def test_a_log_that_approaches_accelerating_is_replayed_from_its_own_state():
    log = turning_log("starboard", speed=0.6 * steady(RPS))
    trial = describe_trial(log, "turning")
    assert steady_log_approach(log, trial) is None
    (v,) = validate(with_thrust(2.25), log)
    # No steady approach to compare with: the closed loop starts where the log does, 5 s
    # before the execute (``manoeuvre_from_approach``).
    start = log.loc[log["t"] >= trial.execute_time - APPROACH_LEAD_S, "u"].iloc[0]
    assert v.indices["closed_loop"]["approach_speed"] == pytest.approx(start)
    assert v.indices["measured"]["approach_speed"] == pytest.approx(start)
    assert not any("steady straight speed" in w for w in v.warnings)


def test_a_propeller_stopped_at_the_logs_end_does_not_slow_the_replica():
    """Bug: the replica held the log's mean rps, and a log read whole ends with the propeller
    stopped (the Esso Osaka's zig-zags for 2–8 s: 13_14_21's mean 15.6 rps for 16.7). Here the
    true model's turn from an accelerating approach, its last 30 s logged at n = 0."""
    log = turning_log("starboard", speed=0.6 * steady(RPS))
    log.loc[log["t"] > log["t"].iloc[-1] - 30.0, "n"] = 0.0
    assert log["n"].mean() < 0.85 * RPS
    (v,) = validate(PROPELLED, log)
    measured, closed = v.indices["measured"], v.indices["closed_loop"]
    for k in ("advance", "tactical_diameter", "steady_yaw_rate"):
        assert closed[k] == pytest.approx(measured[k], rel=0.01), k


@pytest.mark.parametrize("first_speed", [0.01, -0.01])
def test_a_turn_that_gathers_speed_from_rest_is_judged_from_its_approach(first_speed):
    """Bug: the Esso Osaka's turning logs start at rest and gather speed for 120 s before the
    execute. `validate` took the first sample's 0.011 m/s as the measured approach speed, ran
    the replay and the closed loop through those 120 s (a zig-zag model's +35° tactical
    diameter 4.1 m from there, 9.9 m from the approach; measured 7.3 m), and a log starting at
    −0.014 m/s got no closed loop at all, without a word."""
    log = turning_log("starboard", speed=0.01, approach=120.0)
    log.loc[0, "u"] = first_speed  # a log at rest reads either side of zero
    trial = describe_trial(log, "turning")
    at_execute = float(log["u"].iloc[trial.execute_index])
    assert at_execute == pytest.approx(steady(RPS), rel=1e-3)  # it is steady by then
    (true,) = validate(PROPELLED, log)
    measured, closed = true.indices["measured"], true.indices["closed_loop"]
    assert measured["approach_speed"] == pytest.approx(at_execute, rel=1e-3)
    for k in ("advance", "transfer", "tactical_diameter", "steady_yaw_rate"):
        assert closed[k] == pytest.approx(measured[k], rel=0.01), k
    (warning,) = [w for w in true.warnings if "approach is not steady" in w]
    assert f"u {first_speed:.3g} m/s at t = 0 s" in warning
    # A model 50 % fast: its indices are those of the log cut 5 s before the execute, as
    # --start auto cuts it, and its errors those of the whole log.
    fast = with_thrust(2.25)
    (whole,) = validate(fast, log)
    cut = trim(log, start="auto", lead=APPROACH_LEAD_S)
    (part,) = validate(fast, cut)
    for column in ("measured", "simulated", "closed_loop"):
        numbers = {k: x for k, x in part.indices[column].items() if isinstance(x, float)}
        assert len(numbers) >= 6
        for k, x in numbers.items():
            assert whole.indices[column][k] == pytest.approx(x, rel=1e-9), (column, k)
    assert whole.indices["closed_loop"]["approach_speed"] == pytest.approx(1.5 * steady(RPS),
                                                                          rel=1e-3)
    assert any("+50 %" in w for w in whole.warnings)
    assert whole.metrics == free_run(fast, log)[1]
    assert whole.metrics != part.metrics


def test_the_command_line_names_the_approach_and_keeps_going(tmp_path, capsys):
    """`shipid validate` prints the closed loop's approach against the log's and warns, exit 0."""
    import json

    from cli_helpers import run

    from shipid.data.io import write_log
    from shipid.identification.identify import identify
    from shipid.reporting.modelfile import save_model

    log = turning_log("starboard")
    path = write_log(log, tmp_path / "turn.csv")
    # Runs that speed up at two propeller speeds: the fit finds the surge (the steady turns
    # never excite it).
    runs = [turning_log(side, speed=0.6 * steady(n), rps=n)
            for side, n in (("port", 8.0), ("starboard", 14.0))]  # fmt: skip
    fit = identify(runs, PROPELLED.structure, force=True)
    assert fit.model.coefficients["u"]["pos(n)^2"] == pytest.approx(B_NN, rel=0.05)
    model_path = save_model(tmp_path / "m.json", fit)
    doc = json.loads(model_path.read_text())
    doc["model"]["coefficients"]["u"]["pos(n)^2"] *= 2.25  # 1.5 times the speed at any rps
    model_path.write_text(json.dumps(doc))
    code, out, err = run(["validate", model_path, path], capsys)
    assert code == 0, err
    (row,) = [line for line in out.splitlines() if "approach_speed" in line]
    cells = [c.strip() for c in row.split("|")]
    measured, closed = float(cells[3]), float(cells[5])
    assert closed / measured == pytest.approx(1.5, rel=0.02)
    assert "steady straight speed" in err and "+50 %" in err


def test_the_replicates_approach_each_at_its_own_steady_speed():
    """With a bootstrap ensemble, each replicate's closed-loop turn starts from its own steady
    speed at the log's rps: the interval of ``approach_speed`` is that of n √(−b/a) over the
    replicates' thrust coefficients b."""
    from shipid.identification.uncertainty import Ensemble, interval

    factors = np.linspace(0.8, 1.25, 19)
    terms = PROPELLED.structure.all_terms
    thetas = np.zeros((len(factors), 3, len(terms)))
    for i, f in enumerate(factors):
        for j, dof in enumerate(("u", "v", "r")):
            for k, t in enumerate(terms):
                thetas[i, j, k] = PROPELLED.coefficients[dof].get(t, 0.0)
        thetas[i, 0, terms.index("pos(n)^2")] *= f
    ensemble = Ensemble(PROPELLED, thetas, block_s=10.0, seed=0)
    (v,) = validate(PROPELLED, turning_log("port"), ensemble=ensemble)
    lo, hi = v.intervals["closed_loop"]["approach_speed"]
    expected = interval([RPS * math.sqrt(-f * B_NN / A_UU) for f in factors])
    assert (lo, hi) == pytest.approx(expected, rel=1e-3)


def test_a_zigzag_from_a_steady_approach_runs_from_the_models_own_speed_too():
    """The zig-zag replica starts as `shipid manoeuvre zigzag` does where the log approaches
    steady: the true model reproduces the log's overshoots, a model 50 % fast at the rps starts
    50 % faster."""
    from shipid.dynamics.steering import SteeringMachine
    from shipid.trials.manoeuvres import zigzag

    steering = SteeringMachine(max_rate=math.radians(5.0))  # a rate the 0.1 s log resolves
    res = zigzag(PROPELLED, 20.0, 20.0, duration=120.0, dt=0.1, approach=10.0,
                 speed=steady(RPS), rps=RPS, method="euler", steering=steering)  # fmt: skip
    log = res.log.copy()
    log["n"] = RPS
    (true,) = validate(PROPELLED, log)
    measured, closed = true.indices["measured"], true.indices["closed_loop"]
    assert true.kind == "zigzag"
    assert closed["approach_speed"] == pytest.approx(steady(RPS), rel=1e-6)
    for k in ("first_overshoot_deg", "second_overshoot_deg"):
        assert closed[k] == pytest.approx(measured[k], abs=0.2), k
    (fast,) = validate(with_thrust(2.25), log)
    assert fast.indices["closed_loop"]["approach_speed"] == pytest.approx(1.5 * steady(RPS),
                                                                         rel=1e-3)
    assert any("+50 %" in w for w in fast.warnings)


@pytest.mark.parametrize("name", ["turning δ = −20°", "zigzag 10/10", "zigzag 20/20 (training)"])
def test_the_true_models_replica_of_its_own_trial_reads_every_index_as_measured(name):
    """Bug: the closed loop's indices counted from its rudder order, one sample after the swing
    start that the log's own indices count from (the compiled step that gives the order moves
    the rudder in it): the true model's replica of its own noise-free trial had the advance
    0.39 m (2.5 %) and the initial turning time 0.2 s short at Δt 0.2 s."""
    from shipid.demo import synthesise_trials
    from shipid.vessels import NOISE_FREE, scale_ship_model

    log = synthesise_trials(0, sensor=NOISE_FREE)[name]
    (v,) = validate(scale_ship_model(), log)
    measured, closed = v.indices["measured"], v.indices["closed_loop"]
    shared = [k for k, x in measured.items() if isinstance(x, float) and k in closed]
    assert len(shared) >= 7
    for k in shared:  # the approach: the first sample's speed against the approach's mean
        tolerance = 1e-5 if k == "approach_speed" else 1e-9
        assert closed[k] == pytest.approx(measured[k], rel=tolerance, abs=1e-9), k


YAW = 0.05  # rad/s: the heading turns 0.1° in 0.0349 s


@pytest.mark.parametrize(("sampling", "duration", "yaw", "step"), [
    (0.02, 20.0, YAW, 0.02), (0.1, 20.0, YAW, 0.1 / 3), (0.5, 20.0, YAW, 0.5 / 15),
    (0.5, 20.0, 0.0, 0.5), (0.5, 20_000.0, YAW, 0.5 / 2), (0.5, 60_000.0, YAW, 0.5)])  # fmt: skip
def test_a_measured_log_is_replicated_at_steps_of_a_tenth_of_a_degree(sampling, duration, yaw,
                                                                       step):  # fmt: skip
    """Steps a whole fraction of the sampling in which the log's fastest yaw rate turns the
    heading 0.1° (none where it is finer already, or never turns), at most 100 000 of them
    (the 20 000 s log: half its 0.5 s; the 60 000 s one: its own); a simulated log's own step."""
    from shipid.data.log import make_log
    from shipid.evaluation.validate import replica_step

    t = np.arange(0.0, duration + sampling / 2, sampling)
    r = yaw * np.sin(t / 7.0)
    r[len(r) // 3] = yaw  # its largest
    measured = make_log({"t": t, "delta": 0.0, "u": 1.0, "v": 0.0, "r": r})
    assert replica_step(measured) == pytest.approx(step, rel=1e-12)
    made = make_log({"t": t, "delta": 0.0, "u": 1.0, "v": 0.0, "r": r},
                    integrator={"method": "euler", "step": sampling})  # fmt: skip
    assert replica_step(made) == sampling


@pytest.mark.parametrize("suffix", ["csv", "parquet"])
def test_a_simulated_trial_keeps_its_integrator_through_its_file(tmp_path, suffix):
    """The replica of a simulated trial read back from its file runs at the trial's step (the
    demo's trial files: the true model's replica is the trial); a bad ``integrator`` in a
    file's metadata is named in one line."""
    from shipid.data.io import read_log, write_log
    from shipid.errors import ShipidError
    from shipid.evaluation.validate import replica_step

    log = turning_log("starboard")
    assert log.attrs["integrator"] == {"method": "euler", "step": 0.1}
    again = read_log(write_log(log, tmp_path / f"turn.{suffix}"))
    assert again.attrs["integrator"] == log.attrs["integrator"]
    assert replica_step(again) == 0.1
    bad = tmp_path / "bad.csv"
    bad.write_text('# shipid-log: {"integrator": {"method": "euler", "step": -1}}\n'
                   "t,delta,u,v,r\n0,0,1,0,0\n1,0,1,0,0\n2,0,1,0,0\n")  # fmt: skip
    with pytest.raises(ShipidError, match="bad.csv: metadata integrator must be"):
        read_log(bad)


def test_a_coarsely_sampled_zigzag_is_replicated_as_the_continuous_ship_ran_it():
    """Bug: a replica stepped at the log's sampling reversed its rudder up to a step after its
    heading reached the switch and stepped Euler at that step: the true ship's 20°/20° zig-zag
    run at 0.01 s (RK4), sampled every 0.5 s as a measured log is (no integrator in its
    metadata), came back from its true model with overshoots 2.0° and 8.7° too large (at 0.1 s
    steps still 1.1° and 0.8°). At 0.0072 s, where its fastest yaw rate turns the heading 0.1°,
    within 0.2° (the rest: the switch heading read off 0.5 s samples)."""
    from shipid.trials.manoeuvres import zigzag
    from shipid.vessels import scale_ship

    truth = scale_ship()
    fine = zigzag(truth, 20, 20, duration=80.0, dt=0.01, method="rk4", approach=5.0).log
    log = sampled_as_measured(fine, 50)
    true_indices = zigzag(truth, 20, 20, duration=80.0, dt=0.01, method="rk4",
                          approach=5.0).indices
    (v,) = validate(truth, log, start_draws=False)
    closed = v.indices["closed_loop"]
    coarse = validate_at_the_logs_step(truth, log)
    for k in ("first_overshoot_deg", "second_overshoot_deg"):
        assert closed[k] == pytest.approx(true_indices[k], abs=0.25), k
        assert abs(coarse[k] - true_indices[k]) > 0.8, k


def test_a_measured_turns_replica_is_ordered_halfway_between_its_samples():
    """Bug: the replica of a measured turn ordered its rudder at the first sample the rudder had
    moved at, where the order fell anywhere since the sample before: the scale ship's 20° turn
    (RK4 at 0.01 s) ordered at ten times across one 0.5 s sample, sampled every 0.5 s, came back
    from the true ship 0.45 m longer in advance than measured, on average (U Δt / 2). Ordered
    halfway, within 0.1 m."""
    from shipid.evaluation.validate import _indices_of, trial_replica
    from shipid.trials.indices import manoeuvre_indices
    from shipid.vessels import scale_ship

    ship = scale_ship()
    longer = []
    for order in np.arange(5.0, 5.5, 0.05):
        fine = turning_circle(ship, 20, duration=80.0, dt=0.01, method="rk4",
                              approach=float(order)).log  # fmt: skip
        log = sampled_as_measured(fine, 50)
        trial = describe_trial(log)
        replica = _indices_of(trial_replica(ship, log, "euler", trial, indices=False), trial, log)
        longer.append(replica["advance"] - manoeuvre_indices(log, trial=trial)["advance"])
    assert abs(np.mean(longer)) < 0.1


def validate_at_the_logs_step(model, log) -> dict:
    """The closed-loop replica's indices at the log's own sampling (the code before)."""
    from shipid.evaluation.validate import _indices_of, trial_replica

    trial = describe_trial(log)
    step = float(np.median(np.diff(log["t"].to_numpy())))
    return _indices_of(trial_replica(model, log, "euler", trial, indices=False, step=step), trial,
                       log)


def test_the_closed_loops_spread_with_its_noisy_start_is_what_the_seeds_show(tmp_path, capsys):
    """The replica starts from the log's first measured u, v, r, one noisy sample each: over 60
    seeds of the demo's noisy 10°/10° zig-zag the true model's replica missed the measured
    overshoots by 0.43° and 0.46° (standard deviation; 0.05° from the noise-free start). The
    spread ``validate`` draws from one log says so; from a noise-free log it is nil."""
    import json

    from cli_helpers import run

    from shipid.data.io import write_log
    from shipid.demo import synthesise_trials
    from shipid.vessels import NOISE_FREE, scale_ship_model

    truth = scale_ship_model()
    noisy = [validate(truth, synthesise_trials(seed)["zigzag 10/10"])[0] for seed in range(4)]
    for key in ("first_overshoot_deg", "second_overshoot_deg"):
        mean = np.mean([v.start_spread[key] for v in noisy])
        assert 0.3 <= mean <= 0.6, (key, mean)
    (clean,) = validate(truth, synthesise_trials(0, sensor=NOISE_FREE)["zigzag 10/10"])
    assert max(clean.start_spread.values()) < 0.02
    path = write_log(synthesise_trials(0)["zigzag 10/10"], tmp_path / "zz.csv")
    model = tmp_path / "truth.json"
    model.write_text(json.dumps({"format": "shipid-model", "version": 2, "model": truth.to_dict()}))
    code, text, err = run(["validate", model, path, "--json", tmp_path / "v.json", "--report",
                           tmp_path / "report"], capsys)  # fmt: skip
    assert code == 0, err
    assert "how far its indices move with the noise of its start" in text
    assert "how far its indices move with the noise of its start" in (
        tmp_path / "report" / "report.html").read_text()
    rec = json.loads((tmp_path / "v.json").read_text())["logs"][0]
    assert rec["closed_loop_start_spread"] == pytest.approx(noisy[0].start_spread, rel=1e-9)


def test_the_closed_loops_intervals_hold_the_noise_of_its_start():
    """An ensemble of identical members (the true model, 40 times) once gave the closed loop's
    indices an interval of zero width: every replicate started from the log's one noisy first
    sample. Each now starts from its own draw of that noise, so the interval is what the start
    alone leaves open: about ±2 of ``start_spread``'s standard deviations."""
    from shipid.demo import synthesise_trials
    from shipid.identification.uncertainty import Ensemble
    from shipid.vessels import scale_ship_model

    truth = scale_ship_model()
    thetas = np.repeat(truth.theta[None], 40, axis=0)
    ensemble = Ensemble(truth, thetas, block_s=10.0, seed=0)
    log = synthesise_trials(0)["zigzag 10/10"]
    (v,) = validate(truth, log, ensemble=ensemble)
    lo, hi = v.intervals["closed_loop"]["first_overshoot_deg"]
    width = (hi - lo) / (2 * 1.96 * v.start_spread["first_overshoot_deg"])
    assert 0.5 <= width <= 2.0, width
    # The replay starts from the measured state as the free run does: no start noise there.
    lo, hi = v.intervals["simulated"]["first_overshoot_deg"]
    assert hi - lo < 1e-9


@pytest.mark.parametrize("kind", ["zigzag", "turning"])
def test_a_wind_models_replica_meets_the_logs_wind(kind):
    """Bug: the closed-loop replica of a model with wind terms ran in still air, whatever the log
    met: on the Esso Osaka's +35° turn (a true wind of 1.1 m/s, three times the ship's speed)
    its tactical diameter came 8.47 m instead of 8.02 m. The replica now meets the log's mean
    true wind, read off its relative wind: the true model's replica of its own trial in a
    steady wind reads every index as measured (in still air its first overshoot and its advance
    missed: checked against the code before)."""
    from shipid.data.log import mean_true_wind
    from shipid.dynamics.model import ModelStructure
    from shipid.dynamics.steering import SteeringMachine
    from shipid.trials.manoeuvres import zigzag
    from shipid.vessels import scale_ship_model

    base = scale_ship_model()
    terms = {d: tuple(base.structure.terms[d]) + (("wind_speed^2*sin(wind_angle)",)
                                                  if d != "u" else ("wind_speed^2",))
             for d in "uvr"}  # fmt: skip
    coefs = {d: dict(base.coefficients[d]) for d in "uvr"}
    coefs["u"]["wind_speed^2"] = -2e-3
    coefs["v"]["wind_speed^2*sin(wind_angle)"] = -6e-3
    coefs["r"]["wind_speed^2*sin(wind_angle)"] = 4e-3
    truth = ManoeuvringModel(ModelStructure("windy", terms), coefs)
    wind = (2.5, math.radians(60.0))
    kw = {"duration": 90.0, "dt": 0.2, "method": "euler", "speed": 1.93, "approach": 2.0,
          "wind": wind, "steering": SteeringMachine(max_rate=math.radians(9.6))}  # the demo's
    res = zigzag(truth, 20, 20, **kw) if kind == "zigzag" else turning_circle(truth, 30, **kw)
    log = res.log  # with the relative wind it met (test_a_wind_models_manoeuvre_logs_the_wind_it_met)
    assert mean_true_wind(log) == pytest.approx(wind, abs=1e-9)
    (v,) = validate(truth, log)
    measured, closed = v.indices["measured"], v.indices["closed_loop"]
    shared = [k for k, x in measured.items() if isinstance(x, float) and k in closed
              and k != "approach_speed"]  # fmt: skip
    assert len(shared) >= 5
    for k in shared:
        assert closed[k] == pytest.approx(measured[k], rel=1e-6, abs=1e-6), k


def test_a_wind_models_own_approach_is_steady_in_the_logs_wind():
    """A turn's replica starts from the model's own steady straight speed at the log's rps: for
    a model with wind terms that speed was found in still air and the replica then met the log's
    wind, 32 % slower here than in still air. Found in the log's mean true wind on its heading,
    the true model's own approach is the log's, and every index of its turn reads as measured."""
    from test_equilibrium import _windy_propelled

    from shipid.dynamics.equilibrium import surge_equilibrium

    truth, wind = _windy_propelled(), (2.0, math.radians(20.0))
    speed = surge_equilibrium(truth, 0.45, RPS, wind=wind)
    assert speed < 0.7 * surge_equilibrium(truth, 0.45, RPS)  # a wind from near ahead
    res = turning_circle(truth, 35.0, duration=150.0, dt=0.1, approach=10.0, speed=speed,
                         rps=RPS, method="euler", wind=wind)  # fmt: skip
    log = res.log.assign(n=RPS)
    (v,) = validate(truth, log)
    measured, closed = v.indices["measured"], v.indices["closed_loop"]
    assert closed["approach_speed"] == pytest.approx(speed, rel=1e-4)
    assert measured["approach_speed"] == pytest.approx(speed, rel=1e-4)
    for k in ("advance", "transfer", "tactical_diameter", "steady_yaw_rate"):
        assert closed[k] == pytest.approx(measured[k], rel=1e-3), k


def test_a_wind_models_manoeuvre_logs_the_wind_it_met():
    """A manoeuvre on a model with wind terms logged no wind, so its log could not be replayed,
    validated or fitted by that model. It now logs what an anemometer on the ship reads: the
    Euler replay with that relative wind (held over each step) runs as the closed loop did, to
    rounding (the closed loop turns the true wind into the relative one inside the compiled
    kernel, so this holds ``relative_wind`` to the kernel's convention), and the log's mean
    true wind is the one given."""
    from test_equilibrium import _windy_propelled

    from shipid.data.log import mean_true_wind
    from shipid.dynamics.simulate import simulate_log
    from shipid.trials.manoeuvres import zigzag

    model, wind = _windy_propelled(), (2.0, 0.4)
    log = zigzag(model, 20, 20, duration=60, dt=0.1, speed=0.45, rps=RPS, wind=wind,
                 method="euler").log  # fmt: skip
    assert mean_true_wind(log) == pytest.approx(wind, abs=1e-12)
    replay = simulate_log(model, log, method="euler").log
    for c in ("u", "v", "r", "psi"):
        np.testing.assert_allclose(replay[c], log[c], atol=1e-12, err_msg=c)
    still = zigzag(model, 20, 20, duration=60, dt=0.1, speed=0.45, rps=RPS, method="euler").log
    assert mean_true_wind(still)[0] == pytest.approx(0.0, abs=1e-12)  # still air: no wind


@pytest.mark.parametrize("kind", ["turning", "pull-out"])
@pytest.mark.parametrize("side", ["starboard", "port"])
def test_the_replica_of_a_turn_logged_from_its_order(kind, side):
    """The scale ship's rudder is instantaneous, so its runs are logged from the order, the
    rudder over at the first sample. Bugs: the held angle was read as the largest swing from the
    first sample, none for a turn (validate stopped: "rudder angle must be > 0, got 0.0") and
    the release for a pull-out, whose replica then turned the other way."""
    from shipid.trials.manoeuvres import pull_out
    from shipid.vessels import scale_ship

    ship = scale_ship()
    run = {"dt": 0.1, "method": "euler"}  # validate's closed loop: the same run exactly
    log = (turning_circle(ship, 35, side, duration=60, **run) if kind == "turning"
           else pull_out(ship, 35, side, hold=60, release=30, **run)).log  # fmt: skip
    (v,) = validate(ship.dynamics, log)
    measured, closed = v.indices["measured"], v.indices["closed_loop"]
    assert v.kind == kind
    assert closed["turn_direction"] == measured["turn_direction"] == side
    shared = ("advance", "transfer", "tactical_diameter", "steady_yaw_rate") + \
        (("yaw_rate_at_release", "residual_yaw_rate") if kind == "pull-out" else ())  # fmt: skip
    for k in shared:
        assert closed[k] == pytest.approx(measured[k], rel=1e-6), k


# A ship whose rudder's yaw moment grows with its speed (u·δ): its steady turn's yaw rate is
# the same at any speed, so a surge that keeps too much speed widens its turn by the speed alone.
U_RUDDER = ManoeuvringModel(
    ModelStructure("u-rudder", {"u": ("|u|*u", "pos(n)^2"), "v": ("u*r", "u*v", "u*delta"),
                                "r": ("u*r", "u*v", "u*delta")}),
    {"u": {"|u|*u": A_UU, "pos(n)^2": B_NN},
     "v": {"u*r": -0.3, "u*v": -0.6, "u*delta": 0.015},
     "r": {"u*r": -0.8, "u*v": -0.2, "u*delta": -0.08}})  # fmt: skip
# The truth loses speed in the turn: the centripetal v·r in its surge (a ship's
# (m + m_y)/(m + m_x), about 1.8 for a tanker).
TURN_LOSS = 1.8


def with_coefficients(model: ManoeuvringModel, changes: dict, name: str) -> ManoeuvringModel:
    """``model`` with ``changes`` {dof: {term: value}} made, new terms added to its structure."""
    structure = model.structure.union({d: tuple(c) for d, c in changes.items()}, name=name)
    coefficients = {d: dict(c) for d, c in model.coefficients.items()}
    for d, c in changes.items():
        coefficients[d].update(c)
    return ManoeuvringModel(structure, coefficients)


def lateral_steady_turn(model: ManoeuvringModel, u: float, delta: float) -> tuple[float, float]:
    """(v, r) of the steady turn of ``U_RUDDER``'s lateral form at a held surge speed ``u``: the
    2 × 2 linear balance of its sway and yaw equations, solved in closed form."""
    c = {d: model.coefficients[d] for d in ("v", "r")}
    a = np.array([[c[d]["u*v"] * u, c[d]["u*r"] * u] for d in ("v", "r")])
    b = -np.array([c[d]["u*delta"] * u * delta for d in ("v", "r")])
    return tuple(np.linalg.solve(a, b))


def test_the_turns_speed_is_shown_and_names_the_surge_where_it_carries_the_miss(tmp_path, capsys):
    """`validate` shows the speed in the steady turn, and where the closed loop's turn misses the
    log's by more than 10 % says whether its speed or its yaw rate carries the miss (issue #10:
    from one Esso zig-zag the 35° turns came 1.2–2 times as fast as measured, their yaw rates
    within 10 %, and the table showed the tactical diameter's miss without its cause)."""
    from cli_helpers import run

    from shipid.data.io import write_log

    truth = with_coefficients(U_RUDDER, {"u": {"v*r": TURN_LOSS}}, "u-rudder+vr")
    res = turning_circle(truth, 35.0, "starboard", duration=300.0, dt=0.1, approach=10.0,
                         speed=steady(RPS), rps=RPS, method="rk4")  # fmt: skip
    log = res.log.copy()
    log["n"] = RPS
    # U_RUDDER keeps its straight speed in the turn (its surge has no v, r): its steady turn is
    # the lateral balance at that speed, in closed form.
    v_ss, r_ss = lateral_steady_turn(U_RUDDER, steady(RPS), math.radians(35.0))
    (v,) = validate(U_RUDDER, log)
    measured, closed = v.indices["measured"], v.indices["closed_loop"]
    assert closed["steady_speed"] == pytest.approx(math.hypot(steady(RPS), v_ss), rel=2e-3)
    assert abs(closed["steady_yaw_rate"]) == pytest.approx(abs(r_ss), rel=2e-3)
    assert abs(measured["steady_yaw_rate"]) == pytest.approx(abs(r_ss), rel=0.02)
    assert measured["steady_speed"] < 0.85 * closed["steady_speed"]  # the truth slows in its turn
    (note,) = [w for w in v.warnings if "steady turn is" in w]
    assert "mostly the speed" in note and "surge" in note
    assert f"{closed['steady_speed']:.4g} m/s against {measured['steady_speed']:.4g} m/s" in note
    # The truth on its own log: no note.
    (own,) = validate(truth, log)
    assert not any("steady turn is" in w for w in own.warnings)
    # A rudder a third weaker in yaw, the surge right: the yaw rate carries the miss.
    weak = with_coefficients(truth, {"r": {"u*delta": -0.08 * 2 / 3}}, "weak")
    (v,) = validate(weak, log)
    (note,) = [w for w in v.warnings if "steady turn is" in w]
    assert "mostly the yaw rate" in note
    # The command line shows the speed in the turn in its table and the note on stderr.
    model_path = tmp_path / "m.json"
    U_RUDDER.save(model_path)
    code, out, err = run(["validate", model_path, write_log(log, tmp_path / "turn.csv")], capsys)
    assert code == 0, err
    (row,) = [line for line in out.splitlines() if "| steady_speed " in line]
    cells = [c.strip() for c in row.split("|")]
    assert float(cells[3]) == pytest.approx(measured["steady_speed"], rel=1e-3)
    assert float(cells[5]) == pytest.approx(closed["steady_speed"], rel=1e-3)
    assert "mostly the speed" in " ".join(err.split())
