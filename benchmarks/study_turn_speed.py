"""What carries the miss of the 35° turns predicted from one Esso Osaka zig-zag (issue #10): the
speed the model keeps in the turn, or its yaw rate. A steady turn is 2U/|r| across, so the two
factors say which equation to look at; ``validate`` now says which (``_turn_notes``).

1. The default ``identify`` on each of the nine zig-zag files, judged on the two ±35° turns
   (closed loop): the tactical diameter's error, the speed in the steady turn and the steady yaw
   rate over the measured ones, and what ``validate``'s note names; the other eight zig-zags'
   yaw-rate error over their spread beside.
2. The same structure with the surge's turn terms pinned where the particulars put them
   (tried, not kept): v·r at (m + m_y)/(m + m_x) ± 5 % (m_y from Clarke et al. 1983's Y′v̇, m_x
   5 % of m, as the Esso 190 000 dwt tanker's m11 = 1.05), r² in [0, 2 x_G m/(m + m_x)], and
   ``--constraints signs`` (the rudder's drag δ² ≤ 0 among them).
3. Going astern: which default models ``identify`` warns of in a crash stop, against how many of
   the four random runs (astern spans in each) their free runs diverge in.
4. What ``validate``'s note advises: each file with one 35° turn among the training logs, judged
   on the other turn.

Run: .venv/bin/python benchmarks/study_turn_speed.py
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import tempfile
import time
import warnings

import numpy as np
from esso_logs import DATA

from shipid.cli import main as shipid
from shipid.data.formats import ESSO_OSAKA_MODEL
from shipid.data.particulars import Particulars
from shipid.evaluation.validate import validate
from shipid.identification.priors import clarke_derivatives
from shipid.reporting.modelfile import load_model
from shipid.trials.reading import read_trial_log

X_SHARE = 0.05  # m_x / m


def surge_turn_bounds(p: Particulars) -> list[str]:
    """``--bound`` options holding the surge's v·r and r² where the particulars put them."""
    m = p.mass if p.mass is not None else p.rho * p.volume
    m_y = -0.5 * p.rho * p.length**3 * clarke_derivatives(p)["Yvdot"]
    m_x = X_SHARE * m
    vr = (m + m_y) / (m + m_x)
    rr = p.xg * m / (m + m_x)
    return ["--bound", f"u: v*r >= {0.95 * vr:.4f}", "--bound", f"u: v*r <= {1.05 * vr:.4f}",
            "--bound", "u: r*r >= 0", "--bound", f"u: r*r <= {2 * rr:.4f}",
            "--constraints", "signs"]  # fmt: skip


def _fit(argv: list[str], out: str, stderr: io.StringIO | None = None) -> bool:
    with contextlib.redirect_stdout(io.StringIO()), \
            contextlib.redirect_stderr(stderr if stderr is not None else io.StringIO()):
        return shipid([*argv, "-o", out]) == 0


def _diverged(model, logs: dict) -> int:
    """How many of ``logs`` the model's free run diverges in."""
    runs = (validate(model, log, start_draws=False)[0] for log in logs.values())
    return sum(v.simulation is None or v.simulation.diverged for v in runs)


def _structure_flags(name: str) -> list[str]:
    """``--model`` and the drag's flag that refit the structure ``name`` a default chose."""
    spec = re.sub(r" \(.*", "", name)
    crossflow = "+crossflow(" in spec
    spec = re.sub(r"\+crossflow\([^)]*\)", "", spec)
    return ["--model", spec, "--crossflow" if crossflow else "--no-crossflow"]


def _judge(model, turns: dict, zigzags: dict) -> tuple[list[dict], float]:
    """Per turn: TD error [%], speed and yaw-rate ratios, the note's attribution; and the
    held-out zig-zags' median yaw-rate error over their spread."""
    rows = []
    for log in turns.values():
        v = validate(model, log, start_draws=False)[0]
        m, c = v.indices["measured"], v.indices.get("closed_loop") or {}
        note = next((w for w in v.warnings if "steady turn is" in w), "")
        named = next((k for k in ("the speed", "the yaw rate", "both") if f"is mostly {k}" in
                      note or f"miss is {k}" in note), "–")  # fmt: skip
        try:
            rows.append({"td": 100 * (c["tactical_diameter"] / m["tactical_diameter"] - 1),
                         "speed": c["steady_speed"] / m["steady_speed"],
                         "yaw": abs(c["steady_yaw_rate"] / m["steady_yaw_rate"]),
                         "named": named})  # fmt: skip
        except (KeyError, TypeError):
            rows.append({"td": np.inf, "speed": np.nan, "yaw": np.nan, "named": "no turn"})
    errors = []
    for log in zigzags.values():
        v = validate(model, log, start_draws=False)[0]
        bad = v.error is not None or v.simulation is None or v.simulation.diverged
        errors.append(np.inf if bad else v.metrics["r"]["std"] / float(np.std(log["r"])))
    return rows, float(np.median(errors))


def main() -> None:
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    warnings.simplefilter("ignore")
    start = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    zig_files = sorted((DATA / "zigzag").glob("*.csv"))
    turns = {f: read_trial_log(f, fmt="osaka-frt") for f in sorted((DATA / "turning").glob("*.csv"))}
    zigzags = {f: read_trial_log(f, fmt="osaka-frt") for f in zig_files}
    bounds = surge_turn_bounds(Particulars(**ESSO_OSAKA_MODEL))
    print("surge pinned:", " ".join(bounds), "\n")
    print("One zig-zag file each; the two 35° turns closed loop: tactical diameter error, speed "
          "in the steady turn and steady yaw rate over the measured, what validate's note names; "
          "the other zig-zags' yaw-rate error / spread (median)\n")
    print("| file | made by | 35° TD | speed in the turn | yaw rate | note names | zig-zags r |")
    print("|---|---|---|---|---|---|---|")
    randoms = {f: read_trial_log(f, fmt="osaka-frt")
               for f in sorted((DATA / "random").glob("*.csv"))}  # fmt: skip
    summary: dict[str, dict[str, list]] = {}
    astern: list[tuple[str, bool, int]] = []
    with tempfile.TemporaryDirectory() as tmp:
        out = f"{tmp}/m.json"
        for z in zig_files:
            err = io.StringIO()
            if not _fit(["identify", "--format", "osaka-frt", str(z)], out, err):
                print(f"| {z.stem[-8:]} | default failed | | | | | |")
                continue
            astern.append((z.stem[-8:], "crash stop" in err.getvalue(),
                           _diverged(load_model(out), randoms)))
            structure = load_model(out).structure.name
            pinned = ["identify", "--format", "osaka-frt", str(z),
                      *_structure_flags(structure), *bounds]  # fmt: skip
            for label, argv in (("default", None), ("surge pinned", pinned)):
                if argv is not None and not _fit(argv, out):
                    print(f"| {z.stem[-8:]} | {label} failed | | | | | |")
                    continue
                others = {f: log for f, log in zigzags.items() if f != z}
                rows, zz = _judge(load_model(out), turns, others)
                s = summary.setdefault(label, {"td": [], "zz": [], "named": [], "speed": []})
                s["td"] += [r["td"] for r in rows]
                s["speed"] += [r["speed"] for r in rows if abs(r["yaw"] - 1) <= 0.1]
                s["zz"].append(zz)
                s["named"] += [r["named"] for r in rows]
                made = f"{label}: {structure}" if argv is None else label
                print(f"| {z.stem[-8:]} | {made} | "
                      + " | ".join(", ".join(fmt.format(r[k]) for r in rows) for k, fmt in
                                   (("td", "{:+.0f} %"), ("speed", "{:.2f}"), ("yaw", "{:.2f}"),
                                    ("named", "{}")))
                      + f" | {zz:.3f} |", flush=True)  # fmt: skip
    print()
    for label, s in summary.items():
        td = np.abs(np.array(s["td"]))
        finite = td[np.isfinite(td)]
        counts = {k: s["named"].count(k) for k in ("the speed", "the yaw rate", "both", "–")}
        print(f"{label}: 35° TD |error| median {np.median(finite):.0f} %, mean {np.mean(finite):.0f} % "
              f"(largest {finite.max():.0f} %, {td.size - finite.size} without); held-out "
              f"zig-zags' r / spread {np.median(s['zz']):.3f}; validate's note names the speed "
              f"{counts['the speed']}, the yaw rate {counts['the yaw rate']}, both "
              f"{counts['both']}, none (within 10 %) {counts['–']} of {len(s['named'])}; where "
              f"the yaw rate came within 10 % ({len(s['speed'])} turns) the speed in the turn "
              f"was {min(s['speed']):.2f}–{max(s['speed']):.2f} times the measured")
    print("\nGoing astern: the default models identify warns of in a crash stop, and the random "
          "runs (of 4) their free runs diverge in\n")
    print("| file | crash-stop warning | random runs diverging |")
    print("|---|---|---|")
    for name, warned, diverged in astern:
        print(f"| {name} | {'yes' if warned else 'no'} | {diverged} |")
    turn_with_other(zig_files, turns)
    print(f"\n{time.perf_counter() - start:.0f} s")


def turn_with_other(zig_files, turns: dict) -> None:
    """Each zig-zag file alone and with one 35° turn among the training logs, judged on the
    other turn (closed loop): tactical diameter error and the speed in the steady turn over the
    measured."""
    print("\nWhat a turning log among the training logs does: the held-out turn's tactical "
          "diameter error, the speed in its steady turn over the measured\n")
    print("| file | held-out turn | the file alone | with the other turn |")
    print("|---|---|---|---|")
    files = list(turns)
    results: dict[str, list[tuple[float, float]]] = {"alone": [], "with": []}

    def held_out(model_path: str, held) -> tuple[float, float]:
        v = validate(load_model(model_path), turns[held], start_draws=False)[0]
        m, c = v.indices["measured"], v.indices.get("closed_loop") or {}
        try:
            return (100 * (c["tactical_diameter"] / m["tactical_diameter"] - 1),
                    c["steady_speed"] / m["steady_speed"])  # fmt: skip
        except (KeyError, TypeError):
            return np.inf, np.nan

    def cell(label: str, judged: tuple[float, float] | None) -> str:
        if judged is None:
            return "failed"
        results[label].append(judged)
        td, speed = judged
        return "no turn" if not np.isfinite(td) else f"{td:+.0f} %, {speed:.2f}"

    with tempfile.TemporaryDirectory() as tmp:
        out = f"{tmp}/m.json"
        for z in zig_files:
            # The file alone is one model, judged on each turn (fitted once, not per turn).
            alone = ({held: held_out(out, held) for held in files}
                     if _fit(["identify", "--format", "osaka-frt", str(z)], out) else None)
            for trained, held in ((files[0], files[1]), (files[1], files[0])):
                with_turn = (held_out(out, held) if _fit(
                    ["identify", "--format", "osaka-frt", str(z), str(trained)], out) else None)
                cells = [cell("alone", None if alone is None else alone[held]),
                         cell("with", with_turn)]  # fmt: skip
                print(f"| {z.stem[-8:]} | {held.stem[-8:]} | {' | '.join(cells)} |", flush=True)
    print()
    for label, rows in results.items():
        td = np.abs(np.array([r[0] for r in rows]))
        finite = td[np.isfinite(td)]
        speeds = np.array([r[1] for r in rows if np.isfinite(r[0])])
        inner = speeds[(speeds >= 0.6) & (speeds <= 1.5)]
        print(f"{label}: held-out turn's TD |error| median {np.median(finite):.0f} %, mean "
              f"{np.mean(finite):.0f} % (largest {finite.max():.0f} %, {td.size - finite.size} "
              f"without); speed in the turn {speeds.min():.2f}–{speeds.max():.2f} times the "
              f"measured, within 0.6–1.5 in {inner.size} of {speeds.size}")


if __name__ == "__main__":
    main()
