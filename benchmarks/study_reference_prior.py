"""A reference ship as the prior (``identify --prior SHIP``, issue #10 item 2): the reference's
trials fitted in the structure identified and carried to the ship's length at equal Froude
number, the LS-SVM drawn toward it. Judged on logs the models were not fitted to:

1. the Esso Osaka's nine zig-zag files one at a time (the 3 m model's length comes with its
   files), the KVLCC2 (a VLCC like the Esso), the ``tanker`` (another VLCC, van Berlekom and
   Goddard's, whose rudder stops at 10°) or the Mariner (a cargo liner) as the reference, at
   several γ, with the hull's cross-flow drag and with the split |v|v, |v|r; judged on the
   other eight zig-zags, the two 35° turns and the four random runs, as
   ``study_crossflow.py`` judges; with ``pairs``, every pair of the files too (the cross-flow
   rows at γ 1 and 10, as ``study_crossflow.py pairs`` judges);
2. the real KVLCC2: identified on MARIN's 20/20 zig-zag (its particulars), judged on the −20/−20
   run and HSVA's 20/10, the KVLCC2's own MMG model as the reference;
3. the ``tanker`` as a truth (another VLCC) with the KVLCC2 as the reference, judged on its own
   turns and zig-zag as ``study_tanker.py`` judges.

Run: .venv/bin/python benchmarks/study_reference_prior.py [pairs]
"""

from __future__ import annotations

import sys
import tempfile
import warnings

from esso_logs import run_with_files
from kvlcc2_logs import kvlcc2_logs
from study_crossflow import MARIN_PARTICULARS, _fit, esso

from shipid.data.io import write_log
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_model

CROSSFLOW = ["--model", "blanke-speed+wind", "--crossflow"]
SPLIT = ["--model", "blanke-speed+wind"]
ESSO_CONFIGS = {
    "default identify": [],
    "blanke-speed+wind --crossflow": CROSSFLOW,
    **{f"  --prior kvlcc2 --gamma {g}": [*CROSSFLOW, "--prior", "kvlcc2", "--gamma", g]
       for g in ("0.1", "1", "10", "100")},
    "  --prior kvlcc2 --gamma auto": [*CROSSFLOW, "--prior", "kvlcc2", "--gamma", "auto"],
    "  --prior tanker --gamma 1": [*CROSSFLOW, "--prior", "tanker", "--gamma", "1"],
    "  --prior mariner --gamma 1": [*CROSSFLOW, "--prior", "mariner", "--gamma", "1"],
    "blanke-speed+wind (no --crossflow)": SPLIT,
    "  --prior kvlcc2 --gamma 1 ": [*SPLIT, "--prior", "kvlcc2", "--gamma", "1"],
    "  --prior kvlcc2 --gamma 100 ": [*SPLIT, "--prior", "kvlcc2", "--gamma", "100"],
}  # fmt: skip


def kvlcc2() -> None:
    logs = kvlcc2_logs()
    train = "MARIN zz 20°"
    print(f"\nKVLCC2, identified on {train} (identify --dt 0.2 --crossflow, MARIN's particulars), "
          "the KVLCC2's MMG model as the reference: each held-out log's free-run error std "
          "u / v / r and closed-loop overshoots\n")
    held = [k for k in logs if k != train]
    print("| structure | prior | " + " | ".join(held) + " |")
    print("|---|---|" + "---|" * len(held))
    measured = []
    with tempfile.TemporaryDirectory() as tmp:
        path = str(write_log(logs[train], f"{tmp}/train.csv"))
        for structure in ("blanke-race+race-damping", "blanke-speed"):
            for prior in ([], ["--prior", "kvlcc2", "--gamma", "1"],
                          ["--prior", "kvlcc2", "--gamma", "100"]):  # fmt: skip
                out = f"{tmp}/m.json"
                if not _fit(["identify", path, "--model", structure, "--crossflow",
                             "--particulars", str(MARIN_PARTICULARS), *prior], out):  # fmt: skip
                    print(f"| {structure} | {' '.join(prior)} | failed |")
                    continue
                cells = []
                for name in held:
                    v = validate(load_model(out), logs[name], start_draws=False)[0]
                    m, ind = v.metrics, v.indices
                    cl, me = ind["closed_loop"], ind["measured"]
                    if len(measured) < len(held):
                        measured.append(f"{name} {me['first_overshoot_deg']:.1f}°, "
                                        f"{me['second_overshoot_deg']:.1f}°")  # fmt: skip
                    cells.append(f"{m['u']['std']:.4f} / {m['v']['std']:.4f} / "
                                 f"{m['r']['std']:.4f}, {cl['first_overshoot_deg']:.1f}°, "
                                 f"{cl['second_overshoot_deg']:.1f}°")  # fmt: skip
                print(f"| {structure} | {' '.join(prior) or 'none'} | {' | '.join(cells)} |",
                      flush=True)  # fmt: skip
    print(f"\nmeasured overshoots: {'; '.join(measured)}")


def tanker(seeds: int = 3) -> None:
    """The ``tanker`` as the truth (another VLCC, van Berlekom and Goddard's; its logs at the sea
    sensors' noise as ``study_tanker.py`` makes them, its length given), the KVLCC2 as the
    reference."""
    import json
    from pathlib import Path

    import study_tanker as st
    from cli_models import model_by_cli, noisy_files

    clean, truth = st.trials(), st.truth_indices()
    print("\nThe tanker as the truth, the KVLCC2 as the reference (identify --model blanke-speed "
          f"--crossflow, the tanker's length), {seeds} seeds: 35° TD and steady r |error| median "
          "(largest), 20° TD error median, 10°/10° worst overshoot error median (largest)\n")
    print("| trained on | made by | 35° TD | 35° steady r | 20° TD | 10°/10° |")
    print("|---|---|---|---|---|---|")
    made = {"blanke-speed --crossflow": [],
            "  --prior kvlcc2 --gamma 1": ["--prior", "kvlcc2", "--gamma", "1"],
            "  --prior kvlcc2 --gamma auto": ["--prior", "kvlcc2", "--gamma", "auto"]}
    rows: dict[tuple[str, str], list[dict]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        particulars = Path(tmp) / "tanker.json"
        particulars.write_text(json.dumps({"length": 304.8}))
        for seed in range(seeds):
            paths = noisy_files(clean, st.SEA_SENSORS, seed, tmp)
            for label in list(st.TRAINING)[:2]:
                files = [paths[f"{n}_{rpm}"] for n, rpm in st.TRAINING[label]]
                for how, flags in made.items():
                    model = model_by_cli(["identify", "--particulars", str(particulars), "--model",
                                          "blanke-speed", "--crossflow", *flags], files,
                                         f"{tmp}/model.json")  # fmt: skip
                    if model is not None:
                        rows.setdefault((label, how), []).append(st.judged(model, truth))
    for (label, how), judged in rows.items():
        print(f"| {label} | {how.rstrip()} | " + " | ".join(st.summary(judged)) + " |")


def pairs() -> None:
    print()
    esso(True, {k: ESSO_CONFIGS[k] for k in ("blanke-speed+wind --crossflow",
                                             "  --prior kvlcc2 --gamma 1",
                                             "  --prior kvlcc2 --gamma 10")})


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    run_with_files(lambda _: esso(False, ESSO_CONFIGS), lambda _: kvlcc2(), lambda _: tanker(),
                   *([lambda _: pairs()] if "pairs" in sys.argv[1:] else []))
