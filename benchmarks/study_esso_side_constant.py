"""A side force that stays the same at every propeller speed, on the Esso Osaka's random runs
(issue #10). The default library's candidates for the nine zig-zag files, written as
advance-ratio similarity has them, end their held turns astern; ``identify`` then searched the
library with every constant (a side force the same at every rps, and astern and stopped too),
and since 2026-11-29 first the library with the side force's constant alone written n|n| (the
surge keeping its constant and δ²: ``auto_structure.SIMILAR_FORMS``). Printed: each ṙ term's
mean contribution along the measured runs (one-step, the model's equation at the logged states)
for the default before (every constant); then, for the nine files and every eight of them whose
default searched past the similar library, the default against the default before (its
searches without the side force's form): the two 35° turns (closed loop), the four
random runs' yaw-rate error with its mean (free run), and the held 10° and 35° turns at 6–16.7
rps from the model's own straight speed (the largest ratio of a turn's tactical diameter at
one rps to the same turn's at another: a ship's is about as wide at every speed).

Run: .venv/bin/python benchmarks/study_esso_side_constant.py
"""

from __future__ import annotations

import os
import tempfile
import time
import warnings

import numpy as np
from cli_models import model_by_cli
from esso_logs import held_out_files
from study_esso_rudder_normal import FORMAT, KEYS

from shipid.dynamics.model import ModelStructure
from shipid.dynamics.terms import parse_term, term_matrix
from shipid.evaluation.validate import validate_log
from shipid.reporting.modelfile import load_document


def _spec(structure: ModelStructure) -> str:
    return "; ".join(f"{d}: {', '.join(t)}" for d, t in structure.terms.items())


def _contributions(model, logs: dict) -> None:
    """Mean of each ṙ term along each log (the model's equation at the logged states)."""
    terms = list(model.coefficients["r"])
    print("Mean contribution of each ṙ term [rad/s²] along the logs, the model's ṙ and the "
          "measured mean ṙ\n")  # fmt: skip
    print("| log | mean u [m/s], n [rps], astern share | " + " | ".join(
        parse_term(t).display() or "1" for t in terms) + " | model | measured |")
    print("|---|---|" + "---|" * (len(terms) + 2))
    for name, log in logs.items():
        inputs = {c: log[c].to_numpy() for c in log.columns if c not in ("t", "u", "v", "r")}
        X = term_matrix(terms, log["u"].to_numpy(), log["v"].to_numpy(), log["r"].to_numpy(),
                        inputs)  # fmt: skip
        parts = (X * np.array([model.coefficients["r"][t] for t in terms])).mean(axis=0)
        measured = np.gradient(log["r"].to_numpy(), log["t"].to_numpy()).mean()
        print(f"| {name} | {log['u'].mean():.3f}, {log['n'].mean():.2f}, "
              f"{(log['n'] < 0).mean():.2f} | " + " | ".join(f"{x:+.1e}" for x in parts)
              + f" | {parts.sum():+.1e} | {measured:+.1e} |")


def _judged(model, turns, randoms, logs) -> tuple[list[float], list[tuple[float, float]]]:
    """The turns' TD and steady r errors [%]; per random run (r error std over r's std, r rms
    error over r's rms)."""
    errors = []
    for path in turns:
        run = validate_log(model, logs[path], path.name, start_draws=False)
        closed, measured = run.indices.get("closed_loop") or {}, run.indices["measured"]
        errors += [100 * (closed[k] / measured[k] - 1) if closed.get(k) is not None else np.nan
                   for k in KEYS]  # fmt: skip
    ratios = []
    for path in randoms:
        r = logs[path]["r"].to_numpy()
        m = validate_log(model, logs[path], path.name, start_draws=False).metrics["r"]
        ratios.append((m["std"] / float(np.std(r)), m["rmse"] / float(np.sqrt(np.mean(r**2)))))
    return errors, ratios


# The held turns across the propeller speeds: the logs' 10–16.7 rps and below, where the random
# runs go.
ACROSS_RPS = (6.0, 8.0, 10.0, 12.0, 14.0, 16.67)


def _across_rps(model) -> tuple[float, int]:
    """The 10° and 35° turns to either side held at each of ``ACROSS_RPS`` from the model's own
    straight speed: the largest ratio of a turn's tactical diameter at one rps to the same
    turn's at another, and how many of the 24 turns diverge or never turn 180°."""
    from shipid.dynamics.equilibrium import surge_equilibrium
    from shipid.trials.manoeuvres import turning_circle

    worst, failed = 1.0, 0
    for rudder in (10.0, 35.0):
        for side in ("starboard", "port"):
            across = []
            for rps in ACROSS_RPS:
                speed = surge_equilibrium(model, 0.3, rps)
                turn = turning_circle(model, rudder, side, rps=rps, speed=speed, dt=0.1,
                                      wind=(0.0, 0.0))  # fmt: skip
                td = None if turn.diverged else turn.indices.get("tactical_diameter")
                if td is None:
                    failed += 1
                else:
                    across.append(td)
            if across:
                worst = max(worst, max(across) / min(across))
    return worst, failed


def _row(label: str, name: str, model, turns, randoms, logs) -> None:
    if model is None:
        print(f"| {label} | {name} | failed | | | |")
        return
    errors, ratios = _judged(model, turns, randoms, logs)
    rms = [b for _, b in ratios]
    worst, failed = _across_rps(model)
    print(f"| {label} | {name} | " + ", ".join(f"{x:+.0f}" for x in errors[0::2]) + " | "
          + ", ".join(f"{x:+.0f}" for x in errors[1::2]) + " | "
          + ", ".join(f"{b:.2f}" for b in rms) + f" ({np.mean(rms):.2f}) | {worst:.2f}, "
          f"{failed} |", flush=True)  # fmt: skip


def main() -> None:
    files = held_out_files()
    if files is None:
        return
    zigzags, turns, randoms, logs = files
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    from shipid.data.io import read_log

    with tempfile.TemporaryDirectory() as scratch:
        before = _every_constant(zigzags, scratch)
        shown = {p.name: logs[p] for p in randoms}
        shown.update({p.name: read_log(p, fmt="osaka-frt", dt=0.5, start="auto", end="auto")
                      for p in zigzags[:2]})  # fmt: skip
        _contributions(before, shown)
        print("\nTrained on the zig-zag files (all nine, then every eight whose default searched "
              "past the similar library); judged on the two 35° turns (closed loop) and the "
              "four random runs (free run)\n")  # fmt: skip
        print("| left out | model | 35° TD off, stbd, port [%] | steady r off, stbd, port [%] | "
              "random runs' r rms error / r rms (mean) | held 10° and 35° turns at 6–16.7 rps: "
              "largest ratio of tactical diameters, failed of 24 |")  # fmt: skip
        print("|---|---|---|---|---|---|")
        for left in [None, *zigzags]:
            kept = [p for p in zigzags if p != left]
            out = f"{scratch}/d.json"
            default = model_by_cli(["identify", *FORMAT], [str(p) for p in kept], out)
            if default is None:
                continue
            library = load_document(out)["identification"]["structure_choice"]["library"] or ""
            if left is not None and " in the surge" not in library:
                continue  # not the side force's form: as before
            label = "none" if left is None else left.stem[-8:]
            _row(label, "identify (default)", default, turns, randoms, logs)
            other = before if left is None else _every_constant(kept, scratch)
            _row(label, "the default before (every constant)", other, turns, randoms, logs)
    print(f"\n{time.perf_counter() - t0:.0f} s")


def _every_constant(zigzags, scratch: str):
    """``identify``'s default as it was before the side force's form: its searches in
    ``SIMILAR_FORMS`` less ``SIDE_FORCE`` (the similar library, then the one with every
    constant)."""
    from shipid.dynamics.similarity import SIDE_FORCE
    from shipid.identification import auto_structure

    forms = auto_structure.SIMILAR_FORMS
    auto_structure.SIMILAR_FORMS = tuple(f for f in forms if f != SIDE_FORCE)
    try:
        return model_by_cli(["identify", *FORMAT], [str(p) for p in zigzags],
                            f"{scratch}/c.json")  # fmt: skip
    finally:
        auto_structure.SIMILAR_FORMS = forms


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main()
