"""Structure against a truth of another structure (issue #10, the principal push): the KVLCC2's MMG
model (propeller, rudder in its race, cubic hull forces; checked against an independent MMG code)
is observed through the zig-zags a basin gives (20/20 to both sides and a 20/10, with sensor
noise), each structure is identified as ``identify`` does (prefilter chosen from the data), and
judged on what it was not fitted to: the 10/10 zig-zags and the 35° turning circles.

Then the real KVLCC2: trained on the MARIN zig-zag 20/20, judged on the MARIN −20° run (free-run
errors, the zig-zag closed loop from its start) and the 35° turn against the MMG model, over the
prefilter cut-offs ``identify`` chooses among.

Run: .venv/bin/python benchmarks/study_structure.py [SEEDS] [NOISE]
"""

from __future__ import annotations

import math
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from shipid.data.preprocess import lowpass
from shipid.identification.identify import identify
from shipid.identification.prefilter import candidate_cutoffs, choose_prefilter
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.vessels import PAPER_IMU, kvlcc2

STRUCTURES = ("blanke-speed", "blanke-race", "blanke-race+race-damping", "abkowitz3")
REAL = STRUCTURES[:3]  # abkowitz3 is judged on the MMG truth only
TRAINING = ((20, 20, "starboard"), (20, 20, "port"), (20, 10, "starboard"))
HELD_ZIGZAGS = ((10, 10, "starboard"), (10, 10, "port"))
DT = 0.2
OVERSHOOTS = ("first_overshoot_deg", "second_overshoot_deg")


def _zigzag(ship, rudder, heading, side, **kw):
    return zigzag(ship, rudder, heading, first=side, duration=300, dt=DT, approach=5, **kw)


def _turn(ship, side, **kw):
    return turning_circle(ship, 35, side=side, duration=600, dt=DT, approach=5, **kw)


def fit_as_identify(logs, structure):
    """``identify``'s LS-SVM fit: the prefilter cut-off chosen by free-run error on the logs.
    Its default goes on to output error only where the LS-SVM leaves nothing but noise and the
    two fits' 35° turns agree; on these MMG logs it keeps the LS-SVM (`blanke` 2.4 times the
    noise, `blanke-speed`'s output-error residuals correlated, `blanke-race+race-damping`'s
    turns far apart; ``study_uncertainty.default_command_mismatch``; ad hoc for the first two)."""

    def fit(train, weights=None):
        return identify(train, model=structure, force=True).model

    cutoff, _ = choose_prefilter(logs, fit)
    return fit(logs if cutoff is None else [lowpass(log, cutoff) for log in logs]), cutoff


def held_out_errors(model, ship, truth_zz, truth_tc, rps: float | None = None,
                    turn_keys=("tactical_diameter", "steady_yaw_rate")) -> list[float]:  # fmt: skip
    """Overshoot errors [deg] of the held-out zig-zags, then the ``turn_keys`` errors [%] of the
    35° turns (nan where the model diverges); ``rps``: the propeller speed a model with terms
    in n runs at."""
    kw = {"speed": ship.approach_speed, "steering": ship.steering, "rps": rps}
    out = []
    for case in HELD_ZIGZAGS:
        ind = _zigzag(model, *case, **kw).indices
        out += [(ind.get(k) or math.nan) - truth_zz[case][k] for k in OVERSHOOTS]
    for side in ("starboard", "port"):
        res = _turn(model, side, **kw)
        ind = {} if res.diverged or not res.indices else res.indices
        for k in turn_keys:
            value = ind.get(k)
            out.append(math.nan if value is None else 100 * (value / truth_tc[side][k] - 1))
    return out


DERIVATIVES = ("∂v̇/∂v", "∂v̇/∂r", "∂v̇/∂δ", "∂ṙ/∂v", "∂ṙ/∂r", "∂ṙ/∂δ")


def sway_yaw_derivatives(accelerations, speed: float, h: float = 1e-5) -> np.ndarray:
    """(6,) ∂(v̇, ṙ)/∂(v, r, δ) at straight running at ``speed`` by central differences of
    ``accelerations(u, v, r, δ) → (u̇, v̇, ṙ)``."""
    out = np.zeros((2, 3))
    for k in range(3):
        e = np.zeros(4)
        e[k + 1] = h
        up = np.ravel(accelerations(speed + e[0], e[1], e[2], e[3]))
        down = np.ravel(accelerations(speed - e[0], -e[1], -e[2], -e[3]))
        out[:, k] = (up[1:3] - down[1:3]) / (2 * h)
    return out.ravel()


def mmg(seeds: int, noise: float) -> None:
    ship = kvlcc2()
    truth_zz = {c: _zigzag(ship, *c).indices for c in HELD_ZIGZAGS}
    truth_tc = {s: _turn(ship, s).indices for s in ("starboard", "port")}
    sensor = PAPER_IMU.scaled(noise)
    print(f"MMG KVLCC2 at {ship.approach_speed:.3f} m/s, rudder rate "
          f"{math.degrees(ship.steering.max_rate):.1f} °/s; trained on zig-zags "
          f"{', '.join(f'{a}/{h} {s}' for a, h, s in TRAINING)}; sensor noise {noise:g} × the "
          f"paper's IMU; {seeds} seeds\n")  # fmt: skip
    print("truth: 10/10 overshoots " + ", ".join(
        f"{s} first {truth_zz[(10, 10, s)][OVERSHOOTS[0]]:.1f}° / "
        f"{truth_zz[(10, 10, s)][OVERSHOOTS[1]]:.1f}°" for s in ("starboard", "port"))
        + "; 35° tactical diameter " + ", ".join(
        f"{truth_tc[s]['tactical_diameter'] / ship.length:.2f} L" for s in truth_tc) + "\n")
    from shipid.vessels.kvlcc2 import accelerations, trimmed_revolutions

    rps = trimmed_revolutions(ship.approach_speed)
    truth_lin = sway_yaw_derivatives(lambda u, v, r, d: accelerations(u, v, r, d, rps),
                                     ship.approach_speed)  # fmt: skip
    errors: dict[str, list[list[float]]] = {s: [] for s in STRUCTURES}
    linear: dict[str, list[np.ndarray]] = {s: [] for s in STRUCTURES}
    t0 = time.perf_counter()
    for seed in range(seeds):
        logs = [sensor.apply(_zigzag(ship, *case).log, seed=100 * seed + i)
                for i, case in enumerate(TRAINING)]  # fmt: skip
        for structure in STRUCTURES:
            model, _ = fit_as_identify(logs, structure)
            errors[structure].append(held_out_errors(model, ship, truth_zz, truth_tc))
            linear[structure].append(
                sway_yaw_derivatives(model.accelerations, ship.approach_speed) / truth_lin - 1)
    head = ["10/10 stbd 1st", "10/10 stbd 2nd", "10/10 port 1st", "10/10 port 2nd",
            "TD stbd", "r stbd", "TD port", "r port"]  # fmt: skip
    print("Mean error (largest |error|) over the seeds; overshoots in degrees, the 35° turn's "
          "tactical diameter and steady yaw rate in %; diverged turns counted apart.\n")
    print("| structure | " + " | ".join(head) + " | turns diverged |")
    print("|---" * (len(head) + 2) + "|")
    for structure, rows in errors.items():
        e = np.array(rows)
        cells = []
        for j in range(e.shape[1]):
            col = e[:, j][np.isfinite(e[:, j])]
            cells.append("–" if col.size == 0 else f"{col.mean():+.1f} ({np.abs(col).max():.1f})")
        diverged = int(np.isnan(e[:, 4:]).any(axis=1).sum())
        print(f"| {structure} | " + " | ".join(cells) + f" | {diverged} of {len(rows)} |")
    print("\nThe identified models' linear sway–yaw derivatives at the approach speed against the "
          "MMG model's (the truth the issue asks for within 30 %): mean relative error (largest "
          "|error|) over the seeds.\n")
    print("| structure | " + " | ".join(DERIVATIVES) + " | all within 30 % |")
    print("|---" * (len(DERIVATIVES) + 2) + "|")
    for structure, rows in linear.items():
        e = 100 * np.array(rows)
        within = int((np.abs(e) <= 30).all(axis=1).sum())
        print(f"| {structure} | " + " | ".join(f"{e[:, j].mean():+.0f} % ({np.abs(e[:, j]).max():.0f} %)"
                                               for j in range(e.shape[1]))
              + f" | {within} of {len(rows)} seeds |")  # fmt: skip
    print(f"\n{time.perf_counter() - t0:.1f} s")


def _same(a: float | None, b: float | None) -> bool:
    return a is None and b is None or None not in (a, b) and math.isclose(a, b, rel_tol=1e-9)


def real_data() -> None:
    """The real KVLCC2 trained on MARIN's zig-zag 20/20: the held-out MARIN −20° run and HSVA
    20/10 run, and the 35° turn against the MMG model, over the prefilter cut-offs."""
    from shipid.data.io import read_log
    from shipid.evaluation.validate import validate

    data = Path(__file__).resolve().parents[2] / "shared" / "data"
    if not data.is_dir():
        print("\n../shared/data is absent: no real-data rows")
        return
    kw = {"fmt": "simman-marin", "scale": 45.7, "dt": DT}
    train = read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_20_m.dat", **kw)
    held = {"MARIN zz −20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_-20_m.dat", **kw),
            "HSVA zz 20/10": read_log(data / "kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                                      fmt="simman-hsva", dt=DT)}  # fmt: skip
    mmg_turn = _turn(kvlcc2(), "starboard").indices
    print("\nKVLCC2, trained on MARIN zz 20/20; held out: MARIN zz −20/−20 (overshoots 12.9°, "
          "16.1° measured) and HSVA zz 20/10 (11.0°, 12.9°), free-run error std u / v / r and "
          "the zig-zag closed loop from the trial's start; the 35° turn to starboard against the "
          f"MMG model (tactical diameter {mmg_turn['tactical_diameter']:.1f} m, steady speed "
          f"{mmg_turn['steady_speed']:.2f} m/s, steady yaw rate {mmg_turn['steady_yaw_rate']:.4f} "
          "rad/s)\n")  # fmt: skip
    print("| structure | prefilter | chosen by identify | " + " | ".join(
        f"{name}: error std, overshoots" for name in held)
        + " | 35° TD (m) | steady speed (m/s) | steady r (rad/s) |")
    print("|---" * (6 + len(held)) + "|")
    chosen_models = {}
    for structure in REAL:
        chosen_models[structure], chosen = fit_as_identify([train], structure)
        for cutoff in (None, *candidate_cutoffs(DT)[:4]):
            model = identify(train if cutoff is None else lowpass(train, cutoff),
                             model=structure, force=True).model  # fmt: skip
            cells = []
            for v in validate(model, list(held.values()), list(held)):
                closed = v.indices["closed_loop"]
                cells.append(" / ".join(f"{v.metrics[s]['std']:.4f}" for s in "uvr")
                             + f", {closed[OVERSHOOTS[0]]:.1f}°, {closed[OVERSHOOTS[1]]:.1f}°")
            tc = _turn(model, "starboard", speed=float(train["u"].iloc[0]),
                       steering=kvlcc2().steering)  # fmt: skip
            ind = {} if tc.diverged or not tc.indices else tc.indices
            turn = [ind.get(k) for k in ("tactical_diameter", "steady_speed", "steady_yaw_rate")]
            print(f"| {structure} | {'none' if cutoff is None else f'{cutoff:g} Hz'} | "
                  f"{'yes' if _same(cutoff, chosen) else ''} | " + " | ".join(cells) + " | "
                  + " | ".join("diverged" if x is None else f"{x:.4g}" for x in turn) + " |")
    ship = kvlcc2()
    truth = {c: _zigzag(ship, *c).indices for c in HELD_ZIGZAGS}
    print("\nThe 10/10 zig-zags (no real one here) predicted by the models above (the prefilter "
          "identify chooses) from the MARIN run's approach speed, against the MMG model of the "
          "same ship: first / second overshoot [deg]\n")  # fmt: skip
    print("| model | 10/10 starboard first | 10/10 port first |")
    print("|---|---|---|")
    print("| MMG model | " + " | ".join(f"{truth[c][OVERSHOOTS[0]]:.1f}, {truth[c][OVERSHOOTS[1]]:.1f}"
                                     for c in HELD_ZIGZAGS) + " |")  # fmt: skip
    from shipid.dynamics.steering import SteeringMachine

    for structure, model in chosen_models.items():
        # The KVLCC2's gear, and a rudder that moves at once (what `manoeuvre` gave model
        # files before it used their training rudder rate).
        for label, gear in (("", ship.steering), (", instantaneous rudder", SteeringMachine())):
            kw = {"speed": float(train["u"].iloc[0]), "steering": gear}
            cells = []
            for c in HELD_ZIGZAGS:
                ind = _zigzag(model, *c, **kw).indices
                cells.append(", ".join(f"{ind.get(k) or math.nan:.1f}" for k in OVERSHOOTS))
            print(f"| {structure}{label} | " + " | ".join(cells) + " |")


def prior_effect(seeds: int = 3, noise: float = 1.0) -> None:
    """Does the Clarke prior (from the MARIN particulars) help the coefficients? The MMG trials
    as in ``mmg``, blanke-race prefiltered as identify does, γ by free-run cross-validation over
    the logs (``identify --gamma auto``) with and without the prior: the largest error of the
    six linear sway–yaw derivatives against the MMG model's."""
    from shipid.data.particulars import read_particulars
    from shipid.dynamics.model import get_structure
    from shipid.identification.physics import PhysicsOptions
    from shipid.identification.priors import clarke_prior
    from shipid.identification.select import select
    from shipid.vessels.kvlcc2 import accelerations, trimmed_revolutions

    path = Path(__file__).resolve().parents[2] / "shared/data/kvlcc2-marin/ship_data.yml"
    if not path.exists():
        return
    ship = kvlcc2()
    U = ship.approach_speed
    rps = trimmed_revolutions(U)
    truth = sway_yaw_derivatives(lambda u, v, r, d: accelerations(u, v, r, d, rps), U)
    prior = clarke_prior(read_particulars(path), get_structure("blanke-race"), U, "starboard")
    sensor = PAPER_IMU.scaled(noise)
    print(f"\nThe Clarke prior, blanke-race on the MMG trials at {noise:g} × the paper's noise: "
          "largest relative error of the six linear derivatives, γ chosen by free-run CV\n")
    print("| seed | without prior: γ, largest error | with the Clarke prior: γ, largest error |")
    print("|---|---|---|")
    for seed in range(seeds):
        logs = [sensor.apply(_zigzag(ship, *case).log, seed=100 * seed + i)
                for i, case in enumerate(TRAINING)]  # fmt: skip
        _, cutoff = fit_as_identify(logs, "blanke-race")
        train = logs if cutoff is None else [lowpass(log, cutoff) for log in logs]
        cells = []
        for physics in (None, PhysicsOptions(prior=prior)):
            sel = select(train, library="blanke-race", search="none", cv="logo",
                         plausibility=False, physics=physics)  # fmt: skip
            err = np.abs(sway_yaw_derivatives(sel.model.accelerations, U) / truth - 1).max()
            cells.append(f"{sel.gamma:g}, {100 * err:.0f} %")
        print(f"| {seed} | " + " | ".join(cells) + " |")


def leave_one_log_out() -> None:
    """The three real KVLCC2 zig-zags (MARIN ±20/20, HSVA 20/10): each structure identified on
    two, judged on the third (free-run error std and the zig-zag run closed loop from its start)."""
    from shipid.data.io import read_log
    from shipid.evaluation.validate import validate

    data = Path(__file__).resolve().parents[2] / "shared" / "data"
    if not data.is_dir():
        return
    marin = {"fmt": "simman-marin", "scale": 45.7, "dt": DT}
    logs = {"MARIN zz 20/20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_20_m.dat", **marin),
            "MARIN zz −20/−20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_-20_m.dat",
                                         **marin),
            "HSVA zz 20/10": read_log(data / "kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                                      fmt="simman-hsva", dt=DT)}  # fmt: skip
    print("\nKVLCC2, leave one real log out: identified (as identify does) on the other two\n")
    print("| structure | held out | u / v / r error std | overshoots measured | closed loop |")
    print("|---|---|---|---|---|")
    for structure in REAL:
        for held, log in logs.items():
            model, _ = fit_as_identify([x for k, x in logs.items() if k != held], structure)
            v = validate(model, [log])[0]
            me, cl = v.indices["measured"], v.indices["closed_loop"]
            print(f"| {structure} | {held} | "
                  + " / ".join(f"{v.metrics[s]['std']:.4f}" for s in "uvr")
                  + f" | {me[OVERSHOOTS[0]]:.1f}°, {me[OVERSHOOTS[1]]:.1f}° | "
                  f"{cl[OVERSHOOTS[0]]:.1f}°, {cl[OVERSHOOTS[1]]:.1f}° |")


def _real_logs(data: Path) -> dict:
    from shipid.data.io import read_log

    marin = {"fmt": "simman-marin", "scale": 45.7, "dt": DT}
    return {"MARIN zz 20/20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_20_m.dat", **marin),
            "MARIN zz −20/−20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_-20_m.dat",
                                         **marin),
            "HSVA zz 20/10": read_log(data / "kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                                      fmt="simman-hsva", dt=DT)}  # fmt: skip


def nested_selection() -> None:
    """Selection judged on a log it never saw: for each real KVLCC2 log held out, ``select``
    (stepwise terms and γ by leave-one-log-out free-run error) runs on the other two, and the
    chosen model runs free over the held-out one; against the fixed blanke-race+race-damping."""
    from shipid.evaluation.validate import validate
    from shipid.identification.select import select

    data = Path(__file__).resolve().parents[2] / "shared" / "data"
    if not data.is_dir():
        return
    logs = _real_logs(data)
    fixed = "blanke-race+race-damping"
    print("\nKVLCC2, selection judged on the log left out (select's own cross-validation runs on "
          "the other two, prefilter chosen as identify does for the library's full structure)\n")
    print("| library | held out | terms u / v / r | γ | u / v / r error std | fixed "
          f"{fixed} |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for library in (fixed, "blanke-race+race-damping+abkowitz3"):
        for held, log in logs.items():
            train = [x for k, x in logs.items() if k != held]
            _, cutoff = fit_as_identify(train, library)
            train = train if cutoff is None else [lowpass(x, cutoff) for x in train]
            sel = select(train, library=library, cv="logo")
            chosen = validate(sel.model, [log])[0].metrics
            ref = validate(fit_as_identify([x for k, x in logs.items() if k != held], fixed)[0],
                           [log])[0].metrics  # fmt: skip
            terms = " / ".join(str(len(sel.model.structure.terms.get(d, ()))) for d in "uvr")
            print(f"| {library} | {held} | {terms} | {sel.gamma:g} | "
                  + " / ".join(f"{chosen[s]['std']:.4f}" for s in "uvr") + " | "
                  + " / ".join(f"{ref[s]['std']:.4f}" for s in "uvr") + " |")


def all_logs() -> None:
    """Each structure identified on all three real KVLCC2 zig-zags (as identify does): the
    predictions no log here can check, the 10/10 zig-zags and the 35° turn, against the
    predictions from the MARIN 20/20 run alone (``real_data``): how much they rest on the
    training set."""
    data = Path(__file__).resolve().parents[2] / "shared" / "data"
    if not data.is_dir():
        return
    logs = _real_logs(data)
    ship = kvlcc2()
    kw = {"speed": float(logs["MARIN zz 20/20"]["u"].iloc[0]), "steering": ship.steering}
    print("\nKVLCC2 identified on all three real zig-zags: the 10/10 zig-zags (first / second "
          "overshoot [deg]) and the 35° turn to starboard\n")  # fmt: skip
    print("| structure | prefilter | 10/10 starboard first | 10/10 port first | 35° advance (m) | "
          "TD (m) | steady speed (m/s) | steady r (rad/s) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for structure in REAL:
        model, cutoff = fit_as_identify(list(logs.values()), structure)
        cells = []
        for c in HELD_ZIGZAGS:
            ind = _zigzag(model, *c, **kw).indices
            cells.append(", ".join(f"{ind.get(k) or math.nan:.1f}" for k in OVERSHOOTS))
        tc = _turn(model, "starboard", **kw)
        ind = {} if tc.diverged or not tc.indices else tc.indices
        turn = [ind.get(k) for k in ("advance", "tactical_diameter", "steady_speed",
                                     "steady_yaw_rate")]  # fmt: skip
        print(f"| {structure} | {'none' if cutoff is None else f'{cutoff:.3g} Hz'} | "
              + " | ".join(cells) + " | "
              + " | ".join("diverged" if x is None else f"{x:.4g}" for x in turn) + " |")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope and plausibility warnings of the candidates
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    mmg(int(sys.argv[1]) if len(sys.argv) > 1 else 10,
        float(sys.argv[2]) if len(sys.argv) > 2 else 0.25)  # fmt: skip
    real_data()
    leave_one_log_out()
    nested_selection()
    all_logs()
    prior_effect()
