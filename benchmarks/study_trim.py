"""Where a model is linearised (``shipid linearise``, the autopilot's tuning): rudder amidships
against its trimmed straight run (the rudder and drift that hold it straight).

The README's Esso Osaka model (`select` from the nine zig-zags and three random runs, Δk 0.5 s,
the README's library, ``--average``) at its own steady speed at 16.67 rps, and the README's
three KVLCC2 structures from the MARIN 20° zig-zag (Δk 0.2 s, the prefilter ``identify``
chooses) at the trial's approach speed: Nomoto's K and T1 at each point.

Run: .venv/bin/python benchmarks/study_trim.py
"""

from __future__ import annotations

import contextlib
import io
import math
import warnings
from pathlib import Path

from esso_logs import README_HELD, esso_logs, run_with_files

from shipid.cli import main as cli
from shipid.control.linear import nomoto
from shipid.data.io import read_log, write_log
from shipid.dynamics.equilibrium import steady_approach
from shipid.reporting.modelfile import load_document, load_model, training_conditions

MARIN = Path(__file__).resolve().parents[2] / "shared" / "data" / "kvlcc2-marin"


def _quiet(argv) -> None:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert cli([str(a) for a in argv]) == 0, argv


def _row(name: str, model, speed: float, rps: float | None) -> str:
    amid, trimmed = nomoto(model, speed, rps, trimmed=False), nomoto(model, speed, rps)
    trim = trimmed["trim"]
    held = "none" if trim is None else \
        f"{math.degrees(trim['delta']):.2f}°, {trim['v']:.3g} m/s"  # fmt: skip
    return (f"| {name} | {speed:.4g} m/s{'' if rps is None else f', {rps:.4g} rps'} | {held} | "
            f"{amid['K']:.3g}, {amid['T1']:.3g} s | {trimmed['K']:.3g}, {trimmed['T1']:.3g} s | "
            f"{100 * (trimmed['K'] / amid['K'] - 1):+.0f} % |")


def study(folder: Path) -> None:
    print("| model | speed | trim δ0, v0 | K, T1 at rudder amidships | K, T1 at the trim | K moved |")
    print("|---|---|---|---|---|---|")
    zz, rnd, _ = esso_logs(0.5)
    paths = [write_log(x, folder / f"zz_{k}.csv") for k, x in zz.items()]
    paths += [write_log(x, folder / f"rnd_{k}.csv") for k, x in rnd.items() if k != README_HELD]
    esso = folder / "esso.json"
    _quiet(["select", *paths, "--library", "low-speed+wind+propeller-asymmetry", "--average",
            "--quiet", "-o", esso])  # fmt: skip
    model = load_model(esso)
    cond = training_conditions(load_document(esso))
    app = steady_approach(model, cond["speed"], cond["rps"])
    print(_row("Esso Osaka (README recipe)", model, app.speed, app.rps))
    if not MARIN.is_dir():
        return
    log = MARIN / "MARIN_FREE_KVLCC2_zz_20_m.dat"
    speed = float(read_log(log, fmt="simman-marin", scale=45.7, dt=0.2)["u"].iloc[0])
    for structure in ("blanke-speed", "blanke-race", "blanke-race+race-damping"):
        out = folder / f"{structure}.json"
        _quiet(["identify", "--format", "simman-marin", "--scale", "45.7", "--dt", "0.2",
                "--model", structure, log, "-o", out])  # fmt: skip
        print(_row(f"KVLCC2 {structure}", load_model(out), speed, None))


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    run_with_files(study)
