"""The checks of a model already checked are not run again: a search checks the same models more
than once (the structure comparison's search, then the prefilter's; ``selection_shares``), and the
held turns are most of the checks' time. What is handed back must be what a fresh check gives,
for the same model only, and not shared with the caller before. A held turn that has not
settled is made longer by going on from its last state, not by running again from the start:
the same states to the bit, each second simulated once."""

import numpy as np
import pytest

import shipid.identification.plausibility as plausibility
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.identification.plausibility import check_plausibility
from shipid.vessels import scale_ship_model


@pytest.fixture
def turns(monkeypatch):
    """The held turns run, counted, with an empty memo."""
    monkeypatch.setattr(plausibility, "_CHECKED", type(plausibility._CHECKED)())
    calls = []
    original = plausibility.turning_circle

    def counted(*args, **kwargs):
        calls.append(kwargs.get("side"))
        return original(*args, **kwargs)

    monkeypatch.setattr(plausibility, "turning_circle", counted)
    batch = plausibility.held_turns  # both sides' first runs, together

    def counted_batch(ship, rudder_deg, sides, *args, **kwargs):
        calls.extend(sides)
        return batch(ship, rudder_deg, sides, *args, **kwargs)

    monkeypatch.setattr(plausibility, "held_turns", counted_batch)
    return calls


def _model(rudder_factor: float = 1.0) -> ManoeuvringModel:
    truth = scale_ship_model()
    coefficients = {d: dict(c) for d, c in truth.coefficients.items()}
    for dof in ("v", "r"):
        coefficients[dof]["delta"] *= rudder_factor
    return ManoeuvringModel(truth.structure, coefficients)


def test_the_same_model_checked_again_runs_no_turn_and_gets_a_fresh_checks_result(turns):
    report, notes = check_plausibility(_model(), 1.6)
    ran = len(turns)
    assert ran >= 2  # both sides held (and entered drifting where they settle)
    again, again_notes = check_plausibility(_model(), 1.6)  # an equal model, another object
    assert len(turns) == ran
    assert again == report and again_notes == notes
    plausibility._CHECKED.clear()
    fresh, fresh_notes = check_plausibility(_model(), 1.6)
    assert len(turns) == 2 * ran
    assert fresh == again and fresh_notes == again_notes


def test_what_the_caller_changes_in_a_report_does_not_reach_the_next(turns):
    report, notes = check_plausibility(_model(), 1.6)
    steady = report["held_rudder"]["port"]["steady_speed"]
    report["held_rudder"]["port"]["steady_speed"] = -1.0
    report["approach"] = "changed by a caller"
    notes.append("added by a caller")
    again, again_notes = check_plausibility(_model(), 1.6)
    assert again["held_rudder"]["port"]["steady_speed"] == steady
    assert "approach" not in again and "added by a caller" not in again_notes


@pytest.mark.parametrize("change", ["coefficient", "speed", "rudder", "structure"])
def test_another_model_or_approach_is_checked_anew(turns, change):
    check_plausibility(_model(), 1.6)
    ran = len(turns)
    model, kwargs = _model(), {"speed": 1.6}
    if change == "coefficient":
        model = _model(rudder_factor=0.5)
    elif change == "speed":
        kwargs["speed"] = 1.2
    elif change == "rudder":
        kwargs["rudder_deg"] = 25.0
    else:  # the same coefficients, the surge left out of the structure
        truth = scale_ship_model()
        sway_yaw = ModelStructure("sway and yaw", {d: t for d, t in truth.structure.terms.items()
                                                   if d != "u"})  # fmt: skip
        model = ManoeuvringModel(sway_yaw, {d: c for d, c in truth.coefficients.items()
                                            if d != "u"})  # fmt: skip
    report, _ = check_plausibility(model, **kwargs)
    assert len(turns) > ran
    if change == "coefficient":  # half the rudder: a wider turn, as the fresh check has it
        first = plausibility._CHECKED[next(iter(plausibility._CHECKED))][0]
        assert (abs(report["held_rudder"]["starboard"]["steady_yaw_rate"])
                < abs(first["held_rudder"]["starboard"]["steady_yaw_rate"]))  # fmt: skip


def test_a_model_whose_coefficients_differ_in_the_last_bit_is_another():
    model = _model()
    other = _model()
    other.theta = np.nextafter(other.theta, np.inf)
    assert plausibility._checked_key(model, 1.6) != plausibility._checked_key(other, 1.6)
    assert plausibility._checked_key(model, 1.6) == plausibility._checked_key(_model(), 1.6)


# --- a held turn that has not settled goes on from where it stopped --------------------------


def _slowly_unstable() -> ManoeuvringModel:
    """A yaw that grows as e^{0.004 t} under the held rudder: unsettled at 300 s, past the
    divergence bound of 5 rad/s at 505 s."""
    structure = ModelStructure("slowly unstable", {"v": ("v", "r", "delta"),
                                                   "r": ("v", "r", "delta")})  # fmt: skip
    return ManoeuvringModel(structure, {"v": {"v": -0.5, "r": 0.0, "delta": 0.0},
                                        "r": {"v": 0.0, "r": 0.004, "delta": -0.005}})  # fmt: skip


@pytest.mark.parametrize("case", ["tanker", "odd step", "diverges later"])
def test_a_longer_held_turn_goes_on_from_the_last_and_equals_the_run_from_the_start(case):
    from shipid.vessels import tanker

    if case == "tanker":  # a full-scale VLCC: unsettled at 300 and 600 s, settled at 1200 s
        ship = tanker()
        model, speed, rudder, dt = ship, ship.approach_speed, 10.0, 0.1
    elif case == "odd step":  # a step that divides none of the lengths
        model, speed, rudder, dt = scale_ship_model(), 1.6, 35.0, 0.18471546577
    else:
        model, speed, rudder, dt = _slowly_unstable(), 1.0, 35.0, 0.2
    run = plausibility._held_runs(model, speed, None, rudder, "starboard", dt)
    for length in (300.0, 600.0, 1200.0, 2400.0):
        from_the_start = plausibility._held_runs(model, speed, None, rudder, "starboard", dt)
        assert run(length) == from_the_start(length)
    if case == "tanker":
        assert not run(300.0)["settled"] and run(1200.0)["settled"]
    if case == "diverges later":
        first, later = run(300.0), run(600.0)
        assert not first["diverged"] and not first["settled"]
        assert later["diverged"] and "t = 505.40 s" in later["reason"]


def test_the_held_turns_simulate_each_second_once(monkeypatch):
    from shipid.vessels import tanker

    ship = tanker()
    simulated = []
    original = plausibility.turning_circle

    def counted(*args, **kwargs):
        simulated.append(kwargs["duration"])
        return original(*args, **kwargs)

    monkeypatch.setattr(plausibility, "turning_circle", counted)
    batch = plausibility.held_turns

    def counted_batch(ship, rudder_deg, sides, duration, *args, **kwargs):
        simulated.extend([duration] * len(sides))
        return batch(ship, rudder_deg, sides, duration, *args, **kwargs)

    monkeypatch.setattr(plausibility, "held_turns", counted_batch)
    out = plausibility.held_rudder(ship, ship.approach_speed, rudder_deg=10.0, drifting=False)
    for side in ("starboard", "port"):
        assert out[side]["settled"] and out[side]["duration"] == 1200.0
    assert sum(simulated) == pytest.approx(2 * 1200.0)  # 300 + 300 + 600 a side, not 2100


def test_threads_checking_side_by_side_get_each_its_own_models_report(turns):
    from concurrent.futures import ThreadPoolExecutor

    factors = [0.5, 0.75, 1.0, 1.25] * 4
    with ThreadPoolExecutor(4) as pool:
        reports = list(pool.map(lambda f: check_plausibility(_model(f), 1.6)[0], factors))
    plausibility._CHECKED.clear()
    alone = {f: check_plausibility(_model(f), 1.6)[0] for f in set(factors)}
    assert all(r == alone[f] for r, f in zip(reports, factors, strict=True))


@pytest.mark.parametrize("case", ["terms", "reference ship", "one side diverges"])
def test_both_sides_run_together_are_each_side_run_alone(case):
    """``held_turns`` runs the two sides' first held turns in one batch (side by side on numba's
    threads): each the states, the log and the divergence report of its own turning circle."""
    import pandas as pd

    from shipid.trials.manoeuvres import as_vessel, held_turns, turning_circle
    from shipid.vessels import tanker

    if case == "terms":
        ship, rudder, duration, dt = as_vessel(scale_ship_model(), 1.6), 35.0, 300.0, 0.1
    elif case == "reference ship":
        ship, rudder, duration, dt = tanker(), 10.0, 600.0, 0.5
    else:  # a yaw that grows to the divergence bound to one side, within it to the other
        lopsided = ModelStructure("lopsided", {"v": ("v", "r", "delta"),
                                               "r": ("v", "r", "delta", "1")})  # fmt: skip
        model = ManoeuvringModel(lopsided, {"v": {"v": -0.5, "r": 0.0, "delta": 0.0},
                                            "r": {"v": 0.0, "r": 0.004, "delta": -0.005,
                                                  "1": 0.002}})  # fmt: skip
        ship, rudder, duration, dt = as_vessel(model, 1.0), 35.0, 600.0, 0.2
    together = held_turns(ship, rudder, ("starboard", "port"), duration, dt)
    # And entered drifting, each side from its own start (the runaway check's inward drift).
    drift = [{"v": 0.1 * ship.approach_speed}, {"v": -0.1 * ship.approach_speed}]
    drifting = held_turns(ship, rudder, ("starboard", "port"), duration, dt, initial=drift)
    for k, side in enumerate(("starboard", "port")):
        for res, initial in ((together[k], None), (drifting[k], drift[k])):
            alone = turning_circle(ship, rudder, side=side, duration=duration, dt=dt,
                                   indices=False, initial=initial)  # fmt: skip
            pd.testing.assert_frame_equal(res.log, alone.log, check_exact=True)
            assert res.log.attrs == alone.log.attrs
            assert (res.diverged, res.reason, res.diverged_at) == \
                (alone.diverged, alone.reason, alone.diverged_at)  # fmt: skip
    assert not drifting[0].log.equals(together[0].log)  # the start is each side's own
    if case == "one side diverges":
        assert [r.diverged for r in together] == [True, False]
