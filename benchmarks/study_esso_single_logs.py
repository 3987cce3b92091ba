"""The default `shipid identify` on one Esso Osaka zig-zag file, as it comes (no flags but
`--format`), judged on the other eight zig-zags and the two 35° turns, each read as the
README's `import` cuts it; then on every pair of zig-zag files, judged on the other nine logs.
What a user with one or two trials gets: which structure, and how far its free runs miss logs
it never saw (yaw rate error std over the log's spread; most of them at another propeller
speed, which a structure without n cannot know). For the pairs also the 35° turns' tactical
diameters (closed loop), the four random runs (read whole) and whether `identify` warned below
the logs' propeller speeds. Every held-out log is validated once per model.

Run: .venv/bin/python benchmarks/study_esso_single_logs.py
"""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import os
import tempfile
import time
import warnings

import numpy as np
from esso_logs import DATA

from shipid.cli import main as shipid
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_model
from shipid.trials.reading import read_trial_log


def main() -> None:
    warnings.simplefilter("ignore")
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    files = zigzags + sorted((DATA / "turning").glob("*.csv"))
    held = {f: read_trial_log(f, fmt="osaka-frt") for f in files}
    randoms = {f: read_trial_log(f, fmt="osaka-frt") for f in sorted((DATA / "random").glob("*.csv"))}
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| trained on | rps | structure (how) | held-out logs: r error / spread, median (worst) "
          "| the same, --no-rps-similarity | diverged | seconds |")
    print("|---|---|---|---|---|---|---|")
    start = time.perf_counter()
    other_rps = []  # (with, without similarity) on the held-out logs at another rps
    with tempfile.TemporaryDirectory() as tmp:
        out = f"{tmp}/m.json"
        for f in zigzags:
            t0 = time.perf_counter()
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):  # fmt: skip
                code = shipid(["identify", "--format", "osaka-frt", str(f), "-o", out])
            seconds = time.perf_counter() - t0
            if code:
                print(f"| {f.stem[-8:]} | | failed | | | | |")
                continue
            how = (json.loads(open(out).read())["identification"].get("structure_choice")
                   or {}).get("how")  # fmt: skip
            model = load_model(out)
            others = {g: log for g, log in held.items() if g != f}
            errors = _errors(_validations(model, others), others)
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):  # fmt: skip
                shipid(["identify", "--format", "osaka-frt", str(f), "--no-rps-similarity",
                        "-o", f"{tmp}/plain.json"])  # fmt: skip
            plain_model = load_model(f"{tmp}/plain.json")
            plain = _errors(_validations(plain_model, others), others)
            finite = errors[np.isfinite(errors)]
            rps = float(np.median(held[f]["n"]))
            for g, a, b in zip(others, errors, plain, strict=True):
                if abs(float(np.median(held[g]["n"])) - rps) > 0.1:
                    other_rps.append((a, b))
            worst = f"{finite.max():.2f}" if finite.size else "–"
            print(f"| {f.stem[-8:]} | {rps:.4g} | {model.structure.name} ({how}) | "
                  f"{np.median(errors):.2f} ({worst}) | {np.median(plain):.2f} "
                  f"({plain[np.isfinite(plain)].max():.2f}) | {int(np.isinf(errors).sum())} of "
                  f"{len(errors)} | {seconds:.1f} |")
        pairs = np.array(other_rps)
        print(f"\nHeld-out logs at another propeller speed than the file's ({len(pairs)} runs): "
              f"r error / spread median {np.median(pairs[:, 0]):.2f} with the default's "
              f"advance-ratio similarity, {np.median(pairs[:, 1]):.2f} without "
              f"(--no-rps-similarity); better in {int(np.sum(pairs[:, 0] < pairs[:, 1]))}, worse "
              f"in {int(np.sum(pairs[:, 0] > pairs[:, 1]))}")
        print("\nEvery pair of zig-zag files, by how the default chose the structure: held-out "
              "logs' r error / spread, the median over the pairs of each pair's median, and the "
              "runs that diverged\n")
        print("| structure chosen | pairs | median r error / spread | diverged | 35° turns: "
              "tactical diameter, abs error median (largest) |")
        print("|---|---|---|---|---|")
        by_how: dict[str, list[tuple[float, int, int, np.ndarray]]] = {}
        warned: dict[bool, list[np.ndarray]] = {True: [], False: []}
        random_errors = []  # each pair's median over the random runs
        for a, b in itertools.combinations(zigzags, 2):
            said = io.StringIO()
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(said):
                code = shipid(["identify", "--format", "osaka-frt", str(a), str(b), "-o", out])
            if code:
                by_how.setdefault("failed", []).append((np.nan, 0, 0, np.empty(0)))
                continue
            choice = json.loads(open(out).read())["identification"].get("structure_choice") or {}
            model = load_model(out)
            how = choice.get("how")
            label = (f"{model.structure.name} ({how})" if how != "select"
                     else "terms chosen by select")  # fmt: skip
            others = {g: log for g, log in held.items() if g not in (a, b)}
            runs = _validations(model, others)
            errors = _errors(runs, others)
            turns = _turn_errors([v for g, v in zip(others, runs, strict=True) if "turn" in g.stem])
            by_how.setdefault(label, []).append(
                (float(np.median(errors)), int(np.isinf(errors).sum()), len(errors), turns))
            warned["below the logs' propeller speeds" in said.getvalue()].append(turns)
            random_errors.append(float(np.median(_errors(_validations(model, randoms), randoms))))
        for label, rows in sorted(by_how.items(), key=lambda kv: -len(kv[1])):
            medians = [r[0] for r in rows]
            turns = np.abs(np.concatenate([r[3] for r in rows]))
            print(f"| {label} | {len(rows)} | {np.median(medians):.2f} | "
                  f"{sum(r[1] for r in rows)} of {sum(r[2] for r in rows)} | "
                  f"{_turn_cell(turns)} |")  # fmt: skip
        every = np.abs(np.concatenate([r[3] for rows in by_how.values() for r in rows]))
        print(f"\nThe two 35° turns (closed loop) over the 36 pairs: tactical diameter "
              f"{_turn_cell(every)}, mean {np.mean(every[np.isfinite(every)]):.0f} %")
        print(f"The held-out logs' r error / spread, median over the pairs of each pair's median: "
              f"{np.median([r[0] for rows in by_how.values() for r in rows]):.3f}; the four "
              f"random runs' (read whole), {np.median(random_errors):.2f}")
        for flag, rows in warned.items():
            turns = np.abs(np.concatenate(rows)) if rows else np.empty(0)
            print(f"Pairs {'warned' if flag else 'not warned'} below the logs' propeller speeds "
                  f"(identify's warning): {len(rows)}, their turns {_turn_cell(turns)}")
    print(f"\n{time.perf_counter() - start:.0f} s")


def _validations(model, logs) -> list:
    """``validate`` of ``model`` on each of ``logs`` ({path: log}), once."""
    return [validate(model, log, start_draws=False)[0] for log in logs.values()]


def _turn_errors(runs, key: str = "tactical_diameter") -> np.ndarray:
    """The 35° turns' closed-loop error [%] in the index ``key`` (the tactical diameter) of
    their validations ``runs`` (inf where there is none)."""
    out = []
    for v in runs:
        try:
            out.append(100 * (v.indices["closed_loop"][key] / v.indices["measured"][key] - 1))
        except (KeyError, TypeError):
            out.append(np.inf)
    return np.array(out)


def _turn_cell(errors: np.ndarray) -> str:
    """|error| median (largest) [%], and how many turns had no index."""
    finite = errors[np.isfinite(errors)]
    none = len(errors) - len(finite)
    cell = f"{np.median(finite):.0f} % ({finite.max():.0f} %)" if len(finite) else "–"
    return cell + (f", {none} without" if none else "")


def _errors(runs, logs) -> np.ndarray:
    """The free runs' yaw rate error std over each log's spread, from their validations
    ``runs`` (inf where one diverged)."""
    out = []
    for v, log in zip(runs, logs.values(), strict=True):
        diverged = v.error is not None or v.simulation.diverged
        out.append(np.inf if diverged else v.metrics["r"]["std"] / float(np.std(log["r"])))
    return np.array(out)


if __name__ == "__main__":
    main()
