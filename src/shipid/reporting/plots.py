"""Figures: measured vs simulated (u, v, r, their errors, rudder and heading, x–y tracks), the
residual analysis, and any set of logs; PNG, SVG or PDF by the file's extension. Every axis has its
unit; titles are the log's name, not the typed path."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from shipid.data.log import column_values
from shipid.outputs import OutputSet, atomic_write  # noqa: E402
from shipid.trials.indices import track  # noqa: E402

LABELS = {"u": "surge u [m/s]", "v": "sway v [m/s]", "r": "yaw rate r [rad/s]"}
ERROR_LABELS = {"u": "error in u [m/s]", "v": "error in v [m/s]", "r": "error in r [rad/s]"}
FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
DPI = 100


def _fixed_margins(fig, **adjust) -> None:
    """Margins set once instead of the tight layout, which measures every label by drawing the
    figure (40 % of the saving time of the figures drawn per log)."""
    from matplotlib.layout_engine import PlaceHolderLayoutEngine

    fig.set_layout_engine(PlaceHolderLayoutEngine(adjust_compatible=True, colorbar_gridspec=True))
    fig.subplots_adjust(**adjust)


def _save(fig, path, out: OutputSet | None = None):
    """Save ``fig`` by the extension of ``path`` (PNG, SVG, PDF), staged in ``out`` if given;
    a file-like ``path`` (e.g. ``io.BytesIO``) receives a PNG."""
    # Laid out once while drawing: ``bbox_inches="tight"`` would draw the figure twice.
    if fig.get_layout_engine() is None:
        fig.set_layout_engine("tight")
    if hasattr(path, "write"):
        try:
            fig.savefig(path, format="png", dpi=DPI)
            return path
        finally:
            plt.close(fig)
    fmt = FORMATS.get(Path(path).suffix.lower(), "png")

    def writer(p: Path) -> None:
        fig.savefig(p, format=fmt, dpi=DPI)

    try:
        return out.write(path, writer) if out is not None else atomic_write(path, writer)
    finally:
        plt.close(fig)


def _track_axes(ax, relative: bool = False, legend: bool = True) -> None:
    """North up, east right, equal scales; ``relative``: offsets from the first position."""
    ax.set_xlabel("east y − y0 [m]" if relative else "y (east) [m]")
    ax.set_ylabel("north x − x0 [m]" if relative else "x (north) [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8)


def rudder_and_heading(log: pd.DataFrame, path: str | Path, title: str = "",
                       out: OutputSet | None = None) -> Path:  # fmt: skip
    """Rudder angle and heading change of a log over time."""
    psi, _, _ = track(log)
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(log["t"], np.degrees(log["delta"]), label="rudder δ")
    ax.plot(log["t"], np.degrees(psi - psi[0]), label="heading change ψ − ψ0")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("angle [deg]")
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(title or "training zig-zag: rudder and heading")
    return _save(fig, path, out)


def measured_vs_simulated(measured: pd.DataFrame, simulated: pd.DataFrame, path: str | Path,
                          title: str = "", out: OutputSet | None = None,
                          bands: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
                          error_band=None,
                          tied: Mapping[str, pd.DataFrame] | None = None) -> Path:  # fmt: skip
    """u, v, r measured and simulated with their errors; rudder and heading; x–y tracks.
    ``bands``: {state: (lower, upper)} prediction band drawn around the simulation;
    ``error_band`` (``shipid.evaluation.error_band.ErrorBand``): its ± half-widths drawn on the
    errors; ``tied``: {structure: simulated log} of the structures that tied with the model's
    in ``identify``'s comparison, dashed beside its simulation (states, heading, track)."""
    tied = dict(tied or {})
    tied_style = {name: {"lw": 1.0, "ls": "--", "color": f"C{4 + k}", "label": f"{name} (tied)"}
                  for k, name in enumerate(tied)}  # fmt: skip
    fig = plt.figure(figsize=(12, 11))
    grid = fig.add_gridspec(4, 2, height_ratios=[1, 1, 1, 1.3])
    n = len(simulated)
    t_sim = column_values(simulated, "t")
    first = None
    for i, s in enumerate(("u", "v", "r")):
        ax = fig.add_subplot(grid[i, 0], sharex=first)
        first = first or ax
        ax.plot(measured["t"], measured[s], lw=0.8, color="0.5", label="measured")
        ax.plot(t_sim, simulated[s], lw=1.4, color="C0", label="simulated")
        for name, run in tied.items():
            ax.plot(run["t"], run[s], **tied_style[name])
        if bands and s in bands:
            lo, hi = bands[s][0][:n], bands[s][1][:n]
            bounded = np.isfinite(lo) & np.isfinite(hi)
            ax.fill_between(t_sim, np.where(bounded, lo, np.nan), np.where(bounded, hi, np.nan),
                            color="C0", alpha=0.2, lw=0, label="95 % prediction band")
            if not bounded.all():  # too many replicates diverged: the band has no edge there
                ax.fill_between(t_sim, 0, 1, where=~bounded, transform=ax.get_xaxis_transform(),
                                color="C3", alpha=0.08, lw=0, label="band not bounded")
        ax.set_ylabel(LABELS[s])
        ax.grid(alpha=0.3)
        err_ax = fig.add_subplot(grid[i, 1], sharex=first)
        err = column_values(measured, s)[:n] - column_values(simulated, s)
        err_ax.plot(t_sim, err, lw=0.8, color="C3")
        err_ax.axhline(0.0, color="0.3", lw=0.6)
        width = None if error_band is None else error_band.half_width[s]
        if width is not None and np.isfinite(width):
            for sign in (1, -1):
                err_ax.axhline(sign * width, color="C1", lw=0.9, ls="--",
                               label=f"cross-validated {100 * error_band.level:g} % error band"
                               if sign > 0 else None)  # fmt: skip
            if i == 0:
                err_ax.legend(loc="best", fontsize=8)
        err_ax.set_ylabel(ERROR_LABELS[s])
        err_ax.grid(alpha=0.3)
        if i == 0:
            ax.legend(loc="best", fontsize=8)
    ax = fig.add_subplot(grid[3, 0], sharex=first)
    psi_m, xm, ym = track(measured)
    psi_s, xs, ys = track(simulated)
    ax.plot(measured["t"], np.degrees(measured["delta"]), lw=1.0, color="C2", label="rudder δ")
    ax.plot(measured["t"], np.degrees(psi_m - psi_m[0]), lw=0.8, color="0.5",
            label="heading change, measured")  # fmt: skip
    ax.plot(t_sim, np.degrees(psi_s - psi_s[0]), lw=1.2, color="C0",
            label="heading change, simulated")  # fmt: skip
    tied_tracks = {name: track(run) for name, run in tied.items()}
    for name, (psi_t, _, _) in tied_tracks.items():
        ax.plot(tied[name]["t"], np.degrees(psi_t - psi_t[0]), **tied_style[name])
    ax.set_ylabel("angle [deg]")
    ax.set_xlabel("t [s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    tr = fig.add_subplot(grid[3, 1])
    tr.plot(ym - ym[0], xm - xm[0], color="0.5", lw=0.8, label="measured")
    tr.plot(ys - ys[0], xs - xs[0], color="C0", lw=1.2, label="simulated")
    for name, (_, xt, yt) in tied_tracks.items():
        tr.plot(yt - yt[0], xt - xt[0], **tied_style[name])
    _track_axes(tr, relative=True)
    fig.suptitle(title)
    # Drawn for every validated log: fixed margins (see _fixed_margins).
    _fixed_margins(fig, left=0.07, right=0.985, bottom=0.05, top=0.955, hspace=0.3, wspace=0.22)
    return _save(fig, path, out)


def residuals(analysis: Mapping[str, dict], path: str | Path, title: str = "",
              out: OutputSet | None = None) -> Path:  # fmt: skip
    """Autocorrelation of the error of each state and its cross-correlation with the rudder,
    with the 95 % band of white noise (``shipid.evaluation.metrics.residual_correlations``)."""
    fig, axes = plt.subplots(3, 2, figsize=(11, 7), sharex=True)
    for i, s in enumerate(("u", "v", "r")):
        a = analysis[s]
        lags = np.asarray(a["lags"])
        for j, key in enumerate(("autocorrelation", "cross_correlation_rudder")):
            ax = axes[i, j]
            ax.vlines(lags, 0, a[key], color="C0")
            ax.axhspan(-a["band"], a["band"], color="C1", alpha=0.25, lw=0)
            ax.set_ylabel(f"{s}: " + ("autocorrelation [-]" if j == 0 else "corr. with δ [-]"))
            ax.grid(alpha=0.3)
    axes[2, 0].set_xlabel("lag [samples]")
    axes[2, 1].set_xlabel("lag [samples]")
    fig.suptitle(title or "residual analysis (band: 95 % of white noise)")
    _fixed_margins(fig, left=0.08, right=0.985, bottom=0.08, top=0.93, hspace=0.15, wspace=0.25)
    return _save(fig, path, out)


def tracks(logs: dict[str, pd.DataFrame], path: str | Path, title: str = "x–y track",
           out: OutputSet | None = None) -> Path:  # fmt: skip
    """x–y tracks of several logs (north up, east right)."""
    fig, ax = plt.subplots(figsize=(6, 6))
    for label, log in logs.items():
        _, x, y = track(log)
        ax.plot(y, x, label=label)  # east to the right, north up
    _track_axes(ax)
    ax.set_title(title)
    return _save(fig, path, out)


def logs_figure(logs: Mapping[str, pd.DataFrame], path: str | Path, title: str = "",
                out: OutputSet | None = None) -> Path:  # fmt: skip
    """Any logs over one another: u, v, r, rudder, heading, propeller speed, and the track."""
    extra = any("n" in log.columns for log in logs.values())
    rows = 6 if extra else 5
    fig = plt.figure(figsize=(12, 2.2 * rows))
    grid = fig.add_gridspec(rows, 2, width_ratios=[2, 1])
    axes = [fig.add_subplot(grid[i, 0]) for i in range(rows)]
    track_ax = fig.add_subplot(grid[:, 1])
    for label, log in logs.items():
        t = column_values(log, "t")
        psi, x, y = track(log)
        for ax, s in zip(axes, ("u", "v", "r"), strict=False):
            ax.plot(t, log[s], lw=1.0, label=label)
        axes[3].plot(t, np.degrees(log["delta"]), lw=1.0, label=label)
        axes[4].plot(t, np.degrees(psi - psi[0]), lw=1.0, label=label)
        if extra and "n" in log.columns:
            axes[5].plot(t, log["n"], lw=1.0, label=label)
        track_ax.plot(y - y[0], x - x[0], lw=1.0, label=label)
    sides = {log.attrs.get("rudder_positive") for log in logs.values()}
    side = next(iter(sides)) if len(sides) == 1 else None  # None too where no log states one
    rudder = "rudder δ [deg]" + (f", + to {side}" if side else "")
    labels = [LABELS["u"], LABELS["v"], LABELS["r"], rudder, "heading ψ − ψ0 [deg]",
              "propeller n [rps]"]  # fmt: skip
    for ax, lab in zip(axes, labels, strict=False):
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("t [s]")
    axes[0].legend(fontsize=8)
    _track_axes(track_ax, relative=True, legend=False)
    fig.suptitle(title)
    return _save(fig, path, out)


def autopilot_figure(runs: Mapping[str, pd.DataFrame], path, title: str = "",
                     out: OutputSet | None = None):  # fmt: skip
    """Heading (and the order) and rudder of autopilot runs over time."""
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for label, log in runs.items():
        a1.plot(log["t"], np.degrees(log["psi"]), label=f"{label}: heading")
        a2.plot(log["t"], np.degrees(log["delta"]), label=label)
    first = next(iter(runs.values()))
    a1.plot(first["t"], np.degrees(first["psi_d"]), "k--", lw=0.8, label="ordered heading")
    a1.set_ylabel("heading ψ [deg]")
    a2.set_ylabel("rudder δ [deg]")
    a2.set_xlabel("t [s]")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle(title)
    return _save(fig, path, out)


def tracks_with_waypoints(runs: Mapping[str, pd.DataFrame], waypoints, path, title: str = "",
                          out: OutputSet | None = None):  # fmt: skip
    """Tracks of path-following runs with the waypoints and the legs between them."""
    fig, ax = plt.subplots(figsize=(7, 7))
    wp = np.asarray(waypoints, dtype=float)
    ax.plot(wp[:, 1], wp[:, 0], "k--", lw=0.8, label="path")
    ax.plot(wp[:, 1], wp[:, 0], "ks", ms=5)
    for label, log in runs.items():
        ax.plot(log["y"], log["x"], lw=1.2, label=label)
    _track_axes(ax)
    ax.set_title(title)
    return _save(fig, path, out)
