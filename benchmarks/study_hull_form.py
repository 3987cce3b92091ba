"""What sets the straight-line stability of a model fitted to zig-zags (issue #10): the form of
the hull's nonlinear damping, not the noise.

Models of the KVLCC2's 20/20 zig-zags come out strongly course-unstable (Nomoto T2 −14 to −19 s
from the real MARIN and HSVA runs), and so do those of its MMG model's own zig-zags, whose truth
is all but neutral (T2 −2398 s): their 10°/10° overshoots come high. The script fits the same
logs with ``blanke-race+race-damping`` as it stands (the hull's nonlinear sway and yaw damping in
moduli, |v|v and |v|r, cross-flow drag's form) and with those terms written cubic (v³ and v²r,
the MMG model's form), as ``identify`` fits them (prefilter chosen from the data), on

0. the paper's scale ship (a stable hull in moduli; ``blanke`` and the same written cubic) from
   its 20/20 zig-zag through the paper's IMU: both sway–yaw eigenvalues;
1. the KVLCC2's MMG model (a cubic hull), noise-free and through a quarter of the paper's IMU,
   from zig-zags of 20°, 10° and 5°: the largest sway–yaw eigenvalue at the approach (1/s; T2 =
   −1/λ) against the truth's, and the 10°/10° overshoots of the fits of 20/20 zig-zags;
2. the Esso 190 000 dwt tanker (a hull in moduli, Norrbin's; the ``tanker`` vessel at 80 rpm),
   noise-free and through a ship's sensors at sea, from its 20/20 zig-zag: the same;
3. the real KVLCC2, each run alone: the eigenvalue, the other two runs' free-run yaw rate error
   and closed-loop overshoots, and the 10°/10° zig-zags no run here holds.

Run: .venv/bin/python benchmarks/study_hull_form.py
"""

from __future__ import annotations

import math
import os
import time
import warnings

import numpy as np
from study_structure import HELD_ZIGZAGS, OVERSHOOTS, _zigzag, fit_as_identify
from study_tanker import SEA_SENSORS, ship_at

from shipid.control.linear import linearise
from shipid.dynamics.model import ModelStructure, get_structure
from shipid.dynamics.terms import parse_term
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, kvlcc2
from shipid.vessels.kvlcc2 import trimmed_revolutions

STRUCTURE = "blanke-race+race-damping"
# Each modulus term of the hull's damping and the cubic term of the same parity in v and r.
CUBIC = {"|v|v": "v^3", "|v|r": "v^2*r", "|r|r": "r^3", "v*|r|": "v*r^2"}


def cubic(structure: str) -> ModelStructure:
    """``structure`` with its modulus hull terms written cubic (``CUBIC``)."""
    s = get_structure(structure)
    swap = {parse_term(k).text: v for k, v in CUBIC.items()}
    return ModelStructure(f"{s.name}, hull cubic", {
        dof: tuple(swap.get(parse_term(t).text, t) for t in terms)
        for dof, terms in s.terms.items()})


FORMS = {"moduli (as it stands)": STRUCTURE, "cubic": cubic(STRUCTURE)}


def largest_eigenvalue(model, speed: float, rps: float | None = None) -> float:
    """The largest real part of the sway–yaw block's eigenvalues, linearised about straight
    running at ``speed`` (trimmed: the rudder that holds the ship straight)."""
    return float(np.linalg.eigvals(linearise(model, speed, rps)["A"][1:, 1:]).real.max())


def _t2(lam: float) -> str:
    return f"{lam:+.4f} (T2 {-1 / lam:+.0f} s)" if abs(lam) > 1e-9 else f"{lam:+.4f}"


def _overshoots(model, speed, steering, rps, cases) -> list[float]:
    out = []
    for case in cases:
        ind = _zigzag(model, *case, speed=speed, steering=steering, rps=rps).indices or {}
        out += [ind.get(k) or math.nan for k in OVERSHOOTS]
    return out


def paper_ship(seeds: int = 3) -> None:
    """The paper's scale ship (its truth in moduli, stable): ``blanke`` and the same written
    cubic from its noisy 20/20 zig-zag, as the demo's training trial."""
    from shipid.vessels import get_vessel

    ship = get_vessel("scale-ship")
    speed = ship.approach_speed
    clean = zigzag(ship, 20, 20, duration=90, dt=0.2).log
    eig = np.linalg.eigvals(linearise(ship, speed)["A"][1:, 1:]).real
    print(f"\n0. The paper's scale ship (hull in moduli), its 20/20 zig-zag through the paper's IMU: "
          f"sway–yaw eigenvalues at {speed:.3g} m/s, truth {eig.max():+.3f} and {eig.min():+.3f} "
          "1/s\n")
    print("| seed | " + " | ".join(f"{f}: eigenvalues [1/s]" for f in FORMS) + " |")
    print("|---" * (1 + len(FORMS)) + "|")
    for seed in range(seeds):
        log = PAPER_IMU.apply(clean, seed=seed)
        cells = []
        for form in ("blanke", cubic("blanke")):  # FORMS for the paper's structure
            model, _ = fit_as_identify([log], form)
            e = np.linalg.eigvals(linearise(model, speed)["A"][1:, 1:]).real
            cells.append(f"{e.max():+.3f}, {e.min():+.3f}")
        print(f"| {seed} | " + " | ".join(cells) + " |")


def mmg_truth(seeds: int = 2) -> None:
    ship = kvlcc2()
    rps = trimmed_revolutions(ship.approach_speed)
    speed = ship.approach_speed
    truth = largest_eigenvalue(ship, speed, rps)
    truth_zz = _overshoots(ship, speed, ship.steering, None, HELD_ZIGZAGS)
    sets = {"20/20 to starboard": [(20, 20, "starboard")],
            "20/20 both sides": [(20, 20, "starboard"), (20, 20, "port")],
            "20/20 and 10/10": [(20, 20, "starboard"), (10, 10, "port")],
            "10/10 to starboard": [(10, 10, "starboard")],
            "5/5 to starboard": [(5, 5, "starboard")]}  # fmt: skip
    print(f"\n1. The KVLCC2's MMG model (cubic hull): largest sway–yaw eigenvalue at "
          f"{speed:.3f} m/s, {rps:.4g} rps, truth {_t2(truth)}; 10°/10° overshoots (starboard "
          "first, second; port first, second): truth "
          + ", ".join(f"{x:.1f}°" for x in truth_zz) + "\n")
    print("| trained on | noise | " + " | ".join(f"{f}: eigenvalue [1/s]" for f in FORMS)
          + " | " + " | ".join(f"{f.split(' (')[0]}: 10°/10° overshoots' error [°]"
                             for f in FORMS) + " |")
    print("|---" * (2 + 2 * len(FORMS)) + "|")
    for name, cases in sets.items():
        clean = [_zigzag(ship, *c).log.assign(n=rps) for c in cases]
        for noise, seed in [(0.0, 0)] + [(0.25, s) for s in range(seeds)]:
            logs = clean if noise == 0 else [
                PAPER_IMU.scaled(noise).apply(log, seed=100 * seed + i).assign(n=rps)
                for i, log in enumerate(clean)]
            lams, zz = [], []
            for form in FORMS.values():
                model, _ = fit_as_identify(logs, form)
                lams.append(_t2(largest_eigenvalue(model, speed, rps)))
                if name.startswith("20/20"):
                    e = np.subtract(_overshoots(model, speed, ship.steering, rps, HELD_ZIGZAGS),
                                    truth_zz)  # fmt: skip
                    zz.append(", ".join(f"{x:+.1f}" for x in e))
                else:
                    zz.append("–")  # trained on a 10°/10° or smaller
            label = "none" if noise == 0 else f"{noise:g} × IMU, seed {seed}"
            print(f"| {name} | {label} | " + " | ".join(lams) + " | " + " | ".join(zz) + " |")


def tanker_truth(seeds: int = 2) -> None:
    rpm = 80.0
    ship = ship_at(rpm)
    rps = rpm / 60.0
    speed = ship.approach_speed

    def zz(model, a, h, side, **kw):
        return zigzag(model, a, h, first=side, duration=1500, dt=1.0, approach=20, speed=speed,
                      steering=ship.steering, **kw)

    held = ((10, 10, "starboard"), (10, 10, "port"), (20, 20, "port"))
    truth_zz = [zz(ship, *c).indices[k] for c in held for k in OVERSHOOTS]
    # The tanker's own dynamics hold its rpm: linearised without a propeller speed.
    truth = largest_eigenvalue(ship, speed)
    print(f"\n2. The Esso 190 000 dwt tanker (hull in moduli) at {rpm:g} rpm, {speed:.2f} m/s: "
          f"truth {_t2(truth)}; trained on its 20/20 zig-zag to starboard; overshoots of its "
          "10°/10° to starboard and to port and 20°/20° to port: truth "
          + ", ".join(f"{x:.1f}°" for x in truth_zz) + "\n")
    print("| noise | " + " | ".join(f"{f}: eigenvalue [1/s]" for f in FORMS) + " | "
          + " | ".join(f"{f.split(' (')[0]}: overshoots' error [°]" for f in FORMS) + " |")
    print("|---" * (1 + 2 * len(FORMS)) + "|")
    clean = zz(ship, 20, 20, "starboard").log.assign(n=rps)
    for noise, seed in [(0.0, 0)] + [(1.0, s) for s in range(seeds)]:
        log = clean if noise == 0 else SEA_SENSORS.apply(clean, seed=seed).assign(n=rps)
        lams, errs = [], []
        for form in FORMS.values():
            model, _ = fit_as_identify([log], form)
            lams.append(_t2(largest_eigenvalue(model, speed, rps)))
            got = [(zz(model, *c, rps=rps).indices or {}).get(k) or math.nan
                   for c in held for k in OVERSHOOTS]  # fmt: skip
            errs.append(", ".join(f"{x:+.1f}" for x in np.subtract(got, truth_zz)))
        label = "none" if noise == 0 else f"a ship's sensors at sea, seed {seed}"
        print(f"| {label} | " + " | ".join(lams) + " | " + " | ".join(errs) + " |")


def real_kvlcc2() -> None:
    from kvlcc2_logs import DATA, kvlcc2_logs

    from shipid.evaluation.validate import validate

    if not DATA.is_dir():
        print("\n../shared/data is absent: no real-data rows")
        return
    logs = kvlcc2_logs()
    steering = kvlcc2().steering
    print("\n3. The real KVLCC2, each run alone (Δk 0.2 s): largest eigenvalue at the run's "
          "approach; on each other run the free-run yaw rate error std [rad/s] and the "
          "closed-loop overshoots (measured); the 10°/10° zig-zags to starboard and to port "
          "from the run's approach with the KVLCC2's gear (no such run is here)\n")
    print("| trained on | hull | eigenvalue [1/s] | held out: r error std; overshoots (measured) "
          "| 10°/10° overshoots (stbd; port) |")
    print("|---|---|---|---|---|")
    for name, log in logs.items():
        speed = float(log["u"].iloc[:20].mean())
        held = [h for h in logs if h != name]
        for form_name, form in FORMS.items():
            model, _ = fit_as_identify([log], form)
            cells = []
            for v in validate(model, [logs[h] for h in held], held):
                c, m = v.indices["closed_loop"], v.indices["measured"]
                cells.append(f"{v.name}: {v.metrics['r']['std']:.4f}; "
                             f"{c[OVERSHOOTS[0]]:.1f}°, {c[OVERSHOOTS[1]]:.1f}° "
                             f"({m[OVERSHOOTS[0]]:.1f}°, {m[OVERSHOOTS[1]]:.1f}°)")
            ten = _overshoots(model, speed, steering, None, HELD_ZIGZAGS)
            print(f"| {name} | {form_name} | {_t2(largest_eigenvalue(model, speed))} | "
                  + "; ".join(cells) + f" | {ten[0]:.1f}°, {ten[1]:.1f}°; {ten[2]:.1f}°, "
                  f"{ten[3]:.1f}° |")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # the MARIN yaw rate's offset (study_gyro_offset.py)
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    paper_ship()
    mmg_truth()
    tanker_truth()
    real_kvlcc2()
    print(f"\n{time.perf_counter() - t0:.0f} s")
