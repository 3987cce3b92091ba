"""Where the 35° turn's steady state comes from, and a hull whose nonlinear terms come from the
particulars (issue #10): the MMG model of the KVLCC2 (reference-ships.md §2) split into its
hull's linear and nonlinear forces and the rest along its own 20/20 zig-zag and in its steady
35° turn; then the sway–yaw hull written in Kijima et al.'s form, with their regression of the
derivatives on L, B, d and Cb as a prior or held, beside ``--rudder-normal``, judged on what the
models were not fitted to: the MMG model as the truth (its 10/10 zig-zags and 35° turns), the
real KVLCC2 (the unseen MARIN and HSVA runs; the MMG model's turn) and the Esso Osaka (its two
35° turns and four random runs).

Kijima, K., Katsuno, T., Nakiri, Y. and Furukawa, Y. (1990), On the manoeuvring performance of a
ship with the parameter of loading condition, J. Soc. Naval Arch. Japan 168, 141–148: with
β = −v′ the drift angle, r′ = rL/U, k = 2d/L,

    Y′ = Y′β β + Y′r r′ + Y′ββ β|β| + Y′rr r′|r′| + Y′ββr β² r′ + Y′βrr β r′²   (N′ alike)
    Y′β = πk/2 + 1.4 Cb B/L          Y′r − (m′ + m′x) = −1.5 Cb B/L
    Y′ββ = 2.5 d(1 − Cb)/B + 0.5     Y′rr = 0.343 d Cb/B − 0.07
    Y′ββr = 1.5 d Cb/B − 0.65        Y′βrr = 5.95 d(1 − Cb)/B
    N′β = k                          N′r = −0.54 k + k²
    N′ββ = −0.96 d(1 − Cb)/B + 0.066 N′rr = 0.5 Cb B/L − 0.09
    N′ββr = −(57.5 (Cb B/L)² − 18.4 Cb B/L + 1.6)      N′βrr = −(0.5 d Cb/B − 0.05)

in the MMG prime system (½ρLdU², ½ρL²dU²). Written in shipid's terms exactly (U v, U r, |v|v,
|r|r, U r sin²β, r² sin β: sin β = −v/U), through the Clarke prior's mass matrix
(``shipid.identification.priors``), they are a prior or held values (``--bound`` both ways) of
those terms; the rudder is ``--rudder-normal``'s. Tried and not kept (the section of
benchmarks/README.md says why).

Run: .venv/bin/python benchmarks/study_kijima_hull.py
"""

from __future__ import annotations

import importlib
import itertools
import json
import math
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from cli_models import model_by_cli
from esso_logs import held_out_files
from kvlcc2_logs import kvlcc2_logs
from study_esso_rudder_normal import FORMAT, _judged
from study_kvlcc2_turn import (
    MMG_PARTICULARS,
    PARTICULARS,
    READ,
    TRAINING,
    _cell,
    _turn_and_zigzag,
    unseen_runs,
)
from study_structure import HELD_ZIGZAGS, PAPER_IMU, _turn, _zigzag, held_out_errors
from study_structure import TRAINING as MMG_TRAINING

from shipid.data.formats import ESSO_OSAKA_MODEL
from shipid.data.io import write_log
from shipid.data.particulars import Particulars, read_particulars
from shipid.dynamics.model import ManoeuvringModel, ModelStructure, get_structure
from shipid.dynamics.terms import parse_term
from shipid.identification.priors import clarke_derivatives

KIJIMA_TERMS = ("U*v", "U*r", "|v|*v", "|r|*r", "U*r*sin(beta)^2", "r^2*sin(beta)")
HULL_SIGNALS = {"u", "v", "r", "U", "beta"}


def kijima_derivatives(p: Particulars) -> dict[str, float]:
    """Kijima et al. (1990) in the v′ form (v′ = −β): Y′ = Yv v′ + Yr r′ + Yvv v′|v′| + Yrr r′|r′|
    + Yvvr v′² r′ + Yvrr v′ r′², N′ alike; Yr net of the rigid body's (m′ + m′x) u′ r′."""
    L, B, d, Cb = p.length, p.beam, p.draught, p.block_coefficient
    k, cbl = 2 * d / L, Cb * B / L
    return {"Yv": -(math.pi / 2 * k + 1.4 * cbl), "Yr": -1.5 * cbl,
            "Yvv": -(2.5 * d * (1 - Cb) / B + 0.5), "Yrr": 0.343 * d * Cb / B - 0.07,
            "Yvvr": 1.5 * d * Cb / B - 0.65, "Yvrr": -(5.95 * d * (1 - Cb) / B),
            "Nv": -k, "Nr": -0.54 * k + k * k,
            "Nvv": 0.96 * d * (1 - Cb) / B - 0.066, "Nrr": 0.5 * cbl - 0.09,
            "Nvvr": -(57.5 * cbl**2 - 18.4 * cbl + 1.6), "Nvrr": 0.5 * d * Cb / B - 0.05}  # fmt: skip


def kijima_coefficients(p: Particulars) -> dict[str, dict[str, float]]:
    """The Kijima hull (and the rigid body's x_G m u r) as acceleration-form coefficients of
    ``KIJIMA_TERMS`` in v̇ and ṙ, through the Clarke prior's mass matrix."""
    c, kd = clarke_derivatives(p), kijima_derivatives(p)
    rho, L, d = p.rho, p.length, p.draught
    m = p.mass if p.mass is not None else rho * p.volume
    xg = p.xg or 0.0
    q = 0.5 * rho
    M = np.array([[m - q * L**3 * c["Yvdot"], m * xg - q * L**4 * c["Yrdot"]],
                  [m * xg - q * L**4 * c["Nvdot"],
                   m * (0.25 * L) ** 2 + m * xg**2 - q * L**5 * c["Nrdot"]]])  # fmt: skip
    f = q * L * d
    # Per term, in the order of KIJIMA_TERMS: U²v′ = U v, U²r′ = L U r, U²v′|v′| = v|v|,
    # U²r′|r′| = L² r|r|, U²v′²r′ = L U r sin²β, U²v′r′² = −L² r² sin β.
    powers = (0, 1, 0, 2, 1, 2)
    forces = {dof: [f * L ** (pw + (dof == "N")) * s * kd[dof + name] for name, pw, s in
                    zip(("v", "r", "vv", "rr", "vvr", "vrr"), powers, (1, 1, 1, 1, 1, -1),
                        strict=True)] for dof in ("Y", "N")}  # fmt: skip
    forces["N"][1] -= xg * m
    acc = np.linalg.solve(M, np.array([forces["Y"], forces["N"]]))
    return {dof: dict(zip(KIJIMA_TERMS, map(float, acc[i]), strict=True))
            for i, dof in enumerate(("v", "r"))}  # fmt: skip


def with_kijima_hull(name: str) -> str:
    """``name``'s structure with its second-degree sway–yaw hull terms (u v, u r, |v|v, ...) in
    Kijima's form, as a ``--model`` text."""
    terms = dict(get_structure(name).terms)
    for dof in ("v", "r"):
        have = list(terms[dof])
        hull = [t for t in have if _second_degree_hull(t)]
        at = have.index(hull[0])
        kept = [t for t in have if t not in hull]
        terms[dof] = tuple(kept[:at] + [parse_term(t).text for t in KIJIMA_TERMS] + kept[at:])
    return "; ".join(f"{d}: {', '.join(t)}" for d, t in terms.items())


def _second_degree_hull(text: str) -> bool:
    term = parse_term(text)
    signals = set(term.signals)
    return (bool(signals) and signals <= HULL_SIGNALS and bool(signals & {"v", "r", "beta"})
            and sum(term.degree_in(s) for s in ("u", "v", "r", "U")) == 2)  # fmt: skip


def held(coefficients: dict, terms=KIJIMA_TERMS[2:]) -> list[str]:
    """``--bound`` both ways at Kijima's values of ``terms`` (the nonlinear ones)."""
    out = []
    for dof, values in coefficients.items():
        for term in terms:
            out += ["--bound", f"{dof}: {term} >= {values[term]!r}",
                    "--bound", f"{dof}: {term} <= {values[term]!r}"]  # fmt: skip
    return out


def _prior_file(coefficients: dict, path: str) -> str:
    structure = ModelStructure("Kijima et al. (1990)", {d: tuple(c) for d, c in
                                                          coefficients.items()})
    ManoeuvringModel(structure, coefficients).save(path)
    return path


def force_split() -> None:
    """The MMG model's yaw acceleration split into its hull's linear and nonlinear parts, the
    rigid body's u·r and the rest (rudder and propeller), rms along its own 20/20 zig-zag
    (starboard first) and in its steady 35° turn."""
    mmg = importlib.import_module("shipid.vessels.kvlcc2")
    from shipid.vessels.kvlcc2 import trimmed_revolutions

    ship = mmg.kvlcc2()
    n = trimmed_revolutions(ship.approach_speed)
    c = ship.dynamics.packed  # masses and the mass matrix's inverse

    def split(u, v, r, delta):
        U = np.hypot(u, v)
        vp, rp = v / U, r * mmg.L / U
        q = 0.5 * mmg.RHO * mmg.L * mmg.D_DRAUGHT * U * U
        linear = (q * (mmg.YV * vp + mmg.YR * rp), q * mmg.L * (mmg.NV * vp + mmg.NR * rp))
        nonlinear = (q * (mmg.YVVV * vp**3 + mmg.YVVR * vp**2 * rp + mmg.YVRR * vp * rp**2
                          + mmg.YRRR * rp**3),
                     q * mmg.L * (mmg.NVVV * vp**3 + mmg.NVVR * vp**2 * rp
                                  + mmg.NVRR * vp * rp**2 + mmg.NRRR * rp**3))  # fmt: skip
        rigid = (-(c.m + c.mx) * u * r, -c.x_g * c.m * u * r)
        yaw = {k: c.inv10 * y + c.inv11 * nn for k, (y, nn) in
               (("hull, linear", linear), ("hull, nonlinear", nonlinear), ("rigid body", rigid))}
        total = mmg.KVLCC2Dynamics(n).derivatives(np.column_stack([u, v, r]), delta)[:, 2]
        yaw["rudder (the rest)"] = total - sum(yaw.values())
        return yaw

    zz = _zigzag(ship, 20, 20, "starboard").log
    tc = _turn(ship, "starboard").log.iloc[-50:]
    cases = {"20/20 zig-zag, rms": zz, "steady 35° turn": tc}
    rows = {label: split(*(log[c].to_numpy() for c in ("u", "v", "r", "delta")))
            for label, log in cases.items()}  # fmt: skip
    print("The MMG model's yaw acceleration [rad/s²] by part (rms over the zig-zag; mean over the "
          "steady turn's last 10 s)\n")  # fmt: skip
    parts = list(next(iter(rows.values())))
    print("| state | " + " | ".join(parts) + " | nonlinear / rudder |")
    print("|---|" + "---|" * (len(parts) + 1))
    for label, yaw in rows.items():
        agg = ((lambda x: float(np.sqrt(np.mean(x**2)))) if "rms" in label
               else (lambda x: float(np.mean(x))))  # fmt: skip
        values = [agg(yaw[k]) for k in parts]
        ratio = abs(values[1]) / abs(values[3])
        print(f"| {label} | " + " | ".join(f"{x:+.5f}" for x in values) + f" | {ratio:.2f} |")
    for label, log in cases.items():
        U = np.hypot(log["u"], log["v"])
        print(f"{label}: largest |v′| {np.max(np.abs(log['v'] / U)):.3f}, |r′| "
              f"{np.max(np.abs(log['r'] * mmg.L / U)):.3f}")
    # The hull's nonlinear yaw moment N′ at the steady turn: the MMG model's and Kijima's.
    last = tc.iloc[-1]
    U = math.hypot(last["u"], last["v"])
    vp, rp = last["v"] / U, last["r"] * mmg.L / U
    kd = kijima_derivatives(Particulars(**MMG_PARTICULARS))
    own = mmg.NVVV * vp**3 + mmg.NVVR * vp**2 * rp + mmg.NVRR * vp * rp**2 + mmg.NRRR * rp**3
    kij = (kd["Nvv"] * vp * abs(vp) + kd["Nrr"] * rp * abs(rp) + kd["Nvvr"] * vp**2 * rp
           + kd["Nvrr"] * vp * rp**2)  # fmt: skip
    print(f"the hull's nonlinear N′ in the steady turn (v′ {vp:.3f}, r′ {rp:.3f}): the MMG "
          f"model's {own:.4f}, Kijima's {kij:.4f}")


VARIANTS = ("plain", "rn", "kijima", "kijima rn", "kijima rn held", "kijima rn prior")


def _argv(variant: str, name: str, particulars: str, coefficients: dict, prior: str) -> list:
    """The ``identify`` options of a variant of the structure ``name``."""
    kijima = variant.startswith("kijima")
    argv = ["--model", with_kijima_hull(name) if kijima else name, "--particulars", particulars]
    if " rn" in f" {variant}":
        argv.append("--rudder-normal")
    if variant.endswith("held"):
        argv += held(coefficients)
    if variant.endswith("prior"):
        argv += ["--prior", prior, "--gamma", "auto"]
    return argv


def mmg_truth(folder: Path, seeds: int = 6) -> None:
    """As study_kvlcc2_turn.mmg_truth: the MMG model's 20/20 zig-zags through 0.25 × the paper's
    IMU, its rps logged, each model made by ``shipid identify``; judged on its 10/10 zig-zags and
    35° turns."""
    from shipid.vessels import kvlcc2
    from shipid.vessels.kvlcc2 import trimmed_revolutions

    ship = kvlcc2()
    rps = trimmed_revolutions(ship.approach_speed)
    truth_zz = {c: _zigzag(ship, *c).indices for c in HELD_ZIGZAGS}
    truth_tc = {s: _turn(ship, s).indices for s in ("starboard", "port")}
    keys = ("tactical_diameter", "steady_yaw_rate", "steady_speed")
    sensor = PAPER_IMU.scaled(0.25)
    particulars = str(folder / "mmg.json")
    Path(particulars).write_text(json.dumps(MMG_PARTICULARS), encoding="utf-8")
    coefficients = kijima_coefficients(Particulars(**MMG_PARTICULARS))
    prior = _prior_file(coefficients, str(folder / "kijima.json"))
    print(f"\nThe MMG model as the truth ({seeds} seeds; mean error (mean |error|) over them)\n")
    print("| trained on | model | 10/10 overshoots stbd 1st, 2nd, port 1st, 2nd [deg] | 35° "
          "tactical diameter stbd, port [%] | steady yaw rate [%] | steady speed [%] | failed |")
    print("|---|---|---|---|---|---|---|")
    for n_logs, label in ((1, "20/20 to starboard"), (3, "20/20 both sides, 20/10")):
        files = [[str(write_log(sensor.apply(_zigzag(ship, *case).log, seed=100 * seed + i)
                                .assign(n=rps), folder / f"zz{seed}_{i}.csv"))
                  for i, case in enumerate(MMG_TRAINING)][:n_logs] for seed in range(seeds)]
        for variant in VARIANTS:
            argv = ["identify", *_argv(variant, "blanke-speed", particulars, coefficients, prior)]
            rows, failed = [], 0
            for paths in files:
                model = model_by_cli(argv, paths, str(folder / "m.json"))
                if model is None:
                    failed += 1
                    continue
                rows.append(held_out_errors(model, ship, truth_zz, truth_tc, rps, keys))
            e = np.array(rows) if rows else np.full((1, 10), np.nan)
            print(f"| {label} | blanke-speed {variant} | {_cell(e, range(4), '+.1f')} | "
                  f"{_cell(e, (4, 7), '+.0f')} | {_cell(e, (5, 8), '+.0f')} | "
                  f"{_cell(e, (6, 9), '+.0f')} | {failed} |")  # fmt: skip


def real_kvlcc2(folder: Path) -> None:
    """Trained on the MARIN 20/20 run (particulars from ship_data.yml), judged on the unseen
    runs and against the MMG model's 35° turn and 10°/10° zig-zag, as study_kvlcc2_turn."""
    coefficients = kijima_coefficients(read_particulars(PARTICULARS))
    prior = _prior_file(coefficients, str(folder / "kijima-kvlcc2.json"))
    held_out = {k: v for k, v in kvlcc2_logs(0.2).items() if k != "MARIN zz 20°"}
    print("\nThe real KVLCC2, trained on MARIN zz 20°\n")
    print("| model | MARIN zz −20°: r, overshoots | HSVA 20/10: r, overshoots | advance [m] | "
          "tactical diameter [m] | steady speed [m/s] | steady yaw rate [rad/s] | "
          "10°/10° overshoots [°] |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    print("| MMG model | | | " + " | ".join(_turn_and_zigzag("kvlcc2", folder)) + " |")
    for variant in VARIANTS:
        out = str(folder / "model.json")
        argv = ["identify", *READ, *_argv(variant, "blanke-speed", PARTICULARS, coefficients,
                                          prior)]  # fmt: skip
        model = model_by_cli(argv, [str(TRAINING)], out)
        if model is None:
            print(f"| blanke-speed {variant} | failed | | | | | | |")
            continue
        cells = unseen_runs(model, held_out) + _turn_and_zigzag(out, folder)
        print(f"| blanke-speed {variant} | " + " | ".join(cells) + " |")


def esso(folder: Path) -> None:
    """``blanke-rps+wind`` (the default's fallback for logs at several rps) with each variant,
    trained on the nine zig-zag files and on every pair, judged on the two 35° turns and the
    four random runs as study_esso_rudder_normal."""
    files = held_out_files()
    if files is None:
        return
    zigzags, turns, randoms, logs = files
    particulars = str(folder / "esso.json")
    Path(particulars).write_text(json.dumps(ESSO_OSAKA_MODEL), encoding="utf-8")
    coefficients = kijima_coefficients(Particulars(**ESSO_OSAKA_MODEL))
    prior = _prior_file(coefficients, str(folder / "kijima-esso.json"))
    print("\nThe Esso Osaka, blanke-rps+wind\n")
    print("| trained on | model | 35° turns' TD off: median, mean |abs| [%] | steady r off: "
          "median, mean |abs| [%] | random runs' r error / std: median, mean | diverged |")
    print("|---|---|---|---|---|---|")
    for label, sets in (("nine zig-zags", [list(zigzags)]),
                        ("two files (36 pairs)", [list(p) for p in
                                                  itertools.combinations(zigzags, 2)])):
        for variant in VARIANTS:
            argv = ["identify", *FORMAT, *_argv(variant, "blanke-rps+wind", particulars,
                                                coefficients, prior)]  # fmt: skip
            td, r, rand, diverged, failed = [], [], [], 0, 0
            for train in sets:
                model = model_by_cli(argv, [str(p) for p in train], str(folder / "m.json"))
                if model is None:
                    failed += 1
                    continue
                errors, ratios, div = _judged(model, turns, randoms, logs)
                td, r, rand, diverged = td + errors[0::2], r + errors[1::2], rand + ratios, \
                    diverged + div
            cells = [f"{np.nanmedian(x):+.0f}, {np.nanmean(np.abs(x)):.0f}" if len(x) else "–"
                     for x in (np.array(td), np.array(r))]  # fmt: skip
            cells.append(f"{np.median(rand):.2f}, {np.mean(rand):.2f}" if rand else "–")
            note = f" ({failed} failed)" if failed else ""
            print(f"| {label} | {variant} | " + " | ".join(cells)
                  + f" | {diverged} of {len(sets)}{note} |")


def main() -> None:
    import os

    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    force_split()
    with tempfile.TemporaryDirectory() as scratch:
        mmg_truth(Path(scratch))
        if TRAINING.exists():
            real_kvlcc2(Path(scratch))
        esso(Path(scratch))
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main()
