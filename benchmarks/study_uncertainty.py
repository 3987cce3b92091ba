"""Identifiability study on the paper's ship (issue #10): over seeds of the demo's noisy trials,
the default identification (LS-SVM, prefilter chosen from the data, bootstrap intervals) against
maximum-likelihood output error from it (covariance intervals): how well each predicts the
held-out manoeuvres against the true model's own error, and how often its 95 % intervals cover
the true coefficients. Runs as a ``shipid study`` (``shipid.evaluation.study``).

Then the same comparison on real data: the KVLCC2's held-out zig-zags (``real_data``), and
the plain ``shipid identify`` command, whose default fits by output error where the LS-SVM's
free runs leave only the sensors' noise (``default_command``).

Run: .venv/bin/python benchmarks/study_uncertainty.py [SEEDS] [REPLICATES]
"""

from __future__ import annotations

import math
import os
import sys
import time

from shipid.evaluation.study import StudySpec, run_study, summary


def main(seeds: int = 40, replicates: int = 100) -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {seeds} seeds, "
          f"{replicates} bootstrap replicates for the LS-SVM\n")  # fmt: skip
    t0 = time.perf_counter()
    spec = StudySpec(seeds=tuple(range(seeds)), estimator=("lssvm", "output-error"),
                     bootstrap=replicates)  # fmt: skip
    results = run_study(spec, workers=2, progress=False)
    table = summary(results).drop(columns=["noise", "gamma", "structure", "filter"])
    print(table.set_index("estimator").T.to_markdown())
    from shipid.demo import PAPER_TABLE

    one = results[results["estimator"] == "lssvm"]
    for name in [k for k in PAPER_TABLE if f"{k}: beats paper" in results]:
        truth_beats = sum(all(row[f"{name}: {s} truth error std"] <= p
                              for s, p in zip("uvr", PAPER_TABLE[name], strict=True))
                          for _, row in one.iterrows())  # fmt: skip
        print(f"\nthe true model itself beats the paper on {name} in {truth_beats} of {len(one)}",
              end="")
    print()
    cutoffs = sorted(set(results["cutoff_hz"].round(3)))
    print(f"\nPrefilter cut-offs chosen (LS-SVM and the output-error start): {cutoffs}")
    print(f"time {time.perf_counter() - t0:.1f} s (2 Dask workers)")


def standard_error_coverage(seeds: int = 20) -> None:
    """How often the ± standard errors ``identify`` prints beside the LS-SVM coefficients hold
    the true value (×1.96, a 95 % interval if they were the whole error), over seeds of the
    demo's training zig-zag, the prefilter chosen from the data as ``identify`` does."""
    from shipid.data.preprocess import lowpass
    from shipid.demo import TRAINING, synthesise_trials
    from shipid.identification.identify import identify
    from shipid.identification.prefilter import choose_prefilter
    from shipid.vessels import scale_ship_model

    truth = scale_ship_model()
    hit = total = 0
    for seed in range(1, seeds + 1):
        log = synthesise_trials(seed)[TRAINING]
        cutoff, _ = choose_prefilter([log], lambda logs: identify(logs).model)
        fit = identify(lowpass(log, cutoff) if cutoff else log)
        for dof, coefs in fit.model.coefficients.items():
            se = fit.diagnostics[dof]["std_errors"]
            for term, value in coefs.items():
                want = truth.coefficients.get(dof, {}).get(term)
                if term == "1" or want is None or term not in se:
                    continue
                total += 1
                hit += abs(value - want) <= 1.96 * se[term]
    print(f"\nidentify's ± standard errors, ×1.96, hold the true coefficient in {hit} of {total} "
          f"coefficient × seed pairs ({100 * hit / total:.0f} %), {seeds} seeds")


def default_command(seeds: int = 200) -> None:
    """Issue #10's acceptance, run as a user would: ``shipid identify TRAINING.csv`` (no flags)
    on each seed's noisy 20/20 zig-zag, then the held-out trials. Counts how often the file's
    95 % intervals (estimate ± 1.96 of its standard errors: output error's where the default
    chose it, else the LS-SVM's) hold the true coefficient, the wrong signs outside them, and
    the paper's table rows beaten."""
    import contextlib
    import io
    import json
    import tempfile
    from pathlib import Path

    import numpy as np

    from shipid.cli import main as cli
    from shipid.data.io import write_log
    from shipid.demo import PAPER_TABLE, TRAINING, synthesise_trials
    from shipid.evaluation.validate import validate
    from shipid.reporting.modelfile import load_model
    from shipid.vessels import scale_ship_model

    true_model = scale_ship_model()
    truth = true_model.coefficients
    hit = total = wrong_sign = oe = 0
    per_seed = []  # (inside, pairs) of each seed, for the spread of a 20-seed figure
    beats = {k: 0 for k in PAPER_TABLE if k != TRAINING}
    truth_beats = dict.fromkeys(beats, 0)  # the true model on the same noisy trials
    # Held-out error std over the true model's own on the same noisy trial, per manoeuvre and
    # state: the plain command's model and the LS-SVM it starts from (--no-output-error).
    ratios = {"plain": [], "--no-output-error": []}
    apart = []  # the two fits' 35° held-rudder steady yaw rates, relative difference

    def held_rates(doc):  # a turn that never settled has no steady yaw rate
        held = (doc["identification"].get("plausibility") or {}).get("held_rudder") or {}
        return [held.get(side, {}).get("steady_yaw_rate") if held.get(side, {}).get("settled")
                else None for side in ("starboard", "port")]  # fmt: skip
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(seeds):
            logs = synthesise_trials(seed)
            train = write_log(logs[TRAINING], Path(tmp) / "train.csv")
            out = Path(tmp) / "model.json"
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):
                assert cli(["identify", str(train), "-o", str(out)]) == 0
            doc = json.loads(out.read_text())
            ref = doc["identification"].get("refinement")
            chosen = (doc["identification"]["preprocessing"].get("output_error") or {}).get(
                "fit") == "output error"  # the file's model (its turns may send it back)
            oe += chosen
            se = (ref["statistics"]["standard_errors"] if chosen else
                  {d: v.get("std_errors", {}) for d, v in doc["identification"]["diagnostics"].items()})
            seed_hit, seed_total = hit, total
            for dof, terms in doc["model"]["coefficients"].items():
                for term, value in terms.items():
                    if term == "1" or term not in truth.get(dof, {}):
                        continue
                    want, s = truth[dof][term], se[dof].get(term, 0.0)
                    inside = abs(value - want) <= 1.96 * s
                    total += 1
                    hit += inside
                    wrong_sign += (not inside) and want != 0 and np.sign(value) != np.sign(want)
            per_seed.append((hit - seed_hit, total - seed_total))
            model = load_model(out)
            held = [logs[k] for k in beats]
            own = validate(true_model, held, list(beats))
            for v in own:
                truth_beats[v.name] += all(v.metrics[s]["std"] <= p for s, p in
                                           zip("uvr", PAPER_TABLE[v.name], strict=True))  # fmt: skip
            for v in validate(model, held, list(beats)):
                beats[v.name] += all(v.metrics[s]["std"] <= p for s, p in
                                     zip("uvr", PAPER_TABLE[v.name], strict=True))  # fmt: skip
            ls_out = Path(tmp) / "lssvm.json"
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):
                assert cli(["identify", str(train), "--no-output-error", "-o", str(ls_out)]) == 0
            pair = [held_rates(doc), held_rates(json.loads(ls_out.read_text()))]
            apart.append(max((abs(a / b - 1) for a, b in zip(*pair, strict=True)
                              if a is not None and b is not None), default=0.0))
            for label, path in (("plain", out), ("--no-output-error", ls_out)):
                runs = validate(load_model(path), held, list(beats))
                ratios[label].append([[v.metrics[s]["std"] / t.metrics[s]["std"] for s in "uvr"]
                                      for v, t in zip(runs, own, strict=True)])  # fmt: skip
    print(f"\n`shipid identify TRAINING.csv` (no flags), {seeds} seeds of the demo's trials: "
          f"output error chosen in {oe} of {seeds}; 95 % intervals hold the true coefficient in "
          f"{hit} of {total} coefficient × seed pairs ({100 * hit / total:.0f} %); wrong sign "
          f"outside the interval: {wrong_sign}; the paper's table beaten: "
          + ", ".join(f"{k} {n} of {seeds}" for k, n in beats.items())
          + " (the true model: " + ", ".join(f"{n}" for n in truth_beats.values()) + ")"
          + f"; {(time.perf_counter() - t0) / seeds:.2f} s per seed (both fits); the file's "
          f"and the LS-SVM fit's 35° held-rudder steady yaw rates (settled turns) at most "
          f"{100 * max(apart):.0f} % apart")
    if seeds >= 40:
        blocks = np.array(per_seed[: seeds // 20 * 20]).reshape(-1, 20, 2).sum(axis=1)
        share = blocks[:, 0] / blocks[:, 1]
        print(f"\nThe same count per block of 20 consecutive seeds ({len(share)} blocks): "
              f"{100 * share.min():.0f} to {100 * share.max():.0f} %, at least 90 % in "
              f"{int(np.sum(share >= 0.9))} of {len(share)}")
    print("\nHeld-out error std over the true model's own (1 = the noise floor), median ≤ largest "
          "over the seeds, u / v / r\n")
    print("| manoeuvre | plain `shipid identify` | `--no-output-error` (LS-SVM) |")
    print("|---|---|---|")
    for i, name in enumerate(beats):
        cells = []
        for label in ratios:
            r = np.array(ratios[label])[:, i, :]
            cells.append(" / ".join(f"{m:.2f}" for m in np.median(r, axis=0)) + " ≤ "
                         + " / ".join(f"{m:.2f}" for m in r.max(axis=0)))
        print(f"| {name} | " + " | ".join(cells) + " |")


def default_command_mismatch(seeds: int = 12) -> None:
    """The plain command where the structure is not the truth: `shipid identify` with
    ``--model blanke-race+race-damping`` on two noisy 20/20 zig-zags (starboard and port first)
    of the KVLCC2's MMG model at a quarter of the paper's sensor noise. The noise check chooses
    output error; the 35° turns (tactical diameter against the MMG model's) say whether that
    fit may be kept, and what the default keeps."""
    import contextlib
    import io
    import json
    import tempfile
    from pathlib import Path

    from shipid.cli import main as cli
    from shipid.data.io import write_log
    from shipid.reporting.modelfile import load_model, model_from_document
    from shipid.trials.manoeuvres import turning_circle, zigzag
    from shipid.vessels import PAPER_IMU, kvlcc2

    ship = kvlcc2()
    true_td = turning_circle(ship, 35, duration=300, dt=0.2).indices["tactical_diameter"]

    def turn(model):
        run = turning_circle(model, 35, duration=300, dt=0.2, speed=ship.approach_speed,
                             steering=ship.steering)  # fmt: skip
        ind = {} if run.diverged else run.indices
        td, r = ind.get("tactical_diameter"), ind.get("steady_yaw_rate")  # None: none reached
        return (math.nan if td is None else td), (math.nan if r is None else abs(r))

    print("\nThe plain command where the structure is not the truth: KVLCC2 MMG model, two noisy "
          "20/20 zig-zags (0.25 × the paper's sensor noise), --model blanke-race+race-damping; "
          f"35° tactical diameter against the MMG model's {true_td:.3g} m\n")
    print("| seed | noise check | the file's model | output-error fit: 35° TD | LS-SVM fit: 35° TD "
          "| steady yaw rates apart |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(seeds):
            paths = [str(write_log(PAPER_IMU.scaled(0.25).apply(
                zigzag(ship, 20, 20, duration=150, dt=0.2, first=side).log, seed=10 * seed + i),
                Path(tmp) / f"zz{i}.csv")) for i, side in enumerate(("starboard", "port"))]  # fmt: skip
            out = Path(tmp) / "m.json"
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):
                assert cli(["identify", *paths, "--model", "blanke-race+race-damping",
                            "-o", str(out)]) == 0  # fmt: skip
            doc = json.loads(out.read_text())
            choice = doc["identification"]["preprocessing"]["output_error"]
            ref = doc["identification"].get("refinement")
            worst = max(choice["noise_ratios"].values())
            if ref is None:
                why = choice.get("why", "")
                oe = "not kept (its residuals correlated)" if "correlated" in why else why
                lssvm = load_model(out)
                lssvm_td, _ = turn(lssvm)
                apart = "–"
            else:
                fitted_td, fitted_r = turn(model_from_document({"model": ref["refined_model"]},
                                                               out))  # fmt: skip
                lssvm_td, lssvm_r = turn(model_from_document({"model": ref["initial_model"]}, out))
                oe = (f"{100 * (fitted_td / true_td - 1):+.0f} %" if fitted_td == fitted_td
                      else "no turn (diverged or never steady)")  # fmt: skip
                apart = f"{100 * abs(fitted_r / lssvm_r - 1):.0f} %" if fitted_r == fitted_r \
                    else "–"  # fmt: skip
            print(f"| {seed} | {worst:.3g} × noise | {choice['fit']} | {oe} | "
                  f"{100 * (lssvm_td / true_td - 1):+.0f} % | {apart} |")


def real_data() -> None:
    """KVLCC2 (MARIN zz 20°, ``blanke-speed``, prefilter chosen from the data, as ``identify``):
    the LS-SVM against output error from it, free-run error std on the two held-out zig-zags,
    and the plausibility of each model (35° rudder held)."""
    from pathlib import Path

    from shipid.data.io import read_log
    from shipid.data.preprocess import lowpass
    from shipid.evaluation.validate import validate
    from shipid.identification.identify import identify
    from shipid.identification.output_error import output_error
    from shipid.identification.plausibility import check_plausibility
    from shipid.identification.prefilter import choose_prefilter

    data = Path(__file__).resolve().parents[2] / "shared" / "data"
    if not data.is_dir():
        print("\n../shared/data is absent: no real-data rows")
        return
    marin = dict(fmt="simman-marin", scale=45.7, dt=0.2)
    train = read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_20_m.dat", **marin)
    held = {"MARIN zz −20°": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_-20_m.dat",
                                      **marin),
            "HSVA zz 20/10": read_log(data / "kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                                      fmt="simman-hsva", dt=0.2)}  # fmt: skip

    def fit(logs):
        return identify(logs, model="blanke-speed", force=True).model

    cutoff, _ = choose_prefilter([train], fit)
    lssvm = fit(train if cutoff is None else lowpass(train, cutoff))
    from shipid.identification.output_error import NOISE_DOMINATES, noise_ratios

    ratios = noise_ratios(lssvm, [train]).iloc[0]
    print("\nKVLCC2, MARIN zz 20°: the LS-SVM's free-run error over the log's white noise "
          + ", ".join(f"{s} {x:.3g}" for s, x in ratios.items())
          + f" (the default fits by output error at ≤ {NOISE_DOMINATES:g} in every state)")
    oe, _ = output_error(lssvm, train)
    st = oe.statistics
    print(f"\nKVLCC2, trained on MARIN zz 20° (prefilter {cutoff:.3g} Hz); output error: residual "
          f"lag-1 ρ {max(st['residual_autocorrelation'].values()):.2f}, standard errors widened "
          f"×{st['covariance_inflation'] ** 0.5:.3g}\n")  # fmt: skip
    print("| held out | LS-SVM u / v / r error std | output error |")
    print("|---|---|---|")
    runs = {name: validate(m, list(held.values()), list(held)) for name, m in
            (("lssvm", lssvm), ("oe", oe.model))}  # fmt: skip
    for k, name in enumerate(held):
        cells = [" / ".join(f"{runs[m][k].metrics[s]['std']:.4f}" for s in "uvr")
                 for m in ("lssvm", "oe")]  # fmt: skip
        print(f"| {name} | {cells[0]} | {cells[1]} |")
    speed = float(train["u"].iloc[:25].mean())
    for name, m in (("LS-SVM", lssvm), ("output error", oe.model)):
        notes = check_plausibility(m, speed)[1]
        print(f"\nplausibility of the {name} model: " + ("; ".join(notes) or "passes"))


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))
    standard_error_coverage()
    default_command()
    default_command_mismatch()
    real_data()
