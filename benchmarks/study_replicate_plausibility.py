"""How many bootstrap replicates fail the plausibility checks their model passes (issue #10,
honest uncertainty): `identify --bootstrap 100` counts them (`members_plausibility`, in the
model file's `uncertainty.plausibility`) and warns above a tenth.

1. The default `identify --bootstrap 100` (10 s blocks) on each of the nine Esso Osaka zig-zag
   files alone, with the wall time against the same command with the count skipped
   (`--bootstrap` without it costs what the count adds on top).
2. The demo's training zig-zag of the paper's ship, and the KVLCC2's MARIN zz 20° with the
   README's physics (particulars, Clarke prior, sign constraints, γ by blocks).

Run: .venv/bin/python benchmarks/study_replicate_plausibility.py
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
import time
from pathlib import Path

from esso_logs import DATA

import shipid.cli.identify as cli_identify
import shipid.identification.uncertainty as uncertainty
from shipid.cli import main as shipid

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data"
REPLICATES = 100
CHECKED = cli_identify._replicates_checked
DEFAULT_LIMIT = uncertainty.CHECKED_REPLICATES


def identify(args: list[str], out: Path, count: bool = True, limit: int = DEFAULT_LIMIT
             ) -> tuple[dict, float]:  # fmt: skip
    """The model file's replicate record after ``identify ARGS --bootstrap`` and the wall time;
    ``limit``: how many replicates the count checks (identify's own, or all for the share);
    ``count`` False: the same run with the count skipped (its cost is the difference)."""
    if not count:
        cli_identify._replicates_checked = lambda *a, **k: {
            "checked": 0, "implausible": 0, "reasons": {}}
    uncertainty.CHECKED_REPLICATES = limit  # the count's limit, this run
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            code = shipid(["identify", *args, "--bootstrap", str(REPLICATES), "-o", str(out)])
    finally:
        cli_identify._replicates_checked = CHECKED
        uncertainty.CHECKED_REPLICATES = DEFAULT_LIMIT
    took = time.perf_counter() - t0
    if code:
        raise SystemExit(f"identify {' '.join(args)} failed")
    return json.loads(out.read_text())["uncertainty"].get("plausibility") or {}, took


def row(name: str, args: list[str], out: Path) -> dict:
    record = identify(args, out, limit=REPLICATES)[0]  # all of them, for the share
    with_count = identify(args, out)[1]  # as identify counts: the first DEFAULT_LIMIT
    _, without = identify(args, out, count=False)
    reasons = "; ".join(f"{k} ({v})" for k, v in list(record["reasons"].items())[:3]) or "–"
    print(f"| {name} | {record['implausible']} of {record['checked']} | {reasons} | "
          f"{with_count:.2f} | {without:.2f} |", flush=True)
    return record


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; "
          f"{REPLICATES} replicates\n")
    print("| training log | replicates failing checks the model passes | most common reasons | "
          "identify --bootstrap 100, 40 checked (s) | without the count (s) |")
    print("|---|---|---|---|---|")
    t0 = time.perf_counter()
    shares = []
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "m.json"
        for path in sorted((DATA / "zigzag").glob("*.csv")):
            record = row(f"Esso {path.stem}", ["--format", "osaka-frt", str(path)], out)
            shares.append(record["implausible"] / record["checked"])
        demo = Path(tmp) / "demo"
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            shipid(["demo", "--out", str(demo)])
        row("paper's ship, the demo's 20/20 zig-zag", [str(demo / "zigzag-20-20-training.csv")],
            out)  # fmt: skip
        kv = SHARED / "kvlcc2-marin"
        row("KVLCC2 MARIN zz 20°, the README's physics",
            ["--format", "simman-marin", "--scale", "45.7", "--dt", "0.2", "--model",
             "blanke-speed", "--particulars", str(kv / "ship_data.yml"), "--prior", "clarke",
             "--constraints", "signs", "--gamma", "auto", "--cv", "blocks:4",
             str(kv / "MARIN_FREE_KVLCC2_zz_20_m.dat")], out)  # fmt: skip
    shares.sort()
    print(f"\nEsso one-file models: {100 * shares[0]:.0f}–{100 * shares[-1]:.0f} % of the "
          f"replicates fail (median {100 * shares[len(shares) // 2]:.0f} %)")
    print(f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
