"""The sampling interval Δk on the KVLCC2's real zig-zags (issue #10), beside the Esso Osaka's
(``study_sampling.py``, where 0.5 s predicts the held-out turns far better than the logs' own
0.1 s): ``shipid identify`` from the MARIN 20/20 zig-zag (first rudder +20°) at Δk 0.05–1.0 s,
the default structure (``auto``: the inflow comparison on four blocks of the one log) and the
two it chooses between, judged on the MARIN −20° run and the HSVA 20/10 run (free-run error
std of u, v, r and the closed-loop overshoots). Then why the comparison's choice can differ from
what the unseen runs prefer: the free-run scores of the two structures on four blocks of the
one log against leaving one of the two MARIN runs out.

Run: .venv/bin/python benchmarks/study_kvlcc2_sampling.py
"""

from __future__ import annotations

import warnings
from pathlib import Path

from esso_logs import DATA as ESSO
from esso_logs import run_with_files
from study_auto_structure import _identify

from shipid.data.io import read_log, write_log
from shipid.evaluation.validate import validate
from shipid.identification.select import select
from shipid.reporting.modelfile import load_model

SAMPLING = (0.05, 0.1, 0.2, 0.5, 1.0)
STRUCTURES = ("auto", "blanke-speed", "blanke-race+race-damping")


def _logs(dt: float) -> dict:
    data = ESSO.parent
    marin = {"fmt": "simman-marin", "scale": 45.7, "dt": dt}
    return {"MARIN zz 20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_20_m.dat", **marin),
            "MARIN zz −20": read_log(data / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_-20_m.dat",
                                     **marin),
            "HSVA 20/10": read_log(data / "kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                                   fmt="simman-hsva", dt=dt)}  # fmt: skip


def _cell(v) -> str:
    closed, measured = v.indices["closed_loop"], v.indices["measured"]
    os_ = ", ".join(f"{closed.get(k, float('nan')):.1f}" for k in
                    ("first_overshoot_deg", "second_overshoot_deg"))  # fmt: skip
    meas = ", ".join(f"{measured[k]:.1f}" for k in ("first_overshoot_deg", "second_overshoot_deg"))
    return " / ".join(f"{v.metrics[s]['std']:.4f}" for s in "uvr") + f"; {os_} ({meas})"


def sampling(folder: Path) -> None:
    print("Trained on MARIN zz 20; cells: held-out free-run error std u / v / r; closed-loop "
          "overshoots (measured)\n")  # fmt: skip
    print("| Δk [s] | structure | choice | MARIN zz −20 | HSVA 20/10 |")
    print("|---|---|---|---|---|")
    for dt in SAMPLING:
        logs = _logs(dt)
        path = write_log(logs["MARIN zz 20"], folder / f"zz20_{dt}.csv")
        for structure in STRUCTURES:
            out = folder / "kv.json"
            first, _ = _identify([path], structure, out)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                held = validate(load_model(out), [logs["MARIN zz −20"], logs["HSVA 20/10"]])
            choice = first.split(" (")[0].removeprefix("structure: ") if structure == "auto" \
                else ""  # fmt: skip
            print(f"| {dt:g} | {structure} | {choice} | " + " | ".join(map(_cell, held)) + " |")


def block_scores(folder: Path) -> None:
    print("\nFree-run CV scores (error over spread; u, v, r and their mean ± standard error), "
          "γ 1e4 as the inflow comparison fits them\n")  # fmt: skip
    print("| Δk [s] | held out | structure | score | u | v | r |")
    print("|---|---|---|---|---|---|---|")
    for dt in (0.2, 0.5):
        logs = _logs(dt)
        for label, train, cv in (("four blocks of MARIN zz 20", [logs["MARIN zz 20"]], "blocks:4"),
                                 ("each MARIN run (the other trained on)",
                                  [logs["MARIN zz 20"], logs["MARIN zz −20"]], "logo")):
            for structure in STRUCTURES[1:]:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    row = select(train, library=structure, search="none", cv=cv,
                                 gammas=(1e4,)).candidates.iloc[0]  # fmt: skip
                print(f"| {dt:g} | {label} | {structure} | {row['score']:.3f} ± "
                      f"{row['score_se']:.3f} | {row['score_u']:.3f} | {row['score_v']:.3f} | "
                      f"{row['score_r']:.3f} |")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # the MARIN yaw rate's offset (study_gyro_offset.py)
    run_with_files(sampling, block_scores)
