"""The wind's terms of one Esso Osaka zig-zag file (issue #10): what the default ``identify``
of one file loses in its five wind coefficients, each fitted from one file's gusts.

The pond's true wind, 1.3–2.4 m/s in the zig-zag files, is three to eleven times the ship's
speed (medians), so the default holds
the relative wind's load, ``U_A² cos γ_A`` in surge and ``U_A² sin γ_A``, ``U_A² sin 2γ_A`` in
sway and yaw. The script

1. fits each zig-zag file alone and the nine together (the default ``identify``) and prints
   their wind coefficients, with how far the single files' spread;
2. prints two estimates of them from the dataset's projected areas (A_T 0.135 m², A_L 0.520
   m²), each force over the mass with a rough added mass: a textbook one (C_X 0.6 on A_T, C_Y
   0.8 on A_L, the lateral load's centre 5 % of the length aft of midships, no sin 2γ_A; the
   yaw's lever set after the pooled fits had shown its sign) and Blendermann's (1994) published
   coefficients for a loaded tanker (C_D,t 0.70, C_D,l 0.90 ahead and 0.55 astern, δ 0.40, as
   Fossen's handbook gives them), projected onto the five terms by least squares over every
   wind angle, with the lateral area's centroid, which the dataset does not give, at midships
   and 5 % aft;
3. judges each file's default fit as ``study_crossflow.py`` judges (the other zig-zags and the
   two 35° turns, and the random runs) as it is, with the two signs physics fixes bounded (a
   head wind holds the ship back, a wind from starboard pushes it to port), and with the wind's
   coefficients held at those estimates, at multiples of the first, and with the forces held
   and the yaw's two terms fitted.

With ``pairs``: every pair of the files, the default and the first estimate held.

Run: .venv/bin/python benchmarks/study_esso_wind_terms.py [pairs]
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import warnings

import numpy as np
from esso_logs import DATA
from study_crossflow import _fit, esso

from shipid.identification.identify import material_wind
from shipid.reporting.modelfile import load_model
from shipid.trials.reading import read_trial_log

RHO_AIR = 1.2  # kg/m³
A_T, A_L, LENGTH = 0.135, 0.520, 3.0  # m², m², m (the dataset's README)
MASS = 244.6  # kg
# Added masses and inertia, rough: m_x 5 % of m, m_y as m, I_z + J_z twice m (L/4)².
SURGE_MASS, SWAY_MASS, YAW_INERTIA = 1.05 * MASS, 2.0 * MASS, 2.0 * MASS * (LENGTH / 4) ** 2
C_X, C_Y, LEVER = 0.6, 0.8, -0.05  # the lateral load's centre, in lengths forward of midships
# Blendermann (1994), a loaded tanker: C_D,t, C_D,l over A_T with the wind ahead and astern, δ.
BLENDERMANN_TANKER = (0.70, 0.90, 0.55, 0.40)
TERMS = (("u", "U_A^2*cos(gamma_A)"), ("v", "U_A^2*sin(gamma_A)"), ("v", "U_A^2*sin(2*gamma_A)"),
         ("r", "U_A^2*sin(gamma_A)"), ("r", "U_A^2*sin(2*gamma_A)"))  # fmt: skip
FITTED = {("u", "wind_speed^2*cos(wind_angle)"): ("u", "U_A^2*cos(gamma_A)"),
          ("v", "wind_speed^2*sin(wind_angle)"): ("v", "U_A^2*sin(gamma_A)"),
          ("v", "wind_speed^2*sin(2*wind_angle)"): ("v", "U_A^2*sin(2*gamma_A)"),
          ("r", "wind_speed^2*sin(wind_angle)"): ("r", "U_A^2*sin(gamma_A)"),
          ("r", "wind_speed^2*sin(2*wind_angle)"): ("r", "U_A^2*sin(2*gamma_A)")}  # fmt: skip


def _held(dof: str, term: str, value: float) -> list[str]:
    """``--bound`` both ways at one value: the coefficient given, not fitted."""
    return ["--bound", f"{dof}: {term} <= {value:.4g}", "--bound", f"{dof}: {term} >= {value:.4g}"]


def _flags(coefficients: dict, terms=TERMS) -> list[str]:
    return [flag for key in terms for flag in _held(*key, coefficients[key])]


def aerodynamic() -> dict[tuple[str, str], float]:
    """{(dof, term): coefficient} of the textbook estimate (accelerations per (m/s)² of
    relative wind)."""
    q = 0.5 * RHO_AIR
    side = -q * A_L * C_Y  # N per (m/s)² with the wind from starboard: toward port
    return {TERMS[0]: -q * A_T * C_X / SURGE_MASS, TERMS[1]: side / SWAY_MASS, TERMS[2]: 0.0,
            TERMS[3]: LEVER * LENGTH * side / YAW_INERTIA, TERMS[4]: 0.0}  # fmt: skip


def blendermann(centroid: float) -> dict[tuple[str, str], float]:
    """Blendermann's (1994) loaded tanker projected onto the five terms (least squares over the
    relative wind's angle), the lateral area's centroid ``centroid`` lengths forward of
    midships. Its angle of attack is ours negated (γ_A: where the wind comes from, clockwise
    from the bow)."""
    cd_t, cd_ahead, cd_astern, delta = BLENDERMANN_TANKER
    gamma = np.linspace(-np.pi, np.pi, 721)
    attack = -gamma
    cd_l_af = np.where(np.abs(attack) <= np.pi / 2, cd_ahead, cd_astern)
    den = 1 - 0.5 * delta * (1 - cd_l_af * A_T / A_L / cd_t) * np.sin(2 * attack) ** 2
    c_x = -cd_l_af * np.cos(attack) / den
    c_y = cd_t * np.sin(attack) / den
    c_n = (centroid - 0.18 * (np.abs(attack) - np.pi / 2)) * c_y  # odd in the angle, as c_y
    q = 0.5 * RHO_AIR
    sway_basis = np.column_stack([np.sin(gamma), np.sin(2 * gamma)])
    (x,), _, _, _ = np.linalg.lstsq(np.cos(gamma)[:, None], q * A_T * c_x / SURGE_MASS, rcond=None)
    y = np.linalg.lstsq(sway_basis, q * A_L * c_y / SWAY_MASS, rcond=None)[0]
    n = np.linalg.lstsq(sway_basis, q * A_L * LENGTH * c_n / YAW_INERTIA, rcond=None)[0]
    return dict(zip(TERMS, (x, *y, *n), strict=True))


def _fitted_wind(files, folder: str) -> dict[tuple[str, str], float]:
    out = f"{folder}/w.json"
    assert _fit(["identify", "--format", "osaka-frt", *map(str, files)], out)
    model = load_model(out)
    return {ours: model.coefficients.get(dof, {}).get(term, 0.0)
            for (dof, term), ours in FITTED.items()}  # fmt: skip


def fitted() -> None:
    files = sorted((DATA / "zigzag").glob("*.csv"))
    print("1. The wind's coefficients fitted [m/s² (rad/s² in ṙ) per (m/s)²]\n")
    print("| fitted on | true wind, ship speed (medians) [m/s] | "
          + " | ".join(f"{d}̇ {t}" for d, t in TERMS) + " |")  # fmt: skip
    print("|---" * (len(TERMS) + 2) + "|")
    single = []
    with tempfile.TemporaryDirectory() as folder:
        for f in files:
            single.append(_fitted_wind([f], folder))
            wind, ship = material_wind([read_trial_log(f, fmt="osaka-frt")])
            print(f"| {f.stem[-8:]} | {wind:.2f}, {ship:.2f} | "
                  + " | ".join(f"{single[-1][k]:+.2e}" for k in TERMS) + " |", flush=True)  # fmt: skip
        pooled = _fitted_wind(files, folder)
    print("| the nine together | | " + " | ".join(f"{pooled[k]:+.2e}" for k in TERMS) + " |")
    print()
    for key in TERMS[:2] + TERMS[3:4]:
        values = np.array([s[key] for s in single])
        signs = np.sign(values)
        kept = np.abs(values[signs == np.sign(pooled[key])])
        print(f"{key[0]}̇ {key[1]}: single files {values.min():+.2e} to {values.max():+.2e}; "
              f"{int(np.sum(signs != np.sign(pooled[key])))} of {len(values)} of the other sign "
              f"than the nine together; of its sign, the largest {kept.max() / kept.min():.1f} "
              "times the smallest")  # fmt: skip


def main(pairs: bool = False) -> None:
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    estimate = aerodynamic()
    midships, aft = blendermann(0.0), blendermann(LEVER)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted()
        print("\n2. The estimates\n")
        print("| estimate | " + " | ".join(f"{d}̇ {t}" for d, t in TERMS) + " |")
        print("|---" * (len(TERMS) + 1) + "|")
        for name, values in (("textbook", estimate), ("Blendermann, centroid at midships",
                                                       midships),
                             ("Blendermann, centroid 5 % aft", aft)):  # fmt: skip
            print(f"| {name} | " + " | ".join(f"{values[k]:+.2e}" for k in TERMS) + " |")
        print("\n3. Each file's default identify judged on the other logs\n")
        signs = ["--bound", "u: U_A^2*cos(gamma_A) <= 0", "--bound", "v: U_A^2*sin(gamma_A) <= 0"]
        scaled = {f"the five held at {k:g} times the textbook estimate":
                  _flags({key: k * c for key, c in estimate.items()}) for k in (0, 0.5, 2)}
        configs = {"default": [], "the wind's two signs bounded": signs,
                   "the five held at the textbook estimate": _flags(estimate), **scaled,
                   "the five held at Blendermann's, centroid at midships": _flags(midships),
                   "the five held at Blendermann's, centroid 5 % aft": _flags(aft),
                   "the textbook forces held, the yaw's two fitted": _flags(estimate, TERMS[:3]),
                   "Blendermann's forces held, the yaw's two fitted": _flags(midships, TERMS[:3])}
        esso(False, configs)
        if pairs:
            print()
            esso(True, {"default": [], "the five held at the textbook estimate": _flags(estimate)})
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main("pairs" in sys.argv[1:])
