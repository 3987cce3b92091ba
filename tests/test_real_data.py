"""Readers of the real trial formats and identification on real ships (../shared/data)."""

import math
from pathlib import Path

import numpy as np
import pytest

from shipid.cli import main
from shipid.data.io import read_log
from shipid.errors import ShipidError
from shipid.evaluation.validate import validate
from shipid.identification.identify import identify
from shipid.trials.indices import zigzag_indices
from shipid.trials.manoeuvres import turning_circle

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
MARIN = DATA / "kvlcc2-marin"
OSAKA = DATA / "esso-osaka"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")
LAMBDA = 45.7


@needs_data
def test_marin_reader_rebuilds_time_rotates_velocities_and_froude_scales():
    full = read_log(MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat", fmt="simman-marin")
    model = read_log(MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat", fmt="simman-marin", scale=LAMBDA)
    assert len(full) == 4481 and full.attrs["rudder_positive"] == "port"
    dt = np.diff(full["t"])
    assert np.allclose(dt, dt[0]) and dt[0] == pytest.approx(0.1353, abs=0.001)
    assert np.diff(model["t"])[0] == pytest.approx(0.02, abs=0.0005)
    # Straight approach at 15.5 kn: body surge ≈ speed, sway ≈ 0, whatever the heading.
    assert full["u"].iloc[0] == pytest.approx(8.11, abs=0.01)
    assert abs(full["v"].iloc[0]) < 0.05
    assert model["u"].iloc[0] == pytest.approx(8.11 / math.sqrt(LAMBDA), rel=1e-3)
    assert model["r"].abs().max() == pytest.approx(full["r"].abs().max() * math.sqrt(LAMBDA))
    # Overshoots of the data README (15.1°, 13.3°) take ψ0 = 0; ours take the mean approach
    # heading (manoeuvring-standards.md §7.1): adding it back gives the README's figures.
    ind = zigzag_indices(full, heading_deg=20)
    psi0 = math.degrees(float(np.mean(np.unwrap(full["psi"])[: int(ind["first_execute_time"] /
                                                                  dt[0]) + 1])))  # fmt: skip
    assert ind["first_overshoot_deg"] - psi0 == pytest.approx(15.1, abs=0.15)
    assert ind["second_overshoot_deg"] + psi0 == pytest.approx(13.3, abs=0.15)
    assert zigzag_indices(full)["switch_heading_deg"] == pytest.approx(20, abs=1.0)


@needs_data
def test_osaka_reader_unwraps_heading_and_drops_empty_rows():
    log = read_log(OSAKA / "zigzag" / "zigzag_31-Jul-2020_13_50_28.csv", fmt="osaka-frt")
    assert log.attrs["rudder_positive"] == "starboard"
    assert not log.isna().any().any()
    assert np.max(np.abs(np.diff(log["psi"]))) < 1.0


@needs_data
def test_osaka_logs_carry_the_models_particulars(tmp_path, capsys):
    """The Esso Osaka 3 m model's particulars come with its files (the files do not carry them;
    a model of them had no length for the criteria, the prime form or --crossflow); consistent:
    its mass is ρ·Cb·L·B·T within 0.1 % in the pond's fresh water."""
    from shipid.data.particulars import Particulars

    path = OSAKA / "zigzag" / "zigzag_31-Jul-2020_13_22_52.csv"
    p = Particulars.from_mapping(read_log(path, fmt="osaka-frt").attrs["particulars"])
    assert (p.length, p.beam, p.draught, p.rho) == (3.0, 0.489, 0.201, 1000.0)
    assert p.mass == pytest.approx(p.rho * p.block_coefficient * 3.0 * 0.489 * 0.201, rel=1e-3)
    out = tmp_path / "m.json"
    code = main(["identify", "--format", "osaka-frt", str(path), "--crossflow", "--model",
                 "blanke-speed+wind", "--filter", "none", "-o", str(out)])  # fmt: skip
    assert code == 0
    assert "crossflow_sway(3)" in out.read_text() and "Y_cf(v, r; 3 m)" in capsys.readouterr().out
    assert main(["criteria", str(out), "--no-bands"]) == 0  # in lengths of its own 3 m
    assert "L = 3 m" in capsys.readouterr().out


def test_truncated_and_wrong_format_files(tmp_path):
    dat = tmp_path / "cut.dat"
    dat.write_text("MARIN\nzig-zag\n\n" + "\t".join(["1.00E+00"] * 11) + "\n" + "1.0E+00\t2.0\n")
    with pytest.raises(ShipidError, match="line 5 has 2 values"):
        read_log(dat, fmt="simman-marin")
    csv = tmp_path / "not-osaka.csv"
    csv.write_text("t,delta,u,v,r\n0,0,1,0,0\n")
    with pytest.raises(ShipidError, match="missing column.*osaka-frt"):
        read_log(csv, fmt="osaka-frt")
    code = main(["import", str(csv), "--format", "simman-marin", "-o", str(tmp_path / "o.csv")])
    assert code == 1 and not (tmp_path / "o.csv").exists()


@needs_data
@pytest.mark.parametrize(("path", "fmt", "scale"), [
    (MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat", "simman-marin", None),
    (MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat", "simman-marin", LAMBDA),
    (DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat", "simman-hsva", None),
    (OSAKA / "turning" / "turn_14-Sep-2020_13_39_32.csv", "osaka-frt", None)])
def test_a_known_format_is_read_without_format_and_says_so(path, fmt, scale):
    """Before, `shipid identify MARIN_FREE_KVLCC2_zz_20_m.dat` stopped with "read it with
    --format simman-marin"; it is read as that, with a line saying so."""
    import pandas as pd

    from shipid.errors import ShipidWarning

    given = read_log(path, fmt=fmt, scale=scale)
    with pytest.warns(ShipidWarning, match=f"not a canonical log; read as {fmt}"):
        found = read_log(path, scale=scale)
    pd.testing.assert_frame_equal(found, given)
    assert found.attrs == given.attrs


def test_a_file_in_a_formats_layout_but_not_its_own_is_not_read_as_it(tmp_path):
    """Only MARIN's files start with its name: a tab-separated log of eleven numeric columns
    has their layout, and reading it as one would give another ship's columns silently."""
    rows = ["\t".join(f"{i + k}.0" for k in range(11)) for i in range(5)]
    for first, read in (("time\tdelta", False), ("MARIN (Maritime Research Institute)", True)):
        path = tmp_path / "eleven.dat"
        path.write_text(f"{first}\nzig-zag\n\n" + "\n".join(rows) + "\n")
        if read:
            with pytest.warns(Warning, match="read as simman-marin"):
                log = read_log(path)
            assert list(log["t"]) == [0.0, 1.0, 2.0, 3.0, 4.0] and len(log) == 5
        else:  # nor named as one: the canonical reader's own refusal
            with pytest.raises(ShipidError, match="not a valid CSV file") as err:
                read_log(path)
            assert "simman" not in str(err.value)
    # --columns says the file is meant as a canonical log: no format is guessed.
    marin = tmp_path / "marin.dat"
    marin.write_text("MARIN\nzig-zag\n\n" + "\n".join(rows) + "\n")
    with pytest.raises(ShipidError, match="layout is that of simman-marin"):
        read_log(marin, columns={"time": "t"})


def _numbers(line: str) -> bool:
    try:
        [float(x) for x in line.split()]
    except ValueError:
        return False
    return True


@needs_data
@pytest.mark.parametrize("fmt, path, scale", [
    ("simman-marin", MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat", LAMBDA),
    ("simman-hsva", DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat", None),
])  # fmt: skip
def test_a_simman_file_titled_in_more_or_fewer_lines_reads_the_same(tmp_path, fmt, path, scale):
    """The readers took the shared files' header lengths as the format's (MARIN two lines,
    HSVA four): another run's file titled in one line more was refused at its first line of
    data-to-be ("line 3 is not numeric"), one line fewer lost its first row of data. The header
    is now whatever precedes the first row of the format's numbers, and detection reads it so."""
    import pandas as pd

    from shipid.errors import ShipidWarning

    lines = path.read_bytes().decode("latin-1").splitlines(keepends=True)
    given = read_log(path, fmt=fmt, scale=scale)
    first = next(k for k, ln in enumerate(lines) if len(ln.split()) >= 11 and _numbers(ln))
    for header in ([*lines[:first], "run of 2008, second title line\n"], lines[:1]):
        variant = tmp_path / path.name
        variant.write_bytes("".join([*header, *lines[first:]]).encode("latin-1"))
        pd.testing.assert_frame_equal(read_log(variant, fmt=fmt, scale=scale), given,
                                      check_exact=True)  # fmt: skip
        with pytest.warns(ShipidWarning, match=f"read as {fmt}"):
            found = read_log(variant, scale=scale)
        pd.testing.assert_frame_equal(found, given, check_exact=True)


@needs_data
@pytest.mark.parametrize("structure, r_std", [("blanke", 0.0065), ("blanke-speed", 0.004),
                                              ("blanke-race", 0.0022)])
def test_kvlcc2_identified_on_zz20_predicts_zz_minus20_and_turns_plausibly(structure, r_std):
    kw = {"fmt": "simman-marin", "scale": LAMBDA, "dt": 0.2}
    train = read_log(MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat", **kw)
    test = read_log(MARIN / "MARIN_FREE_KVLCC2_zz_-20_m.dat", **kw)
    fit = identify(train, model=structure, gamma=1e4)
    v = validate(fit.model, test)[0]
    assert not v.simulation.diverged
    assert v.metrics["r"]["std"] < r_std  # rad/s; measured 0.0058 (blanke), 0.0033 (u² δ),
    # 0.0018 (thrust and rudder race, blanke-race)
    measured, predicted = v.indices["measured"], v.indices["closed_loop"]
    if structure == "blanke-speed":
        # The zig-zag run closed loop on the model from the trial's start: overshoots within 1°
        # (measured 12.9° and 16.1°, predicted 13.0° and 15.6°).
        for key in ("first_overshoot_deg", "second_overshoot_deg"):
            assert predicted[key] == pytest.approx(measured[key], abs=1.0)
    if structure == "blanke-race":
        # Half the free-run error, but the overshoots 1.1° high and 2.1° low (14.0°, 14.0°):
        # the closed loop is judged on two numbers, the free run on every sample.
        for key, tol in (("first_overshoot_deg", 1.5), ("second_overshoot_deg", 2.5)):
            assert predicted[key] == pytest.approx(measured[key], abs=tol)
    tc = turning_circle(fit.model, 35, duration=200, dt=0.05, speed=float(train["u"].iloc[0]))
    assert not tc.diverged
    assert 2 * 7.0 < tc.indices["tactical_diameter"] < 6 * 7.0


@needs_data
def test_esso_identified_on_two_20_20_runs_predicts_30_30_and_turns_without_divergence():
    def log(name):
        return read_log(OSAKA / name, fmt="osaka-frt", start="auto", end="auto")

    zz, turn = "zigzag/zigzag_31-Jul-2020_", "turning/turn_14-Sep-2020_"
    train = [log(f"{zz}13_04_24.csv"), log(f"{zz}14_03_39.csv")]
    tests = [log(f"{zz}13_14_21.csv"), log(f"{zz}13_42_53.csv"), log(f"{turn}13_39_32.csv"),
             log(f"{turn}14_16_04.csv")]  # fmt: skip
    assert [t["n"].mean().round(1) for t in train + tests] == [16.7, 12.0, 16.7, 10.0, 10.0, 10.0]
    fit = identify(train, model="blanke-rps", gamma=1e4)
    results = validate(fit.model, tests)
    assert [v.kind for v in results] == ["zigzag", "zigzag", "turning", "turning"]
    for v in results:
        assert not v.simulation.diverged, v.name
        assert v.metrics["r"]["std"] < 0.04  # rad/s; measured 0.021, 0.031, 0.021, 0.034
    # Without the |n|n thrust and u² δ rudder terms the runs at 10 rps diverge.
    plain = validate(identify(train, model="blanke").model, tests)
    assert any(v.simulation.diverged for v in plain)


@needs_data
def test_auto_trim_finds_the_execute_after_a_hand_steered_approach():
    from shipid.data.trim import manoeuvre_end_time, rudder_execute_time

    raw = read_log(OSAKA / "zigzag" / "zigzag_31-Jul-2020_13_04_24.csv", fmt="osaka-frt")
    # Data README: first large rudder at t ≈ 44 s; the helm reaches −8° before it.
    assert rudder_execute_time(raw) == pytest.approx(44.0, abs=0.5)
    end = manoeuvre_end_time(raw)
    kept = raw[(raw["t"] >= 44.0) & (raw["t"] <= end)]
    assert kept["n"].min() > 16 and raw["n"].iloc[-1] == 0  # the propeller stop is cut off
    assert end == pytest.approx(124.4, abs=0.5)


@needs_data
def test_race_damping_predicts_every_held_out_kvlcc2_log_better_in_sway_and_yaw():
    """Leave one of the three real KVLCC2 zig-zags out (MARIN ±20/20, HSVA 20/10), identify on
    the other two as ``identify`` does (prefilter chosen from the data), run free over the third.
    The rudder's damping in the propeller race (v, r beside u·v, u·r) lowers the sway and yaw
    errors in every fold (measured v 0.0121 → 0.0069, 0.0080 → 0.0069, 0.0088 → 0.0068 m/s;
    r 0.0036 → 0.0028, 0.0022 → 0.0018, 0.0040 → 0.0031 rad/s)."""
    from shipid.data.preprocess import lowpass
    from shipid.identification.prefilter import choose_prefilter

    marin = {"fmt": "simman-marin", "scale": LAMBDA, "dt": 0.2}
    logs = [read_log(MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat", **marin),
            read_log(MARIN / "MARIN_FREE_KVLCC2_zz_-20_m.dat", **marin),
            read_log(DATA / "kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat", fmt="simman-hsva",
                     dt=0.2)]  # fmt: skip

    def held_out_errors(structure):
        out = []
        for k, held in enumerate(logs):
            train = [x for i, x in enumerate(logs) if i != k]

            def fit(data, weights=None):
                return identify(data, model=structure, force=True).model

            cutoff, _ = choose_prefilter(train, fit)
            model = fit(train if cutoff is None else [lowpass(x, cutoff) for x in train])
            metrics = validate(model, [held])[0].metrics
            out.append([metrics[s]["std"] for s in ("v", "r")])
        return np.array(out)

    race = held_out_errors("blanke-race")
    damped = held_out_errors("blanke-race+race-damping")
    assert np.all(damped < 0.9 * race), (race, damped)


@needs_data
def test_the_kernel_residual_on_the_kvlcc2_is_the_readmes():
    """docs/physics-and-uncertainty.md, *A kernel residual*: blanke-speed from MARIN zz 20°
    (1.25 Hz prefilter), γ and σ by free-run CV over four blocks (0.1, 4), and the unseen zz −20°
    run's free-run errors 0.0152 / 0.0123 / 0.0038 → 0.0091 / 0.0101 / 0.0031; the folds' gain
    within its noise."""
    from shipid.data.preprocess import lowpass
    from shipid.dynamics.hybrid import HybridModel
    from shipid.dynamics.simulate import simulate_log
    from shipid.identification.residual import choose_residual, fit_residual

    def fit(logs):
        filtered = [lowpass(x, 1.25) for x in logs]
        return identify(filtered, "blanke-speed", force=True).model, filtered

    zz20 = read_log(MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat", fmt="simman-marin", scale=LAMBDA,
                    dt=0.2)  # fmt: skip
    held = read_log(MARIN / "MARIN_FREE_KVLCC2_zz_-20_m.dat", fmt="simman-marin", scale=LAMBDA,
                    dt=0.2)  # fmt: skip
    choice = choose_residual(fit, [zz20], cv="blocks:4")
    assert (choice.gamma, choice.sigma) == (0.1, 4.0)
    assert 0 < choice.gain < choice.gain_se and any("within its noise" in n for n in choice.notes)
    physical, train = fit([zz20])
    hybrid = HybridModel(physical, fit_residual(physical, train, choice.gamma, choice.sigma))
    errors = {}
    for name, model in (("physical", physical), ("hybrid", hybrid)):
        sim = simulate_log(model, held).log
        errors[name] = [float(np.std(held[s].to_numpy()[: len(sim)] - sim[s].to_numpy()))
                        for s in "uvr"]  # fmt: skip
    np.testing.assert_allclose(errors["physical"], [0.0152, 0.0123, 0.0038], atol=6e-5)
    np.testing.assert_allclose(errors["hybrid"], [0.0091, 0.0101, 0.0031], atol=6e-5)


@needs_data
def test_a_scale_mismatch_names_scale_only_for_marins_files(tmp_path, capsys):
    """validate named '--scale' as the remedy for any log at another scale; only MARIN's reader
    Froude-scales its data by it. HSVA's data are the 7 m model's whatever --scale says (a
    label), and a canonical log refuses it: for those the remedy is rescale."""
    from cli_helpers import run

    zz20 = MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat"
    model = tmp_path / "full.json"
    assert run(["identify", "--format", "simman-marin", zz20, "--model", "blanke-speed",
                "--filter", "none", "--no-output-error", "-o", model], capsys)[0] == 0
    code, _, err = run(["validate", model, "--format", "simman-marin", "--scale", "45.7",
                        MARIN / "MARIN_FREE_KVLCC2_zz_-20_m.dat", "--no-bands"], capsys)
    assert code == 0 and "read it with --scale 1, or carry the model over" in err, err
    code, _, err = run(["validate", model, "--format", "simman-hsva", "--no-bands",
                        DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat"], capsys)
    assert code == 0 and "training logs were at 1:1: carry the model over" in err, err


@needs_data
def test_one_esso_file_predicts_the_logs_at_other_rps_by_similarity(tmp_path):
    """One zig-zag file at 12 rps (14_03_39), the default identify: carried to other propeller
    speeds by advance-ratio similarity, its free runs follow the zig-zags at 10, 15 and 16.7 rps
    closer than the fit's own terms, which answer every rps as 12 (yaw rate error over the
    log's spread, median: 0.15 against 0.38 over the other ten logs,
    ``benchmarks/study_esso_single_logs.py``)."""
    from shipid.reporting.modelfile import load_model
    from shipid.trials.reading import read_trial_log

    train = OSAKA / "zigzag" / "zigzag_31-Jul-2020_14_03_39.csv"
    held = [read_trial_log(OSAKA / "zigzag" / f"zigzag_31-Jul-2020_{s}.csv", fmt="osaka-frt")
            for s in ("13_14_21", "13_22_52", "13_57_45")]  # 16.7, 10 and 15 rps
    errors = {}
    for key, extra in (("similar", []), ("plain", ["--no-rps-similarity"])):
        out = tmp_path / f"{key}.json"
        assert main(["identify", "--format", "osaka-frt", str(train), "-o", str(out),
                     *extra]) == 0  # fmt: skip
        model = load_model(out)
        errors[key] = [validate(model, log, start_draws=False)[0].metrics["r"]["std"]
                       / float(np.std(log["r"])) for log in held]  # fmt: skip
    assert np.median(errors["similar"]) < 0.8 * np.median(errors["plain"]), errors
    assert all(a < b for a, b in zip(errors["similar"], errors["plain"], strict=True)), errors


@needs_data
def test_two_esso_files_no_longer_give_a_model_that_turns_on_a_far_wider_path(tmp_path):
    """Two zig-zag files at 10 and 15 rps (13_22_52, 13_57_45), the default identify: `select`'s
    widened average, whose held 35° turn ran on a path 0.30 as curved as the logs' sharpest (at
    5.4 times its approach speed), passed the rule of a quarter and put the 35° turns at 10 rps
    8.8 and 5.5 times the ship's tactical diameter. At 0.4 it is ruled out: the fallback's turns
    came within 64 %, and since the choice is made on four blocks of each file, `select`'s terms
    within 17 % (``benchmarks/study_esso_single_logs.py``'s pairs). The rule acts inside the
    search whatever its library: its second search, with the hull's cross-flow drag, is left out
    (--no-crossflow) to keep the case as it was found."""
    from shipid.reporting.modelfile import load_model
    from shipid.trials.reading import read_trial_log

    train = [OSAKA / "zigzag" / f"zigzag_31-Jul-2020_{s}.csv" for s in ("13_22_52", "13_57_45")]
    out = tmp_path / "pair.json"
    assert main(["identify", "--format", "osaka-frt", *map(str, train), "--no-crossflow", "-o",
                 str(out)]) == 0  # fmt: skip
    model = load_model(out)
    for path in sorted((OSAKA / "turning").glob("*.csv")):
        turn = validate(model, read_trial_log(path, fmt="osaka-frt"), start_draws=False)[0]
        ratio = (turn.indices["closed_loop"]["tactical_diameter"]
                 / turn.indices["measured"]["tactical_diameter"])  # fmt: skip
        assert 0.5 < ratio < 1.8, (path.name, ratio)


@needs_data
def test_two_esso_files_choose_on_four_blocks_of_each(tmp_path):
    """Two logs left out in turn are two folds; identify's choices on one or two logs cut each
    into four blocks (``cross_validation.choice_cv``). The zig-zags at 12 and 16.7 rps
    (13_29_19, 13_14_21) at Δk 0.5 s, the README's random run held out: its yaw rate 0.56 of its
    spread, against 0.85 with the two files left out in turn (``study_auto_structure.py``;
    without the hull's cross-flow drag, which the default now also searches with on one or two
    logs and takes here: 0.71)."""
    import json

    from shipid.reporting.modelfile import load_model

    train = [OSAKA / "zigzag" / f"zigzag_31-Jul-2020_{s}.csv" for s in ("13_29_19", "13_14_21")]
    out = tmp_path / "pair.json"
    assert main(["identify", "--format", "osaka-frt", "--dt", "0.5", *map(str, train),
                 "--no-crossflow", "-o", str(out)]) == 0  # fmt: skip
    assert json.loads(out.read_text())["identification"]["structure_choice"]["cv"] == "blocks:4"
    held = read_log(OSAKA / "random" / "random_31-Jul-2020_12_29_58.csv", fmt="osaka-frt",
                    dt=0.5, end="dropout")  # fmt: skip
    run = validate(load_model(out), held, start_draws=False)[0]
    assert not run.simulation.diverged
    assert run.metrics["r"]["std"] / float(np.std(held["r"])) < 0.7


@needs_data
def test_a_pair_at_12_and_15_rps_turns_at_10_where_the_esso_turned(tmp_path, capsys):
    """Two zig-zag files at 12 and 15 rps (13_50_28, 13_57_45): the default model turned
    plausibly at both and failed at 10 rps, where the Esso's turns were run (their closed loops
    ended without a tactical diameter), and identify warned of it (at 0.6 of the logs' lowest
    rps its held 35° turn failed a check, ``beyond_the_logs.below_the_logs_rps``). Its library held
    a constant force, the same at every rps; written as advance-ratio similarity has it (n|n|,
    ``similarity.similar_library``), the model turns at 10 rps, +21 % and +6 % long with the
    hull's cross-flow drag, which the default also searches with on one or two logs and takes
    here (it was 25 % short; without the drag, +32 % and +20 %, where it had no turn), and
    nothing fails below the logs' rps. The MARIN KVLCC2 model (one rps) gets no such warning
    either."""
    import json

    from shipid.reporting.modelfile import load_model
    from shipid.trials.reading import read_trial_log

    train = [OSAKA / "zigzag" / f"zigzag_31-Jul-2020_{s}.csv" for s in ("13_50_28", "13_57_45")]
    turns = [read_trial_log(p, fmt="osaka-frt") for p in sorted((OSAKA / "turning").glob("*.csv"))]
    out = tmp_path / "pair.json"
    assert main(["identify", "--format", "osaka-frt", *map(str, train), "-o", str(out)]) == 0
    assert "below the logs' propeller speeds" not in capsys.readouterr().err
    library = json.loads(out.read_text())["identification"]["structure_choice"]["library"]
    assert library.endswith("with the hull's cross-flow drag")
    for v in validate(load_model(out), turns, start_draws=False):
        ratio = (v.indices["closed_loop"]["tactical_diameter"]
                 / v.indices["measured"]["tactical_diameter"])  # fmt: skip
        assert 1.0 < ratio < 1.3, ratio
    marin = DATA / "kvlcc2-marin" / "MARIN_FREE_KVLCC2_zz_20_m.dat"
    assert main(["identify", "--format", "simman-marin", "--scale", "45.7", str(marin), "-o",
                 str(tmp_path / "kv.json")]) == 0  # fmt: skip
    assert "below the logs' propeller speeds" not in capsys.readouterr().err
