"""IMO indices on realistic logs against noise-free truths, trial classification, and automatic
trimming (issue #11 items 6–10 and 19)."""

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from shipid.cli import main
from shipid.data.io import read_log, write_log
from shipid.data.log import make_log
from shipid.data.trim import trim
from shipid.errors import ShipidError
from shipid.trials.indices import manoeuvre_indices, turning_indices, zigzag_indices
from shipid.trials.manoeuvres import pull_out, spiral, turning_circle, zigzag
from shipid.trials.trial import describe_trial
from shipid.vessels import PAPER_IMU, scale_ship

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")
OSAKA = DATA / "esso-osaka"
SHIP = scale_ship(rudder_rate_deg=9.6)


def test_steady_turn_ignores_the_pull_out_that_ends_a_measured_turn():
    """Item 6: a 35° turn followed by 100 s of rudder 0 (as a measured turning log ends)."""
    pure = turning_circle(SHIP, 35, duration=200, dt=0.1).indices
    log = pull_out(SHIP, 35, hold=200, release=100, dt=0.1).log
    ind = turning_indices(log, t_order=0.0)
    assert ind["steady_turning_diameter"] == pytest.approx(pure["steady_turning_diameter"], rel=0.01)
    assert ind["steady_yaw_rate"] == pytest.approx(pure["steady_yaw_rate"], rel=0.01)
    # It says which span it used: to where the rudder (9.6 °/s) leaves the held angle.
    assert ind["steady_to"] == pytest.approx(200.0, abs=1.0)
    assert ind["steady_from"] > 20.0
    # The turn and its release: a pull-out, whose turn is read as a turning circle's.
    read = manoeuvre_indices(log)
    assert read["kind"] == "pull-out"
    assert {k: read[k] for k in ind} == ind


@pytest.fixture(scope="module")
def clean_turn():
    return turning_circle(SHIP, 20, duration=240, dt=0.2, method="rk4", approach=2.0).log


@pytest.fixture(scope="module")
def clean_zigzag_10():
    return zigzag(SHIP, 10, 10, duration=90, dt=0.2, method="rk4", approach=2.0).log


def test_noisy_positions_do_not_inflate_the_track_length(clean_zigzag_10):
    """Item 7: 0.5 m position noise made distance_to_second_execute 2.4× too long."""
    truth = zigzag_indices(clean_zigzag_10, t_order=2.0)["distance_to_second_execute"]
    errors = [zigzag_indices(PAPER_IMU.apply(clean_zigzag_10, s), t_order=2.0)
              ["distance_to_second_execute"] - truth for s in range(10)]  # fmt: skip
    assert max(map(abs, errors)) < 0.15  # m, on 7.5 m (measured 0.12 over 20 seeds)


def test_noisy_positions_barely_move_advance_and_tactical_diameter(clean_turn):
    truth = turning_indices(clean_turn, t_order=2.0)
    for seed in range(10):
        noisy = turning_indices(PAPER_IMU.apply(clean_turn, seed), t_order=2.0)
        # Raw positions: errors up to 1.1 m (advance) and 2.4 m (tactical diameter).
        assert noisy["advance"] == pytest.approx(truth["advance"], abs=0.2)
        assert noisy["tactical_diameter"] == pytest.approx(truth["tactical_diameter"], abs=0.2)
        assert noisy["steady_turning_diameter"] == pytest.approx(
            truth["steady_turning_diameter"], abs=0.2)


def test_clean_positions_are_kept(clean_turn):
    from shipid.trials.indices import track

    _, x, y = track(clean_turn)
    np.testing.assert_allclose(x, clean_turn["x"], atol=1e-3)


def test_a_creeping_resampled_rudder_keeps_its_execute(clean_turn):
    """Item 8: a rudder creeping 2e-4° before the order slid the execute to t = 0."""
    crept = clean_turn.copy()
    i0 = int(np.searchsorted(crept["t"], 2.0)) - 1
    crept.loc[: i0, "delta"] = np.linspace(0, np.radians(2e-4), i0 + 1) * np.sign(
        crept["delta"].iloc[-1])
    assert describe_trial(crept).execute_index == describe_trial(clean_turn).execute_index == i0
    a, b = turning_indices(clean_turn), turning_indices(crept)
    assert b["advance"] == pytest.approx(a["advance"], rel=1e-6)


def test_trial_facts_of_a_simulated_zigzag(clean_zigzag_10):
    tr = describe_trial(clean_zigzag_10)
    assert tr.kind == "zigzag" and tr.switch_heading_deg == pytest.approx(10, abs=0.3)
    assert np.degrees(tr.plateau_angle) == pytest.approx(10, abs=1e-6)
    assert np.degrees(tr.rudder_rate) == pytest.approx(9.6, rel=0.01)
    assert tr.execute_time == pytest.approx(1.8)  # the last sample before the rudder moves


def _random_run(seed=0, duration=400.0):
    """Random rudder and propeller orders on the scale ship: neither a zig-zag nor a turn."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, duration, 0.2)
    orders = rng.uniform(-35, 35, size=int(duration // 20) + 1)
    delta = np.radians(orders[(t // 20).astype(int)])
    from shipid.dynamics.simulate import simulate

    log = simulate(SHIP.dynamics, t, delta, {"u": 1.9}).log
    log["n"] = np.where((t // 50) % 2 == 0, 10.0, -6.0)
    return log


def test_random_rudder_runs_are_other_with_a_reason():
    """Item 9: a random run was labelled zig-zag (first overshoot 144°) or turning."""
    ind = manoeuvre_indices(_random_run())
    assert ind["kind"] == "other" and ind["reason"]
    assert set(ind) == {"kind", "reason"}


@needs_data
@pytest.mark.parametrize("name", ["random_03-Aug-2020_11_04_37.csv", "random_31-Jul-2020_12_29_58.csv",
                                  "random_31-Jul-2020_12_48_39.csv", "random_31-Jul-2020_14_52_18.csv"])
def test_esso_random_runs_are_not_zigzags_or_turns(name):
    log = read_log(OSAKA / "random" / name, fmt="osaka-frt")
    assert describe_trial(log).kind == "other"


@needs_data
def test_esso_turns_and_trimmed_zigzags_are_recognised():
    for f in sorted((OSAKA / "turning").glob("*.csv")):
        assert describe_trial(read_log(f, fmt="osaka-frt")).kind == "turning"
    for f in sorted((OSAKA / "zigzag").glob("*.csv")):
        log = read_log(f, fmt="osaka-frt", start="auto", end="auto")
        assert describe_trial(log).kind == "zigzag", f.name


@needs_data
@pytest.mark.parametrize("name", sorted(f.name for f in (OSAKA / "zigzag").glob("*.csv")))
def test_esso_zigzags_read_whole_are_the_trimmed_ones(name):
    """Bug: read whole (no --start auto), four of the nine zig-zags, which start at rest with
    the helm correcting by 13–19° as the ship gathers speed, had that correction taken for the
    execute: two read as no zig-zag, one with reversals at −34° and +19°; and every one's
    overshoots were read from its heading averaged over the whole approach (13_04_24: 6.6° and
    7.0° against 4.8° and 8.9°). The execute is now the held order, where --start auto's
    plateau (``rudder_execute_time``, held 5 s) finds it, and the overshoots those of the cut log."""
    from shipid.data.trim import rudder_execute_time

    whole = read_log(OSAKA / "zigzag" / name, fmt="osaka-frt")
    cut = read_log(OSAKA / "zigzag" / name, fmt="osaka-frt", start="auto")
    tr = describe_trial(whole)
    assert tr.kind == "zigzag"
    # 13_57_45 orders 12° two seconds before its 20° plateau (``earlier_order``).
    assert tr.execute_time == pytest.approx(rudder_execute_time(whole), abs=2.0)
    a, b = zigzag_indices(whole), zigzag_indices(cut)
    for k in ("first_overshoot_deg", "second_overshoot_deg"):
        assert a[k] == pytest.approx(b[k], abs=0.4), k


def test_a_helm_correction_before_the_order_is_not_the_execute():
    """The same zig-zag with and without a helm correction to 14° (70 % of its 20° orders,
    held a second and eased back) 10 s before its execute: the same execute, the same facts."""
    res = zigzag(SHIP, 20, 20, duration=100.0, dt=0.1, method="euler", approach=20.0)
    log = res.log
    helmed = log.copy()
    t = helmed["t"].to_numpy()
    bump = np.interp(t, [8.0, 9.5, 10.5, 14.0], [0.0, -14.0, -14.0, 0.0], left=0.0, right=0.0)
    helmed["delta"] = helmed["delta"] + np.radians(bump)
    plain, tr = describe_trial(log), describe_trial(helmed)
    assert tr.kind == "zigzag" and tr.execute_time == pytest.approx(plain.execute_time)
    assert tr.reversal_headings_deg == pytest.approx(plain.reversal_headings_deg, abs=1e-9)
    assert zigzag_indices(helmed) == pytest.approx(zigzag_indices(log))


def test_forced_kind_and_per_log_errors_in_a_validate_batch(tmp_path, capsys, clean_zigzag_10):
    """Item 9: a run starting astern aborted the whole batch without naming the file."""
    good = write_log(clean_zigzag_10, tmp_path / "good.csv")
    astern = clean_zigzag_10.copy()
    astern["u"] = -astern["u"]
    astern["psi"] = -astern["psi"]
    astern["r"] = -astern["r"]
    bad = write_log(astern, tmp_path / "astern.csv")
    lacking = write_log(clean_zigzag_10.drop(columns=["psi"]).assign(), tmp_path / "nopsi.csv")
    model = tmp_path / "m.json"
    assert main(["identify", str(good), "-o", str(model)]) == 0
    capsys.readouterr()
    code = main(["validate", str(model), str(good), str(bad), str(lacking), "--json",
                 str(tmp_path / "v.json")])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "good.csv" in out and "nopsi.csv" in out
    import json

    logs = json.loads((tmp_path / "v.json").read_text())["logs"]
    assert [v["error"] for v in logs] == [None, None, None]
    code = main(["validate", str(model), str(good), "--kind", "other"])
    out, _ = capsys.readouterr()
    assert code == 0 and "first_overshoot" not in out


def _with_helm_corrections(log, corrections):
    """``log`` with brief helm corrections added to its rudder: (start [s], held [s], angle
    [deg]) each, a 1 s swing there and back."""
    out = log.copy()
    t = out["t"].to_numpy()
    bumps = sum(np.interp(t, [t0, t0 + 1, t0 + 1 + held, t0 + 2 + held], [0, deg, deg, 0],
                          left=0.0, right=0.0) for t0, held, deg in corrections)  # fmt: skip
    out["delta"] = out["delta"] + np.radians(bumps)
    return out


def test_helm_corrections_larger_than_the_orders_are_not_the_execute():
    """A 10°/10° zig-zag after 28 s of straight approach with the helm put over briefly to
    20°, −16° and 13° (as the Esso Osaka's logs that start from rest do, up to 22°): the largest
    deflection was a correction, so half of it was above the orders; the −16° held 2 s was read
    as an earlier order (execute at 14 s), and with the 13° too as no zig-zag ("the rudder
    reversals are not ordered at one switch heading"). The orders are now found against the
    largest *held* deflection, and an earlier order must come at the trial's angle: the facts
    of the log without the corrections, to the sample."""
    import pandas as pd

    z = zigzag(SHIP, 10, 10, duration=100.0, dt=0.1, method="rk4", approach=2.0).log
    lead = z.iloc[[0] * 280].assign(t=np.arange(280) * 0.1)
    lead["x"] = z["x"].iloc[0] + z["u"].iloc[0] * (lead["t"] - 28.0)
    log = pd.concat([lead, z.assign(t=z["t"] + 28.0)], ignore_index=True)
    log.attrs = z.attrs
    plain = describe_trial(log)
    assert plain.kind == "zigzag" and plain.execute_time == pytest.approx(29.9)
    helmed = _with_helm_corrections(log, [(5.0, 1.5, 20.0), (14.0, 2.0, -16.0), (22.0, 1.2, 13.0)])
    tr = describe_trial(helmed)
    assert tr.kind == "zigzag", tr.reason
    assert tr.execute_time == plain.execute_time
    assert tr.reversal_headings_deg == pytest.approx(plain.reversal_headings_deg, abs=1e-9)
    assert zigzag_indices(helmed) == pytest.approx(zigzag_indices(log))
    assert trim(helmed, start="auto")["t"].iloc[0] <= plain.execute_time


def test_a_rest_angle_held_long_is_not_taken_for_a_quick_zigzags_orders():
    """The orders are read against the largest angle held 5 s only where that is a good share
    of the largest deflection: before a quick 20°/5° zig-zag (its rudder held under 5 s at each
    plateau) a −6° helm held through a 30 s approach was the only held angle, its half the
    threshold, and --start auto took the rest itself for the execute (t = 0). As before the
    held angle was used: the zig-zag's execute, and --start auto asks for --start."""
    import pandas as pd

    from shipid.data.trim import rudder_execute_time

    ship = scale_ship(rudder_rate_deg=30)
    z = zigzag(ship, 20, 5, duration=60.0, dt=0.05, method="rk4", approach=2.0).log
    lead = z.iloc[[0] * 600].assign(t=np.arange(600) * 0.05, delta=math.radians(-6.0))
    log = pd.concat([lead, z.assign(t=z["t"] + 30.0)], ignore_index=True)
    log.attrs = z.attrs
    assert describe_trial(log).execute_time == pytest.approx(describe_trial(z).execute_time + 30)
    with pytest.raises(ShipidError, match="no rudder execute found"):
        rudder_execute_time(log)


@needs_data
def test_an_esso_zigzag_at_ten_degrees_after_its_start_from_rest_is_read():
    """The Esso Osaka's 13_50_28 zig-zag (30° at 12 rps) starts from rest, the helm over to
    22° in its first seconds. With its orders after the execute scaled to 10° (a 10°/10°
    zig-zag after the same start), the correction was over twice the orders: --start auto
    found no execute ("no rudder deflection held for 5 s") and the log read as no zig-zag. Now
    the execute is the real one's, and so are its reversals and its cut."""
    from shipid.data.trim import rudder_execute_time

    log = read_log(OSAKA / "zigzag" / "zigzag_31-Jul-2020_13_50_28.csv", fmt="osaka-frt")
    real = describe_trial(log)
    t_exec = rudder_execute_time(log)
    after = log["t"].to_numpy() >= t_exec
    ten = log.copy()
    ten.loc[after, "delta"] *= math.radians(10.0) / real.amplitude
    assert np.degrees(np.max(np.abs(ten["delta"].to_numpy()[~after]))) > 20.0
    assert rudder_execute_time(ten) == pytest.approx(t_exec)
    tr = describe_trial(ten)
    assert tr.kind == "zigzag", tr.reason
    assert tr.execute_time == pytest.approx(real.execute_time)
    assert math.degrees(tr.amplitude) == pytest.approx(10.0, abs=0.3)
    assert tr.reversal_headings_deg == pytest.approx(real.reversal_headings_deg, abs=0.5)
    # --start auto --end auto: the real one's span (the end was read against the correction,
    # so at the execute itself, and the cut refused as "no single zig-zag").
    cut, ten_cut = trim(log, start="auto", end="auto"), trim(ten, start="auto", end="auto")
    assert ten_cut["t"].iloc[[0, -1]].tolist() == cut["t"].iloc[[0, -1]].tolist()


def test_validate_says_why_a_log_has_no_indices_and_kind_judges_it(tmp_path, capsys,
                                                                 clean_zigzag_10):
    """A log read as no zig-zag, turn or pull-out (here a zig-zag whose propeller goes astern
    at its end) got no index rows from validate and no word why (indices said it; the Esso's
    13_22_52 zig-zag with its rudder halved, read at 0.5 s: "rudder swings of 3.93°–7.48° are
    not one zig-zag angle"). Validate now names the log and the reason, in --json too; --kind
    zigzag judges it as one."""
    log = clean_zigzag_10.assign(n=np.where(clean_zigzag_10["t"] > 80.0, -2.0, 10.0))
    path = write_log(log, tmp_path / "uneven.csv")
    good = write_log(clean_zigzag_10, tmp_path / "good.csv")
    out_json = tmp_path / "v.json"
    assert main(["validate", "scale-ship", str(path), str(good), "--json", str(out_json)]) == 0
    out = capsys.readouterr().out
    reason = describe_trial(log).reason
    assert reason == "the propeller is reversed"
    assert f"No manoeuvre indices (read as no zig-zag, turning circle or pull-out; --kind " \
           f"zigzag|turning|pull-out judges a log as one): uneven.csv ({reason})." in out
    assert "good.csv (" not in out  # a zig-zag: its indices, no such note
    import json

    logs = json.loads(out_json.read_text())["logs"]
    assert [(v["manoeuvre"], v["manoeuvre_reason"]) for v in logs] == [
        ("other", reason), ("zigzag", describe_trial(clean_zigzag_10).reason)]
    assert main(["validate", "scale-ship", str(path), "--kind", "zigzag"]) == 0
    out = capsys.readouterr().out
    assert "first_overshoot_deg" in out and "No manoeuvre indices" not in out
    # Read as none because --kind other asked for it: nothing to explain.
    assert main(["validate", "scale-ship", str(good), "--kind", "other"]) == 0
    out = capsys.readouterr().out
    assert "first_overshoot_deg" not in out and "No manoeuvre indices" not in out


def test_a_log_that_cannot_be_validated_is_named_and_the_others_still_run(tmp_path, capsys,
                                                                          clean_zigzag_10):
    good = write_log(clean_zigzag_10, tmp_path / "good.csv")
    broken = tmp_path / "broken.csv"
    broken.write_text("t,delta,u,v,r\n0,0,1,0\n")
    model = tmp_path / "m.json"
    assert main(["identify", str(good), "-o", str(model)]) == 0
    capsys.readouterr()
    code = main(["validate", str(model), str(broken), str(good)])
    out, err = capsys.readouterr()
    assert code == 1
    assert "broken.csv" in err and err.startswith("shipid: error:")
    assert "good.csv" in out  # the good log was validated


def _auto_trim_never_silent(read) -> None:
    """Either refused (no manoeuvre found) or kept with a warning that says how little was kept."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            out = read()
        except ShipidError as exc:
            assert "no single zig-zag or turning circle" in str(exc)
            return
    assert any("kept" in str(w.message) for w in caught), len(out)


def test_auto_trim_of_a_random_run_is_refused_or_reported():
    """Item 10: --start/--end auto on a random run silently kept 1.6 s."""
    log = _random_run(duration=600.0)
    _auto_trim_never_silent(lambda: trim(log, "auto", "auto", "random.csv"))


@needs_data
@pytest.mark.parametrize("name", ["random_03-Aug-2020_11_04_37.csv", "random_31-Jul-2020_12_29_58.csv",
                                  "random_31-Jul-2020_12_48_39.csv", "random_31-Jul-2020_14_52_18.csv"])
def test_auto_trim_of_esso_random_runs_never_passes_silently(name):
    _auto_trim_never_silent(lambda: read_log(OSAKA / "random" / name, fmt="osaka-frt",
                                             start="auto", end="auto"))


def test_zigzag_indices_with_many_reversals_match_a_brute_force_scan():
    """Item 19: the event search is one pass; it must give what a sample-by-sample scan gives."""
    log = zigzag(SHIP, 10, 10, duration=400, dt=0.1).log
    ind = zigzag_indices(log, heading_deg=10.0, t_order=0.0)
    t, psi = log["t"].to_numpy(), log["psi"].to_numpy() - log["psi"].iloc[0]
    k, side, switch = 0, 1.0, math.radians(10.0)
    executes = []
    while True:
        nxt = next((j for j in range(k, len(t)) if side * psi[j] >= switch), None)
        if nxt is None:
            break
        executes.append(nxt)
        k, side = nxt, -side
    first = executes[0]
    frac = (switch - psi[first - 1]) / (psi[first] - psi[first - 1])
    assert ind["initial_turning_time"] == pytest.approx(t[first - 1] + frac * 0.1, abs=1e-9)
    over = math.degrees(np.max(psi[executes[0]:executes[1] + 1])) - 10.0
    assert ind["first_overshoot_deg"] == pytest.approx(over, abs=1e-9)
    assert len(executes) > 20


def test_smoothing_window_is_checked():
    log = zigzag(SHIP, 10, 10, duration=60, dt=0.2).log
    with pytest.raises(ShipidError, match="--smooth"):
        zigzag_indices(log, smooth_s=-5)
    with pytest.raises(ShipidError, match="not shorter than the log"):
        zigzag_indices(log, smooth_s=1e9)
    assert zigzag_indices(log, smooth_s=1.0)["first_overshoot_deg"] == pytest.approx(
        zigzag_indices(log)["first_overshoot_deg"], abs=0.2)


def test_straight_run_is_other():
    t = np.arange(0, 60, 0.2)
    log = make_log({"t": t, "delta": np.zeros(t.size), "u": np.full(t.size, 2.0),
                    "v": np.zeros(t.size), "r": np.zeros(t.size)})  # fmt: skip
    assert manoeuvre_indices(log) == {"kind": "other", "reason": "the rudder never swings"}


def test_validate_says_which_switch_heading_the_overshoots_are_measured_from(tmp_path, capsys):
    """A 20° rudder reversed at 12° of heading: the output names the switch heading the
    overshoots are measured from (a reader comparing with a published table measured from the
    nominal heading needs to know), the one the indices use: 12° and the heading the ship
    turns in the sample the rudder takes to leave its plateau (0.7° here)."""
    log = zigzag(SHIP, 20, 12, duration=90, dt=0.05, method="rk4", approach=2.0).log
    path = write_log(log, tmp_path / "zz.csv")
    model = tmp_path / "m.json"
    assert main(["identify", str(path), "--dt", "0.05", "-o", str(model)]) == 0
    capsys.readouterr()
    assert main(["validate", str(model), str(path), "--dt", "0.05"]) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("Zig-zag overshoots"))
    shown = float(line.split("zz.csv ")[1].rstrip("°."))
    assert shown == pytest.approx(describe_trial(read_log(path), "zigzag").switch_heading_deg,
                                  abs=0.01)  # fmt: skip
    assert 12.0 <= shown <= 12.0 + 1.0


INSTANT = scale_ship()  # no rudder rate: the log's first sample already has the rudder over


@pytest.mark.parametrize("angle", [10, 20])
@pytest.mark.parametrize("first", ["starboard", "port"])
def test_a_zigzag_logged_from_its_order_is_read_as_the_manoeuvre_measured_it(angle, first):
    """The scale ship's instantaneous rudder is over from the first sample of `shipid manoeuvre
    zigzag -o`'s log: read back, the first reversal was taken for the execute (20/20: reversals
    at −27.9° and +12.5°, first overshoot 8.7° against 3.7°)."""
    res = zigzag(INSTANT, angle, angle, first=first, duration=90, dt=0.05)
    tr = describe_trial(res.log)
    assert tr.kind == "zigzag" and tr.execute_index == 0
    assert np.allclose(np.abs(tr.reversal_headings_deg), angle, atol=0.5)
    read = zigzag_indices(res.log)
    for key in ("first_overshoot_deg", "second_overshoot_deg"):
        assert read[key] == pytest.approx(res.indices[key], abs=0.1)
    assert read["initial_turning_time"] == pytest.approx(res.indices["initial_turning_time"],
                                                         abs=0.06)  # fmt: skip


def test_a_pull_out_logged_from_its_order_reads_its_turn_before_the_release():
    """Its release was taken for the execute: a 'turn' of advance 0 after it."""
    log = pull_out(INSTANT, 35, hold=60, release=60, dt=0.1).log
    turn = turning_circle(INSTANT, 35, duration=60, dt=0.1).indices
    read = manoeuvre_indices(log)
    assert read["kind"] == "pull-out"
    for key in ("advance", "transfer", "tactical_diameter"):
        assert read[key] == pytest.approx(turn[key], rel=0.01)


@pytest.mark.parametrize("ship", [INSTANT, SHIP], ids=["instant rudder", "9.6 °/s"])
@pytest.mark.parametrize("side", ["starboard", "port"])
def test_a_pull_out_log_reads_its_release_as_the_manoeuvre_gave_it(ship, side):
    """Bug: a pull-out's log was read as a turning circle, without its yaw rates at the release
    and at the end (what the test is for: a straight-line stable ship's residual goes to 0)."""
    res = pull_out(ship, 20, side, hold=60, release=40, dt=0.1)
    read = manoeuvre_indices(res.log)
    assert read["kind"] == "pull-out" and read["release_time"] == pytest.approx(60.0)
    for key in ("yaw_rate_at_release", "residual_yaw_rate", "residual_fraction"):
        assert read[key] == pytest.approx(res.indices[key], rel=1e-9), key
    # The residual against an independent reading: the stable ship's decay, e^(λ t) from the
    # release, its slowest sway–yaw eigenvalue λ < 0 (a mean over the last 2 s of 40).
    assert abs(read["residual_yaw_rate"]) < 0.05 * abs(read["yaw_rate_at_release"])
    assert np.sign(read["yaw_rate_at_release"]) == np.sign(read["steady_yaw_rate"])


def test_a_noisy_pull_out_is_read_as_one():
    res = pull_out(SHIP, 20, hold=60, release=40, dt=0.1)
    for seed in range(3):
        read = manoeuvre_indices(PAPER_IMU.apply(res.log, seed))
        assert read["kind"] == "pull-out", read.get("reason")
        assert read["yaw_rate_at_release"] == pytest.approx(res.indices["yaw_rate_at_release"],
                                                            abs=0.01)  # fmt: skip
        assert read["residual_yaw_rate"] == pytest.approx(res.indices["residual_yaw_rate"],
                                                          abs=0.005)  # fmt: skip


def test_a_turn_released_briefly_at_its_end_stays_a_turn():
    log = pull_out(SHIP, 35, hold=200, release=20, dt=0.1).log
    assert manoeuvre_indices(log)["kind"] == "turning"


def test_a_straight_approach_with_the_helm_held_over_is_not_the_order(clean_turn):
    """The Esso Osaka's rudder rests near −6° on a straight course: a held helm before the
    execute, under which the ship barely turns, is the approach."""
    log = clean_turn.copy()
    i0 = describe_trial(log).execute_index
    log.loc[: i0, "delta"] = math.radians(-6.0)
    assert describe_trial(log).execute_index > 0


def test_indices_print_an_epoch_execute_time_in_full(tmp_path, capsys, clean_zigzag_10):
    log = clean_zigzag_10.copy()
    log["t"] += 1_700_000_000.0
    path = tmp_path / "epoch.csv"
    write_log(log, path)
    assert main(["indices", str(path)]) == 0
    assert "first_execute_time: 1700000001.8" in capsys.readouterr().out  # was 1.7e+09


def test_a_kind_given_against_the_log_is_named(tmp_path, capsys, clean_zigzag_10):
    """`indices --kind turning` of a zig-zag printed every turning index None without a word;
    a kind the log reads as is said nothing of."""
    path = tmp_path / "zz.csv"
    write_log(clean_zigzag_10, path)
    assert main(["indices", str(path), "--kind", "turning"]) == 0
    assert "--kind turning, but the log reads as zigzag" in capsys.readouterr().err
    assert main(["indices", str(path), "--kind", "zigzag"]) == 0
    assert "reads as" not in capsys.readouterr().err


def test_a_spiral_is_no_turning_circle():
    """Bug: a spiral's log (here the scale ship's, 30 s a step) was read as a turning circle of
    advance, transfer and tactical diameter 0, from an execute found 600 s in, after the ship
    had turned 3300°."""
    log = spiral(INSTANT, (-25, -10, -2, 0, 2, 10, 25), hold=30, dt=0.1).log
    trial = describe_trial(log)
    assert trial.kind == "other" and "before the first rudder order" in trial.reason
    assert manoeuvre_indices(log) == {"kind": "other", "reason": trial.reason}
    # A turn's straight approach, however long, is none of that.
    turn = turning_circle(SHIP, 35, duration=80, dt=0.1, approach=60).log
    assert describe_trial(turn).kind == "turning"


def test_the_command_line_knows_every_kind(tmp_path, capsys):
    from shipid.cli.parser import KINDS as CLI_KINDS
    from shipid.trials.trial import KINDS

    assert CLI_KINDS == KINDS
    path = tmp_path / "pull-out.csv"
    write_log(pull_out(SHIP, 20, hold=60, release=40, dt=0.1).log, path)
    assert main(["indices", str(path), "--kind", "pull-out"]) == 0
    out = capsys.readouterr().out
    assert "pull-out" in out and "residual_yaw_rate" in out


def test_an_unstable_ships_spiral_loop_need_not_turn_both_ways():
    """Bug: the spiral's loop asked for steady turns both ways at one rudder angle. The KVLCC2's
    MMG model is straight-line unstable (its linearisation: a sway–yaw root in the right half
    plane), and its loop is offset to port: held at 0°, it comes to rest at 0 rad/s from
    starboard and at −0.0205 rad/s from port, and the spiral read ``loop: False``. The same
    rudder reached from the two sides with different steady rates is the loop."""
    from shipid.control.linear import linearise
    from shipid.trials.manoeuvres import _loop_rudders
    from shipid.vessels import kvlcc2

    ship = kvlcc2()
    a = np.asarray(linearise(ship.dynamics, ship.approach_speed)["A"], dtype=float)[1:, 1:]
    assert np.linalg.eigvals(a).real.max() > 0  # the truth: unstable
    res = spiral(ship, (2, 0, -2, 0, 2), hold=1000.0, dt=0.1)
    ind = res.indices
    assert not ind["unsettled_rudders_deg"]
    rates = [row["steady_yaw_rate"] for row in ind["table"]]
    assert abs(rates[1]) < 1e-3 and rates[3] == pytest.approx(-0.0205, rel=0.05)
    assert ind["loop"] and ind["loop_rudders_deg"] == [0.0]
    assert ind["loop_yaw_rate_gap"] == pytest.approx(rates[1] - rates[3], rel=1e-12)
    # A stable ship (the paper's) reaches one steady rate from either side: no loop.
    stable = spiral(SHIP, (2, 0, -2, 0, 2), hold=200.0, dt=0.1).indices
    assert not stable["loop"] and stable["loop_yaw_rate_gap"] == 0.0
    # Unsettled rows are no evidence of a loop; rates within 5 % of the largest are one rate.
    rows = [{"rudder_deg": a, "steady_yaw_rate": r, "settled": s}
            for a, r, s in ((0.0, 0.0, True), (0.0, -0.02, False), (25.0, 0.05, True),
                            (25.0, 0.049, True))]  # fmt: skip
    assert _loop_rudders(rows) == ([], 0.0)
    rows[1]["settled"] = True
    assert _loop_rudders(rows) == ([0.0], pytest.approx(0.02))


@pytest.mark.parametrize("tau, settled", [(20.0, True), (2000.0, False), (-1.0, True)])
def test_a_slow_approach_is_not_settled(tau, settled):
    """Bug: a yaw rate counted as settled when its last fifth moved less than 1 %, which a slow
    mode passes far from its end (a full-scale KVLCC2 model's spiral read 15° 18 % short). A
    closed form: r = 1 − 0.2 exp(−t/τ) over 120 s; with τ = 2000 s the last 24 s move 0.28 % of
    the rate, while the rate is 19 % short of its limit. τ < 0: a constant rate."""
    from shipid.trials.manoeuvres import _settled

    t = np.arange(0.0, 120.0, 0.05)
    r = np.ones_like(t) if tau < 0 else 1.0 - 0.2 * np.exp(-t / tau)
    tail = r[int(0.8 * len(r)):]
    assert np.ptp(tail) < 0.01  # what the earlier rule looked at alone
    assert _settled(r, 1.0) is settled
    assert _settled(-r, 1.0) is settled


@pytest.mark.parametrize("n", [1, 2, 7, 100, 1001])
@pytest.mark.parametrize("window", [1, 2, 5, 51, 2000])
def test_the_trims_forward_extremes_are_scipys_filters(n, window):
    """The rudder's spread over the window from each sample on (``trim.forward_extremes``, which
    spares every trimming command ``scipy.ndimage``'s import) against SciPy's own filters."""
    from scipy.ndimage import maximum_filter1d, minimum_filter1d

    from shipid.data.trim import forward_extremes

    x = np.random.default_rng(n * window).normal(size=n)
    x[n // 2 :] = np.round(x[n // 2 :])  # ties, as a rudder's plateaus have
    hi, lo = forward_extremes(x, window)
    origin = -(window // 2)
    assert np.array_equal(hi, maximum_filter1d(x, window, origin=origin, mode="nearest"))
    assert np.array_equal(lo, minimum_filter1d(x, window, origin=origin, mode="nearest"))


def test_a_zigzags_indices_do_not_import_numba(tmp_path):
    """``shipid indices`` of a zig-zag needs no track, yet paid numba's import (0.25 s of its
    0.52 s of imports) for the track smoother; compiled on first use now, as a turn's indices
    need it (and the same as the whole loop run in Python)."""
    from cli_helpers import fresh_python

    from shipid.trials import indices
    from shipid.trials.manoeuvres import turning_circle, zigzag
    from shipid.vessels import PAPER_IMU, scale_ship

    ship = scale_ship(rudder_rate_deg=9.6)
    path = write_log(zigzag(ship, 10, 10, duration=60, dt=0.2).log, tmp_path / "zz.csv")
    code = ("import sys, contextlib, io; from shipid.cli import main; "
            "out = io.StringIO(); cm = contextlib.redirect_stdout(out); cm.__enter__(); "
            f"rc = main(['indices', {str(path)!r}]); cm.__exit__(None, None, None); "
            "print(rc, 'numba' in sys.modules)")  # fmt: skip
    assert fresh_python(code).split() == ["0", "False"]
    turn = PAPER_IMU.apply(turning_circle(ship, 20, duration=60, dt=0.2).log, seed=0)
    args = (np.ascontiguousarray(np.c_[turn["x"], turn["y"]]),
            np.ascontiguousarray(np.c_[turn["u"], turn["v"]] * 0.2), 0.25, 1e-4)  # fmt: skip
    np.testing.assert_allclose(indices._rts_smooth(*args), indices._rts_smooth_loop(*args),
                               rtol=1e-12, atol=1e-12)  # fmt: skip
