"""Figures of the paper's set: rudder and heading of the training zig-zag, measured vs simulated
u, v, r per manoeuvre, the error signals, and the x–y track."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from shipid.outputs import OutputSet, atomic_write  # noqa: E402
from shipid.trials.indices import track  # noqa: E402

LABELS = {"u": "surge u [m/s]", "v": "sway v [m/s]", "r": "yaw rate r [rad/s]"}


FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}


def _save(fig, path: str | Path, out: OutputSet | None = None) -> Path:
    """Save ``fig`` by the extension of ``path`` (PNG, SVG, PDF), staged in ``out`` if given."""
    fmt = FORMATS.get(Path(path).suffix.lower(), "png")

    def writer(p: Path) -> None:
        fig.savefig(p, format=fmt, dpi=110, bbox_inches="tight")

    try:
        return out.write(path, writer) if out is not None else atomic_write(path, writer)
    finally:
        plt.close(fig)


def rudder_and_heading(log: pd.DataFrame, path: str | Path, title: str = "",
                       out: OutputSet | None = None) -> Path:  # fmt: skip
    psi, _, _ = track(log)
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(log["t"], np.degrees(log["delta"]), label="rudder δ [deg]")
    ax.plot(log["t"], np.degrees(psi - psi[0]), label="heading change ψ − ψ0 [deg]")
    ax.set_xlabel("t [s]")
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(title or "training zig-zag: rudder and heading")
    return _save(fig, path, out)


def measured_vs_simulated(measured: pd.DataFrame, simulated: pd.DataFrame, path: str | Path,
                          title: str = "", out: OutputSet | None = None) -> Path:  # fmt: skip
    fig, axes = plt.subplots(3, 2, figsize=(11, 7), sharex=True)
    n = len(simulated)
    for i, s in enumerate(("u", "v", "r")):
        ax = axes[i, 0]
        ax.plot(measured["t"], measured[s], lw=0.8, color="0.5", label="measured")
        ax.plot(simulated["t"], simulated[s], lw=1.4, color="C0", label="simulated")
        ax.set_ylabel(LABELS[s])
        ax.grid(alpha=0.3)
        err = measured[s].to_numpy()[:n] - simulated[s].to_numpy()
        axes[i, 1].plot(simulated["t"], err, lw=0.8, color="C3")
        axes[i, 1].set_ylabel(f"error in {s}")
        axes[i, 1].grid(alpha=0.3)
    axes[0, 0].legend(loc="best", fontsize=8)
    axes[2, 0].set_xlabel("t [s]")
    axes[2, 1].set_xlabel("t [s]")
    fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path, out)


def tracks(logs: dict[str, pd.DataFrame], path: str | Path, title: str = "x–y track",
           out: OutputSet | None = None) -> Path:  # fmt: skip
    fig, ax = plt.subplots(figsize=(6, 6))
    for label, log in logs.items():
        _, x, y = track(log)
        ax.plot(y, x, label=label)  # east to the right, north up
    ax.set_xlabel("y (east) [m]")
    ax.set_ylabel("x (north) [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    return _save(fig, path, out)
