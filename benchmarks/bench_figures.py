"""The figures drawn for every validated log (``validate --plots``, the HTML report, the demo):
saved with their fixed margins against the same figures laid out by matplotlib's tight layout
(what they used, and what the other figures still use), in the same process, PNG at 100 dpi.

Run: .venv/bin/python benchmarks/bench_figures.py
"""

from __future__ import annotations

import io
import os
from unittest import mock

import matplotlib

matplotlib.use("Agg")

from timing import best_of  # noqa: E402

from shipid.demo import TRAINING, synthesise_trials  # noqa: E402
from shipid.evaluation.metrics import residual_correlations  # noqa: E402
from shipid.evaluation.validate import validate  # noqa: E402
from shipid.identification.identify import identify  # noqa: E402
from shipid.reporting import plots  # noqa: E402


def _tight(fig, **adjust) -> None:
    fig.set_layout_engine("tight")


def main() -> None:
    logs = synthesise_trials()
    model = identify(logs[TRAINING]).model
    log = logs["turning δ = −20°"]
    sim = validate(model, [log])[0].simulation.log
    analysis = {s: residual_correlations(log[s].to_numpy()[: len(sim)], sim[s].to_numpy(),
                                         log["delta"].to_numpy()[: len(sim)]) for s in "uvr"}

    figures = {
        "measured vs simulated (u, v, r, errors, rudder, track)":
            lambda: plots.measured_vs_simulated(log, sim, io.BytesIO(), "turn"),
        "residual analysis (3 × 2 correlograms)":
            lambda: plots.residuals(analysis, io.BytesIO(), "turn"),
    }  # fmt: skip
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; best of 5, PNG "
          "into memory\n")  # fmt: skip
    print("| figure | tight layout (s) | fixed margins (s) | speed-up |")
    print("|---|---|---|---|")
    for name, draw in figures.items():
        draw()  # fonts and caches warm
        with mock.patch.object(plots, "_fixed_margins", _tight):
            tight = best_of(draw, 5)
        fixed = best_of(draw, 5)
        print(f"| {name} | {tight:.3f} | {fixed:.3f} | {tight / fixed:.2f}× |")


if __name__ == "__main__":
    main()
