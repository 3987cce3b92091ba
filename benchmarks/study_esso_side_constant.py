"""A side force that stays the same at every propeller speed, on the Esso Osaka's random runs
(issue #10). The default model of the nine zig-zag files holds a constant in v̇ and ṙ (its
similar library's candidates end their held turns astern, so ``identify`` searches the library
with its constant: docs/structures.md). The random runs go at 1–5 rps on the mean, astern a
sixth to a third of the time: there the constant is no longer balanced by the rudder in the
race. Printed: each term's mean contribution to ṙ along the measured runs (one-step, the model's
equation at the logged states), then the random runs' yaw-rate error with and without its mean
for the default, ``select`` on the default library with the constant kept in surge alone, and
the default's terms refitted with the constant of v̇ and ṙ written n|n|.

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

from shipid.dynamics.model import ModelStructure, get_structure
from shipid.dynamics.similarity import similar_library
from shipid.dynamics.terms import parse_term, term_matrix
from shipid.evaluation.validate import validate_log
from shipid.identification.select import DEFAULT_LIBRARY


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


def main() -> None:
    files = held_out_files()
    if files is None:
        return
    zigzags, turns, randoms, logs = files
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    library = get_structure(DEFAULT_LIBRARY)
    similar, _ = similar_library(library)
    surge_constant = ModelStructure("the constant in surge alone", {
        d: similar.terms[d] if d in ("v", "r") else library.terms[d] for d in library.terms})
    with tempfile.TemporaryDirectory() as scratch:
        paths = [str(p) for p in zigzags]
        default = model_by_cli(["identify", *FORMAT], paths, f"{scratch}/d.json")
        from shipid.data.io import read_log

        shown = {p.name: logs[p] for p in randoms}
        shown.update({p.name: read_log(p, fmt="osaka-frt", dt=0.5, start="auto", end="auto")
                      for p in zigzags[:2]})  # fmt: skip
        _contributions(default, shown)
        makers = {
            "identify (default)": default,
            "select, the constant in surge alone": model_by_cli(
                ["select", *FORMAT, "--quiet", "--library", _spec(surge_constant)], paths,
                f"{scratch}/s.json"),
            "the default's terms, the constant of v̇ and ṙ as n|n|": model_by_cli(
                ["identify", *FORMAT, "--model", _side_constant_as_nn(default.structure)], paths,
                f"{scratch}/n.json"),
        }  # fmt: skip
        print("\nTrained on the nine zig-zag files; the two 35° turns (closed loop) and the four "
              "random runs (free run)\n")  # fmt: skip
        print("| model | 35° TD off: median, mean |abs| [%] | steady r off: median, mean |abs| "
              "[%] | random runs: r error std / r std, median | r rms error / r rms: median, "
              "each |")  # fmt: skip
        print("|---|---|---|---|---|")
        for name, model in makers.items():
            if model is None:
                print(f"| {name} | failed | | | |")
                continue
            errors, ratios = _judged(model, turns, randoms, logs)
            td, r = np.array(errors[0::2]), np.array(errors[1::2])
            std, rms = np.array(ratios).T
            print(f"| {name} | {np.nanmedian(td):+.0f}, {np.nanmean(np.abs(td)):.0f} | "
                  f"{np.nanmedian(r):+.0f}, {np.nanmean(np.abs(r)):.0f} | {np.median(std):.2f} | "
                  f"{np.median(rms):.2f}: " + ", ".join(f"{x:.2f}" for x in rms) + " |")
        _leave_one_out(zigzags, turns, randoms, logs, scratch)
    print(f"\n{time.perf_counter() - t0:.0f} s")


def _side_constant_as_nn(structure: ModelStructure) -> str:
    """``structure`` with the constant of v̇ and ṙ written n|n|, as a ``--model`` text."""
    nn = parse_term("|n|*n").text
    return _spec(ModelStructure("the constant of v̇ and ṙ as n|n|", {
        d: tuple(dict.fromkeys(nn if (t == "1" and d != "u") else t for t in ts))
        for d, ts in structure.terms.items()}))  # fmt: skip


def _leave_one_out(zigzags, turns, randoms, logs, scratch: str) -> None:
    """The same on every eight of the nine files whose default holds a side constant."""
    print("\nEvery eight of the nine files whose default model holds a constant in v̇ or ṙ: "
          "the default, and its terms refitted with that constant written n|n|\n")
    print("| left out | model | 35° TD off, stbd, port [%] | steady r off, stbd, port [%] | "
          "random runs' r rms error / r rms |")  # fmt: skip
    print("|---|---|---|---|---|")
    for left in zigzags:
        paths = [str(p) for p in zigzags if p != left]
        default = model_by_cli(["identify", *FORMAT], paths, f"{scratch}/d.json")
        if default is None or not any("1" in default.structure.terms.get(d, ()) for d in "vr"):
            continue
        refit = model_by_cli(["identify", *FORMAT, "--model",
                              _side_constant_as_nn(default.structure)], paths,
                             f"{scratch}/n.json")  # fmt: skip
        for name, model in (("default", default), ("side constant as n|n|", refit)):
            if model is None:
                print(f"| {left.stem[-8:]} | {name} | failed | | |")
                continue
            errors, ratios = _judged(model, turns, randoms, logs)
            print(f"| {left.stem[-8:]} | {name} | " + ", ".join(f"{x:+.0f}" for x in errors[0::2])
                  + " | " + ", ".join(f"{x:+.0f}" for x in errors[1::2]) + " | "
                  + ", ".join(f"{b:.2f}" for _, b in ratios) + " |")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main()
