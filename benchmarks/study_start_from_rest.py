"""Smaller zig-zags after a start from rest: does the trial reading find their orders?

The Esso Osaka's zig-zag files start from rest, the helm put over by up to 22° as the ship
gathers speed, then 15–30° orders. Each file read whole, its rudder after the execute scaled to
10° and 5° (the approach's corrections kept as logged; the heading is the file's own, so the
switch headings and overshoots are those of the real run): ``--start auto --end auto`` and the
zig-zag's facts against the real file's. Before 2026-11-30 (b415d31, e4be4c8, c255d84) the orders were
read against the largest deflection, corrections included: see ``benchmarks/README.md``.

Run: .venv/bin/python benchmarks/study_start_from_rest.py
"""

from __future__ import annotations

import math
import os
import warnings

from esso_logs import raw_files

from shipid.data.io import read_log
from shipid.data.trim import rudder_execute_time, trim
from shipid.errors import ShipidError
from shipid.trials.indices import zigzag_indices
from shipid.trials.trial import describe_trial


def main() -> None:
    files = raw_files()
    if files is None:
        return
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| orders | file | approach's largest helm [°] | cut [s] (real file's) | read as | "
          "execute [s] (real) | overshoots [°] (real) |")
    print("|---|---|---|---|---|---|---|")
    found = {}
    for target in (10.0, 5.0):
        for path in files[0]:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                log = read_log(path, fmt="osaka-frt")
            t = log["t"].to_numpy()
            t_exec = rudder_execute_time(log)
            real = describe_trial(log)
            scaled = log.copy()
            after = t >= t_exec
            scaled.loc[after, "delta"] *= math.radians(target) / real.amplitude
            helm = math.degrees(float(abs(log["delta"].to_numpy()[~after]).max()))
            cut = trim(log, start="auto", end="auto")
            span = f"{cut['t'].iloc[0]:.1f}–{cut['t'].iloc[-1]:.1f}"
            a = zigzag_indices(cut)
            try:
                mine = trim(scaled, start="auto", end="auto")
            except ShipidError as exc:
                print(f"| {target:g}° | {path.stem[-8:]} | {helm:.1f} | refused ({span}) | "
                      f"{str(exc).split(': ', 1)[1][:60]}… | – | – |")
                continue
            tr = describe_trial(mine)
            ok = tr.kind == "zigzag"
            found[target] = found.get(target, 0) + ok
            b = zigzag_indices(mine) if ok else {}
            shoots = (f"{b['first_overshoot_deg']:.2f}, {b['second_overshoot_deg']:.2f} "
                      f"({a['first_overshoot_deg']:.2f}, {a['second_overshoot_deg']:.2f})"
                      if ok else "–")  # fmt: skip
            print(f"| {target:g}° | {path.stem[-8:]} | {helm:.1f} | {mine['t'].iloc[0]:.1f}–"
                  f"{mine['t'].iloc[-1]:.1f} ({span}) | {tr.kind} | {tr.execute_time:.1f} "
                  f"({describe_trial(cut).execute_time:.1f}) | {shoots} |")
    print("\n" + "; ".join(f"{n} of {len(files[0])} read as zig-zags at {t:g}°"
                           for t, n in found.items()))  # fmt: skip


if __name__ == "__main__":
    main()
