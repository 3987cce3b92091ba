"""The Esso Osaka, which has no published model, given a sister hull's: the KVLCC2's MMG model
(prime hull, propeller and rudder coefficients; another VLCC, Cb 0.80 against the Esso's 0.83)
with the Esso's own particulars, its propeller at each log's rate (``shipid mmg kvlcc2
--particulars esso.yml --rps logs``), not fitted to any Esso log; against the default ``shipid
identify`` of one zig-zag file, and the same file fitted with the KVLCC2 (carried to 3 m at
equal Froude number) or the sister's MMG file as the prior (``--prior``, the best one-file
setting of ``study_reference_prior.py``); and the sister's MMG model corrected by one zig-zag
file (``shipid correct``, `blanke-race` terms without and with the wind's, γ 1e4, 100, 1 and
chosen by the free runs of the file's held-out blocks) or by the other eight (judged on the
ninth and the turns). Each model is judged on the logs it was not fitted to, as
``study_esso_single_logs.py`` judges: the free run's yaw-rate error std over the log's spread
(the median over a model's held-out zig-zags, then over the models; a turn's steady yaw rate
barely varies, so its spread says little), the two 35° turns' tactical diameter and steady yaw
rate run closed loop (|error| median / mean, largest, over every model's two turns). The random
runs stop and reverse the propeller, which the MMG standard method does not model: the MMG rows
leave them out.

Run: .venv/bin/python benchmarks/study_esso_sister_mmg.py [pairs]
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import sys
import tempfile
import time
import warnings

import numpy as np
from esso_logs import DATA
from study_esso_single_logs import _errors, _turn_errors

from shipid.cli import main as shipid
from shipid.data.formats import ESSO_OSAKA_MODEL
from shipid.evaluation.validate import validate
from shipid.identification.correction import identify_correction
from shipid.reporting.modelfile import load_model
from shipid.trials.reading import read_trial_log
from shipid.vessels.mmg_file import read_mmg

GAMMAS = (1e4, 1e2, 1.0, "auto")
# The correction's terms: the reference's and the wind's (the MMG model has no wind force).
STRUCTURES = ("blanke-race", "blanke-race+wind")


def _quiet(argv: list[str]) -> int:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        return shipid(argv)


def _judge(model, logs: dict) -> tuple[float, list[float], list[float]]:
    """(median r error / spread over the zig-zags of ``logs``, the turns' tactical diameter
    errors [%], their steady yaw rate errors [%]). A turn's yaw rate barely varies once steady:
    its free run's error over its spread says little, and the turns are judged by their
    indices."""
    runs = [validate(model, log, start_draws=False)[0] for log in logs.values()]
    turns = [v for path, v in zip(logs, runs, strict=True) if "turn" in path.stem]
    zigzags = {p: log for p, log in logs.items() if "turn" not in p.stem}
    zz_runs = [v for path, v in zip(logs, runs, strict=True) if "turn" not in path.stem]
    return (float(np.median(_errors(zz_runs, zigzags))), list(_turn_errors(turns)),
            list(_turn_errors(turns, "steady_yaw_rate")))  # fmt: skip


def _add(store: tuple[list, list, list], judged: tuple) -> None:
    """Append one model's ``_judge`` to the three lists of ``store``."""
    store[0].append(judged[0])
    store[1].extend(judged[1])
    store[2].extend(judged[2])


def _cell(errors: list[float]) -> str:
    e = np.abs(np.array(errors))
    finite = e[np.isfinite(e)]
    none = len(e) - len(finite)
    return (f"{np.median(finite):.0f} % / {np.mean(finite):.0f} % ({finite.max():.0f} %)"
            + (f", {none} without" if none else ""))  # fmt: skip


def main() -> None:
    warnings.simplefilter("ignore")
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    start = time.perf_counter()
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    files = zigzags + sorted((DATA / "turning").glob("*.csv"))
    logs = {f: read_trial_log(f, fmt="osaka-frt") for f in files}
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    rows: dict[str, tuple[list, list, list]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        particulars = f"{tmp}/esso.yml"
        with open(particulars, "w", encoding="utf-8") as fh:
            fh.writelines(f"{k}: {v}\n" for k, v in ESSO_OSAKA_MODEL.items())
        code = _quiet(["mmg", "kvlcc2", "--particulars", particulars, "--rps", "logs",
                       "--speed", "0.35", "-o", f"{tmp}/esso-mmg.yml"])  # fmt: skip
        assert code == 0
        sister = read_mmg(f"{tmp}/esso-mmg.yml")
        print("The two turns approach steady (the zig-zags accelerate through theirs): their "
              "measured approach against the sister's straight-running speed at their rps:\n")
        print("| turn | rps | measured approach (m/s) | the sister's straight speed (m/s) |")
        print("|---|---|---|---|")
        for f in files[len(zigzags):]:
            log = logs[f]
            rps = float(np.median(log["n"]))
            measured = validate(sister, log, start_draws=False)[0].indices["measured"]
            straight, _, _ = _straight(sister, rps)
            print(f"| {f.stem[-8:]} | {rps:.4g} | {measured['approach_speed']:.3f} | "
                  f"{straight:.3f} |")  # fmt: skip
        alone = _judge(sister, logs)
        rows["the sister's MMG model alone (no fit), on all nine zig-zags"] = (
            [alone[0]], alone[1], alone[2])  # fmt: skip
        per_fold = []
        for f in zigzags:
            others = {g: log for g, log in logs.items() if g != f and g in zigzags}
            per_fold.append(float(np.median(_errors(
                [validate(sister, log, start_draws=False)[0] for log in others.values()],
                others))))  # fmt: skip
        rows["the sister's MMG model alone, each fold's eight zig-zags"] = (per_fold, alone[1],
                                                                            alone[2])  # fmt: skip
        identified: tuple[list, list, list] = ([], [], [])
        priors = {p: ([], [], []) for p in ("kvlcc2", f"{tmp}/esso-mmg.yml")}
        corrected = {(m, g): ([], [], []) for m in STRUCTURES for g in GAMMAS}
        pooled = {g: ([], [], []) for g in GAMMAS}
        chosen, chosen_pooled = [], []
        for f in zigzags:
            others = {g: log for g, log in logs.items() if g != f}
            if _quiet(["identify", "--format", "osaka-frt", str(f), "-o", f"{tmp}/m.json"]) == 0:
                _add(identified, _judge(load_model(f"{tmp}/m.json"), others))
            for prior, store in priors.items():
                if _quiet(["identify", "--format", "osaka-frt", str(f), "--model",
                           "blanke-speed+wind", "--crossflow", "--prior", prior, "--gamma", "1",
                           "-o", f"{tmp}/p.json"]) == 0:  # fmt: skip
                    _add(store, _judge(load_model(f"{tmp}/p.json"), others))
            for structure, gamma in corrected:
                fit = identify_correction(logs[f], sister, structure, gamma)
                if gamma == "auto" and structure == STRUCTURES[-1]:
                    chosen.append(fit.gamma)
                _add(corrected[structure, gamma], _judge(fit.vessel, others))
            # The other eight zig-zags, judged on this one and the turns.
            held = {g: log for g, log in logs.items() if g == f or g not in zigzags}
            for gamma, store in pooled.items():
                fit = identify_correction([logs[g] for g in zigzags if g != f], sister,
                                          STRUCTURES[-1], gamma)  # fmt: skip
                if gamma == "auto":
                    chosen_pooled.append(fit.gamma)
                _add(store, _judge(fit.vessel, held))
        rows["default identify, one zig-zag file (9 models)"] = identified
        for prior, judged in priors.items():
            label = "the sister's MMG file" if prior.endswith(".yml") else prior
            rows[f"identify --model blanke-speed+wind --crossflow --prior {label} --gamma 1 "
                 "(9)"] = judged
        for (structure, gamma), judged in corrected.items():
            label = "auto" if gamma == "auto" else f"{gamma:g}"
            rows[f"the sister + {structure} correction from one file, γ {label} (9)"] = judged
        for gamma, judged in pooled.items():
            label = "auto" if gamma == "auto" else f"{gamma:g}"
            rows[f"the sister + {STRUCTURES[-1]} correction from the other eight zig-zags, "
                 f"γ {label}, on the ninth and the turns (9)"] = judged
    print("\n| made by | held-out zig-zags: r / spread | 35° TD | 35° steady r |")
    print("|---|---|---|---|")
    for label, (errors, td, r) in rows.items():
        print(f"| {label} | {np.median(errors):.3f} | {_cell(td)} | {_cell(r)} |")
    print(f"\nγ auto chose {', '.join(f'{g:g}' for g in chosen)} (one file, with the wind); "
          f"{', '.join(f'{g:g}' for g in chosen_pooled)} (eight files)")
    print(f"\n{time.perf_counter() - start:.0f} s")


def _tanker_and_sister():
    """The tanker, and its sister's MMG document and ship: the KVLCC2's coefficients with the
    tanker's particulars (its rudder area and propeller diameter not published: the KVLCC2's
    scaled by length), its gear's 10° and 2.33 °/s."""
    from shipid.data.particulars import Particulars
    from shipid.vessels import get_vessel, kvlcc2
    from shipid.vessels.mmg_file import mmg_vessel, sister_ship

    truth = get_vessel("tanker")
    particulars = Particulars(length=truth.length, beam=47.17, draught=18.46, mass=225.5e6,
                              rudder_limit=math.degrees(truth.steering.max_angle))
    doc, _ = sister_ship(kvlcc2().dynamics.c, particulars, "tanker sister",
                         truth.approach_speed, rudder_rate=math.degrees(truth.steering.max_rate))
    return truth, doc, mmg_vessel(doc)


def tanker_truth() -> None:
    """The same sister (the KVLCC2's coefficients) with the particulars of another VLCC whose
    truth is known: the `tanker` (van Berlekom & Goddard's Esso 190 000 dwt, a Norrbin-type
    model of another laboratory, course-unstable; reference-ships.md §4, its rudder limited to
    10°): the sister's manoeuvres against the truth's, fitted to nothing. Its rudder area and
    propeller diameter are not published: the KVLCC2's scaled by length."""
    from shipid.trials.manoeuvres import turning_circle, zigzag

    truth, doc, sister = _tanker_and_sister()
    print("\nThe tanker as a truth: the sister with its particulars (L 304.8 m, B 47.17 m, T "
          "18.46 m, 225 500 t; rudder limit 10°, 2.33 °/s), fitted to nothing\n")
    print("| ship | 10° turn: TD / L, steady r [rad/s] (starboard, port) | 10°/10° overshoots "
          "[deg] | 5°/5° overshoots [deg] |")
    print("|---|---|---|---|")
    rows = {}
    for name, ship in (("tanker (truth)", truth), ("sister", sister)):
        turns = [turning_circle(ship, 10, side=side, duration=3000, dt=0.5).indices
                 for side in ("starboard", "port")]  # fmt: skip
        zz = [zigzag(ship, a, a, duration=1500, dt=0.5).indices for a in (10, 5)]
        rows[name] = (turns, zz)
        print(f"| {name} | " + ", ".join(f"{t['tactical_diameter'] / truth.length:.2f}, "
                                         f"{abs(t['steady_yaw_rate']):.5f}" for t in turns)
              + " | " + " | ".join(f"{z['first_overshoot_deg']:.1f}, "
                                   f"{z['second_overshoot_deg']:.1f}" for z in zz) + " |")


# Full-scale sensors for the tanker's training logs (an INS and a log speed of a VLCC's trials).
TANKER_NOISE = {"u": 0.02, "v": 0.02, "r": 2e-4, "psi": math.radians(0.05)}


def tanker_truth_from_logs(seeds: int = 5, one_log: bool = False) -> None:
    """The tanker's own 10°/10° zig-zags (both sides first, noisy; ``one_log``: one per seed,
    to starboard first on even seeds and to port on odd ones, as ``identify``'s note on one log
    of a full-form hull has it) as training logs, the
    manoeuvres they do not contain as the judge (its 10° turns, its 5°/5° zig-zags): the
    default ``identify``, and with the particulars giving the gear's 10° limit
    (``rudder_limit``: the plausibility checks hold 10° instead of 35°); the sister alone; the
    sister corrected by the logs (``shipid correct``, blanke-race, γ 1e4, 100 and auto); the
    logs fitted toward the sister
    (``--prior SISTER.yml --model blanke-speed --crossflow --gamma 1``, the Esso's best one-file
    setting). Medians over the seeds of the |error| of each index (turns: both sides; 5°/5°:
    first to starboard)."""

    import yaml

    from shipid.data.io import write_log
    from shipid.trials.manoeuvres import turning_circle, zigzag
    from shipid.vessels.sensors import SensorModel

    start = time.perf_counter()
    truth, doc, sister = _tanker_and_sister()

    def indices(ship, **kw):
        turns = [turning_circle(ship, 10, side=side, duration=3000, dt=0.5, **kw).indices
                 for side in ("starboard", "port")]  # fmt: skip
        zz = zigzag(ship, 5, 5, duration=1500, dt=0.5, **kw).indices
        return ([t.get("tactical_diameter") for t in turns],
                [abs(t.get("steady_yaw_rate") or math.nan) for t in turns],
                [zz.get("first_overshoot_deg"), zz.get("second_overshoot_deg")])

    true = indices(truth)
    gear = {"speed": truth.approach_speed, "steering": truth.steering}
    errors: dict[str, list] = {}

    def judge(label, ship, **kw):
        got = indices(ship, **kw)
        rows = errors.setdefault(label, [[], [], []])
        for k in range(2):
            rows[k] += [100 * abs((g if g is not None else math.inf) / t - 1)
                        for g, t in zip(got[k], true[k], strict=True)]  # fmt: skip
        rows[2] += [abs((g if g is not None else math.inf) - t)
                    for g, t in zip(got[2], true[2], strict=True)]  # fmt: skip

    sensors = SensorModel(white=TANKER_NOISE)
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sister_file = os.path.join(tmp, "sister.yml")
        with open(sister_file, "w", encoding="utf-8") as f:
            yaml.safe_dump(doc, f)
        particulars_file, gear_file = (os.path.join(tmp, f) for f in ("tanker.yml", "gear.yml"))
        hull = {"length": truth.length, "beam": 47.17, "draught": 18.46, "mass": 225.5e6}
        for path, extra in ((particulars_file, {}), (gear_file, {"rudder_limit": 10.0})):
            with open(path, "w", encoding="utf-8") as f:
                yaml.safe_dump({**hull, **extra}, f)
        for seed in range(seeds):
            sides = (("starboard", "port")[seed % 2],) if one_log else ("starboard", "port")
            paths = [str(write_log(sensors.apply(zigzag(truth, 10, 10, first=side,
                                                        duration=1500, dt=0.5).log, 2 * seed + k),
                                   os.path.join(tmp, f"zz_{side}_{seed}.csv")))
                     for k, side in enumerate(sides)]  # fmt: skip
            logs = [read_trial_log(p) for p in paths]
            for label, extra in (("identify (default)", []),
                                 ("identify --particulars with the gear's rudder_limit 10",
                                  ["--particulars", gear_file]),
                                 ("identify --prior sister, blanke-speed --crossflow, γ 1",
                                  ["--prior", sister_file, "--model", "blanke-speed",
                                   "--crossflow", "--gamma", "1", "--particulars",
                                   particulars_file])):  # fmt: skip
                out = os.path.join(tmp, f"m{seed}.json")
                if _quiet(["identify", *paths, *extra, "-o", out]) != 0:
                    raise RuntimeError(f"identify {' '.join(extra)} failed")
                judge(label, load_model(out), **gear)
            judge("sister (fitted to nothing)", sister)
            for gamma in (1e4, 1e2, "auto"):
                fit = identify_correction(logs, sister, "blanke-race", gamma=gamma)
                judge(f"sister corrected, γ {gamma:g}" if gamma != "auto"
                      else "sister corrected, γ auto", fit.vessel)  # fmt: skip
    trained = "one 10°/10° zig-zag (to either side" if one_log else \
        "its 10°/10° zig-zags (both sides"  # fmt: skip
    print(f"\nThe tanker as a truth, trained on {trained}, noisy; {seeds} seeds), judged on its "
          "10° turns and 5°/5° zig-zag: median |error| (largest)\n")
    print("| model | 10° turns' tactical diameter [%] | steady yaw rate [%] | 5°/5° "
          "overshoots [deg] | cases |")
    print("|---|---|---|---|---|")
    for label, (td, r, os_) in errors.items():
        print(f"| {label} | {np.median(td):.1f} ({np.max(td):.1f}) | {np.median(r):.1f} "
              f"({np.max(r):.1f}) | {np.median(os_):.2f} ({np.max(os_):.2f}) | "
              f"{len(td) // 2} |")
    print(f"\n{time.perf_counter() - start:.0f} s")


def _sister_file(folder: str) -> str:
    """The sister's MMG file, as ``main`` makes it, written in ``folder``."""
    particulars = f"{folder}/esso.yml"
    with open(particulars, "w", encoding="utf-8") as fh:
        fh.writelines(f"{k}: {v}\n" for k, v in ESSO_OSAKA_MODEL.items())
    path = f"{folder}/esso-mmg.yml"
    assert _quiet(["mmg", "kvlcc2", "--particulars", particulars, "--rps", "logs", "--speed",
                   "0.35", "-o", path]) == 0  # fmt: skip
    return path


def wind_only_correction() -> None:
    """The sister corrected in the wind's load alone (``shipid correct SHIP --model wind``: its
    hydrodynamics kept whole, the five wind terms fitted) from each zig-zag file, judged as
    ``main`` judges (the other zig-zags, the two turns)."""
    warnings.simplefilter("ignore")
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    files = zigzags + sorted((DATA / "turning").glob("*.csv"))
    logs = {f: read_trial_log(f, fmt="osaka-frt") for f in files}
    print("\nThe sister corrected in the wind's load alone, from one zig-zag file (9 models)\n")
    print("| γ | held-out zig-zags: r / spread | 35° TD | 35° steady r |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        sister = read_mmg(_sister_file(tmp))
        for gamma in (1e4, 1e2, 1.0):
            store: tuple[list, list, list] = ([], [], [])
            for f in zigzags:
                fit = identify_correction([logs[f]], sister, "wind", gamma=gamma)
                _add(store, _judge(fit.vessel, {g: log for g, log in logs.items() if g != f}))
            print(f"| {gamma:g} | {np.median(store[0]):.3f} | {_cell(store[1])} | "
                  f"{_cell(store[2])} |")


def pairs_toward_the_sister() -> None:
    """Every pair of zig-zag files fitted toward the sister (``--model blanke-speed+wind
    --crossflow --prior SHIP``, the one-file setting) against the default, judged as
    ``study_crossflow.esso`` judges."""
    from study_crossflow import esso

    warnings.simplefilter("ignore")
    print()
    with tempfile.TemporaryDirectory() as tmp:
        sister = _sister_file(tmp)
        toward = ["--model", "blanke-speed+wind", "--crossflow", "--prior", sister]
        esso(True, {"default": [], "toward the sister, γ 1": [*toward, "--gamma", "1"],
                    "toward the sister, γ auto": [*toward, "--gamma", "auto"]})


def _straight(ship, rps: float):
    from shipid.cli.targets import _ship_approach

    with contextlib.redirect_stdout(io.StringIO()):
        return _ship_approach(ship, None, rps)


if __name__ == "__main__":
    main()
    tanker_truth()
    tanker_truth_from_logs()
    tanker_truth_from_logs(one_log=True)
    wind_only_correction()
    if "pairs" in sys.argv[1:]:
        pairs_toward_the_sister()
