"""Long logs: indices, validation and reading must be linear in the log length (issue #11 item 19).

A zig-zag of the scale ship is simulated at 0.01 s for N samples (hundreds of reversals), then
timed: ``manoeuvre_indices`` (detection, switch heading, events, smoothed track) and ``validate``
(free run, indices of both logs, the closed-loop replica), and reading it back from CSV. The
baseline is the same work on the shortest log, scaled by the length ratio: a ratio near 1 means
linear time (before the fix: 200 k rows 7.8 s, 500 k 37.7 s, 2 M not done in 500 s).

Then ``validate`` of a 45 000-sample zig-zag with the model's ensemble (the 200 covariance draws
of the output-error fit a plain ``shipid identify`` writes for a noisy log): each draw is one
more free run and closed-loop replica, and their indices, against the same validation without
the ensemble.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
import tempfile
import time

from shipid.data.io import read_log, write_log
from shipid.evaluation.validate import validate
from shipid.identification.identify import identify
from shipid.trials.indices import manoeuvre_indices
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, scale_ship

SIZES = (200_000, 500_000, 2_000_000)


def timed(f):
    t0 = time.perf_counter()
    out = f()
    return time.perf_counter() - t0, out


def main() -> None:
    ship = scale_ship(rudder_rate_deg=9.6)
    fit = identify(zigzag(ship, 20, 20, duration=90, dt=0.2, method="euler", approach=2.0).log,
                   drop={"u": ["r^2"]})  # fmt: skip
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| samples | simulate (s) | indices (s) | validate (s) | read CSV (s) | "
          "indices µs/sample | validate µs/sample | ratio to linear (indices / validate) |")
    print("|---|---|---|---|---|---|---|---|")
    base = None
    with tempfile.TemporaryDirectory() as tmp:
        for n in SIZES:
            t_sim, res = timed(lambda n=n: zigzag(ship, 10, 10, duration=(n - 1) * 0.01, dt=0.01))
            log = res.log
            t_ind, ind = timed(lambda log=log: manoeuvre_indices(log))
            assert ind["kind"] == "zigzag"
            t_val, vals = timed(lambda log=log: validate(fit.model, log))
            assert vals[0].error is None
            path = write_log(log, os.path.join(tmp, "long.csv"))
            t_read, _ = timed(lambda path=path: read_log(path))
            per = (t_ind / n * 1e6, t_val / n * 1e6)
            if base is None:
                base = per
            print(f"| {n:.0e} | {t_sim:.2f} | {t_ind:.2f} | {t_val:.2f} | {t_read:.2f} | "
                  f"{per[0]:.2f} | {per[1]:.2f} | {per[0] / base[0]:.2f} / {per[1] / base[1]:.2f} |")
            sys.stdout.flush()
        ensemble_table(ship, tmp)


def ensemble_table(ship, tmp: str) -> None:
    from shipid.cli import main as shipid
    from shipid.reporting.modelfile import ensemble_from_document, load_document, model_from_document

    trial = PAPER_IMU.apply(zigzag(ship, 20, 20, duration=90, dt=0.2, method="euler").log, seed=1)
    train, out = os.path.join(tmp, "train.csv"), os.path.join(tmp, "model.json")
    write_log(trial, train)
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert shipid(["identify", train, "-o", out]) == 0
    doc = load_document(out)
    model = model_from_document(doc, out, "model")
    ens = ensemble_from_document(doc, out, model)
    log = zigzag(ship, 20, 20, duration=4500, dt=0.1).log
    t_plain, _ = timed(lambda: validate(model, log))
    t_ens, vals = timed(lambda: validate(model, log, ensemble=ens))
    assert vals[0].intervals.get("closed_loop")
    members = len(ens.members())
    print(f"\nvalidate with the model's ensemble ({members} covariance draws of its output-error "
          "fit), a 20/20 zig-zag at 0.1 s\n")  # fmt: skip
    print("| samples | validate (s) | with the ensemble (s) | per draw (ms) |")
    print("|---|---|---|---|")
    print(f"| {len(log)} | {t_plain:.2f} | {t_ens:.2f} | {1e3 * (t_ens - t_plain) / members:.1f} |")


if __name__ == "__main__":
    main()
