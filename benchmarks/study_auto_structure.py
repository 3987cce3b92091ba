"""The default structure (`shipid identify` without --model, `--model auto`) against the earlier
default (`blanke`) and a fixed structure that holds the propeller and the wind (`blanke-rps+wind`),
judged on logs none of them was fitted to: the README's table.

Esso Osaka (the README's logs, Δk 0.5 s): each fold trains on a subset and is judged on the two
35° turns (tactical diameter, steady yaw rate) and the random run 12_29_58 (its r error std over
its spread). KVLCC2: trained on MARIN's 20/20 zig-zag (then on both MARIN runs), judged on the
MARIN −20° run and HSVA's 20/10 run (free-run error std of u, v, r).

Every model is made by the command line itself (``shipid.cli.main``) from logs written as files,
as a user's would be.

Run: .venv/bin/python benchmarks/study_auto_structure.py
"""

from __future__ import annotations

import contextlib
import io
import time
import warnings
from pathlib import Path

import numpy as np
from esso_logs import DATA as ESSO
from esso_logs import README_HELD, esso_logs, run_with_files

from shipid.cli import main
from shipid.data.io import read_log, write_log
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_model

STRUCTURES = ("auto", "blanke", "blanke-rps+wind")
ZZ = {"10": "13_42_53", "12": "14_03_39", "12b": "13_29_19", "16.7": "13_04_24",
      "16.7b": "13_14_21"}  # fmt: skip
FOLDS = {
    "three random runs": ([], "random"),
    "nine zig-zags, three random runs": (None, "random"),
    "nine zig-zags": (None, None),
    "three zig-zags (10, 12, 16.7 rps)": ([ZZ["10"], ZZ["12"], ZZ["16.7"]], None),
    "two zig-zags (10, 16.7 rps)": ([ZZ["10"], ZZ["16.7"]], None),
    "two zig-zags (12, 16.7 rps)": ([ZZ["12b"], ZZ["16.7b"]], None),
    "one zig-zag (16.7 rps)": ([ZZ["16.7"]], None),
}


def _identify(paths: list[Path], structure: str, out: Path, extra: tuple[str, ...] = ()
              ) -> tuple[str, float]:  # fmt: skip
    """The model file ``shipid identify PATHS [--model STRUCTURE] [EXTRA...]`` writes, and its
    first line (the auto structure's choice), and the seconds it took."""
    argv = ["identify", *map(str, paths), "-o", str(out), *extra]
    if structure != "auto":
        argv += ["--model", structure]
    text = io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(text), contextlib.redirect_stderr(io.StringIO()):
        code = main(argv)
    seconds = time.perf_counter() - t0
    first = text.getvalue().splitlines()[0] if code == 0 else "failed"
    return (first if first.startswith("structure") else ""), seconds if code == 0 else -1.0


def _turn_cell(v) -> str:
    if v.simulation is None or v.simulation.diverged:
        return "diverges"
    m, s = v.indices["measured"], v.indices.get("simulated") or {}
    td, r = s.get("tactical_diameter"), s.get("steady_yaw_rate")
    if td is None or r is None:
        return "no index"
    return (f"{100 * (td / m['tactical_diameter'] - 1):+.0f} % "
            f"(r {100 * (r / m['steady_yaw_rate'] - 1):+.0f} %)")  # fmt: skip


def esso(folder: Path) -> None:
    data = esso_logs()
    if data is None:
        return
    zz, rnd, turns = data
    files = {}
    for key, log in {**{f"zz {k}": x for k, x in zz.items()},
                     **{f"rnd {k}": x for k, x in rnd.items()}}.items():  # fmt: skip
        files[key] = write_log(log, folder / f"{key.replace(' ', '_')}.csv")
    held_random = rnd[README_HELD]
    spread = float(np.std(held_random["r"]))
    print(f"Esso Osaka, Δk 0.5 s; held out: the two 35° turns and random run {README_HELD} "
          f"(r spread {spread:.4f} rad/s). Cells: tactical diameter +35°, −35° (steady yaw "
          "rate), random run r error std / spread\n")  # fmt: skip
    print("| trained on | " + " | ".join(STRUCTURES) + " |")
    print("|---" * (len(STRUCTURES) + 1) + "|")
    for fold, (zigzags, randoms) in FOLDS.items():
        keys = [f"zz {k}" for k in (zz if zigzags is None else zigzags)]
        if randoms:
            keys += [f"rnd {k}" for k in rnd if k != README_HELD]
        cells, chosen = [], ""
        for structure in STRUCTURES:
            path = folder / "model.json"
            first, seconds = _identify([files[k] for k in keys], structure, path)
            if seconds < 0:
                cells.append("identify refused")
                continue
            if structure == "auto":
                chosen = first.split(" (")[0].removeprefix("structure: ")
            model = load_model(path)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                vals = validate(model, [*turns, held_random])
            rv = vals[-1]
            random = ("diverges" if rv.simulation is None or rv.simulation.diverged
                      else f"{rv.metrics['r']['std'] / spread:.2f}")  # fmt: skip
            cells.append(f"{_turn_cell(vals[0])}, {_turn_cell(vals[1])}; {random} "
                         f"({seconds:.1f} s)")  # fmt: skip
        print(f"| {fold} (auto: {chosen}) | " + " | ".join(cells) + " |")


def kvlcc2(folder: Path) -> None:
    data = ESSO.parent
    marin = {"fmt": "simman-marin", "scale": 45.7, "dt": 0.2}
    logs = {"MARIN zz 20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_20_m.dat", **marin),
            "MARIN zz −20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_-20_m.dat",
                                     **marin),
            "HSVA 20/10": read_log(data / "kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                                   fmt="simman-hsva", dt=0.2)}  # fmt: skip
    files = {k: write_log(x, folder / f"kv{i}.csv") for i, (k, x) in enumerate(logs.items())}
    print("\nKVLCC2: free-run error std u / v / r of the held-out runs\n")
    print("| trained on | structure | choice | seconds | " + " | ".join(
        f"{k}" for k in logs) + " |")  # fmt: skip
    print("|---|---|---|---|" + "---|" * len(logs))
    for train in (["MARIN zz 20"], ["MARIN zz 20", "MARIN zz −20"]):
        for structure in ("auto", "blanke", "blanke-speed", "blanke-race+race-damping"):
            path = folder / "kv.json"
            first, seconds = _identify([files[k] for k in train], structure, path)
            model = load_model(path)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                vals = validate(model, [logs[k] for k in logs if k not in train])
            cells = {k: " / ".join(f"{v.metrics[s]['std']:.4f}" for s in "uvr")
                     for k, v in zip([k for k in logs if k not in train], vals, strict=True)}
            choice = first.split(" (")[0].removeprefix("structure: ") if structure == "auto" \
                else ""  # fmt: skip
            print(f"| {' + '.join(train)} | {structure} | {choice} | {seconds:.1f} | "
                  + " | ".join(cells.get(k, "(trained)") for k in logs) + " |")


if __name__ == "__main__":
    run_with_files(esso, kvlcc2)
