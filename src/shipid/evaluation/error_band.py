"""How far a free run strays from a log it was not fitted to: a band from cross-validation.

The bootstrap bands (``shipid.identification.uncertainty``) say how much the coefficients, and
with ``select`` the choice of terms, could vary; they do not hold what no candidate can
represent, so on real ships they hold far fewer than 95 % of the measured samples (the Esso
Osaka's: about a third of its yaw rate; ``benchmarks/study_selection_uncertainty.py``). This band
is measured instead: ``select`` runs each fold's model free over the log it left out, and the
band's half-width per state is the conformal quantile of the absolute free-run errors of all
those held-out samples (cross-validation residuals as the calibration set, as the jackknife+ of
Barber et al. 2021 uses leave-one-out ones), a sample after a divergence counting as an
infinite error. A new log
like the held-out ones then has about ``level`` of its samples within ±half-width of the model's
free run: exchangeable logs are the assumption, and a log beyond the training conditions may
stray further. Validation reports the share of each log's samples inside the band.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from shipid.errors import ShipidError

STATES = ("u", "v", "r")
LEVEL = 0.95
METHOD = "conformal quantile of the absolute free-run errors on held-out logs"


@dataclass(frozen=True)
class ErrorBand:
    """Half-width per state (u, v [m/s], r [rad/s]; ∞ where too many held-out samples came after a
    divergence) holding ``level`` of the held-out free-run errors of ``logs`` logs, ``samples``
    samples."""

    half_width: Mapping[str, float]
    level: float
    logs: int
    samples: int
    method: str = METHOD
    # What was held out: "logs", or "blocks" (cut from logs: shorter runs that stray less)
    held_out: str = "logs"

    def shares_within(self, measured: np.ndarray, simulated: np.ndarray) -> dict[str, float]:
        """Per state, the share of a log's samples (``measured`` (n, 3) u, v, r) whose free run
        (``simulated`` (m ≤ n, 3); shorter when it diverged) is within the band; samples after a
        divergence are outside."""
        n, m = len(measured), len(simulated)
        if n == 0:
            return dict.fromkeys(STATES, math.nan)
        err = np.abs(simulated - measured[:m])
        return {s: float(np.sum(err[:, j] <= self.half_width[s]) / n)
                for j, s in enumerate(STATES)}  # fmt: skip

    def scaled(self, speed_ratio: float) -> ErrorBand:
        """The band of a Froude-similar ship whose speeds are ``speed_ratio`` times these (u, v
        × k, r ÷ k for k = speed_ratio, since lengths scale with k²)."""
        w = self.half_width
        return ErrorBand({"u": w["u"] * speed_ratio, "v": w["v"] * speed_ratio,
                          "r": w["r"] / speed_ratio}, self.level, self.logs, self.samples,
                         self.method, self.held_out)  # fmt: skip

    def describe(self) -> str:
        """One line: the half-widths and where they come from."""
        def fmt(x: float) -> str:
            return "not bounded" if math.isinf(x) else f"±{x:.4g}"

        caveat = "; whole logs stray further" if self.held_out == "blocks" else ""
        return (f"cross-validated {100 * self.level:g} % error band (free runs of "
                f"{self.logs} held-out {self.held_out}, {self.samples} samples{caveat}): "
                f"u {fmt(self.half_width['u'])} m/s, v {fmt(self.half_width['v'])} m/s, "
                f"r {fmt(self.half_width['r'])} rad/s")

    def to_dict(self) -> dict:
        """JSON-ready (∞ as null)."""
        return {"level": self.level, "logs": self.logs, "samples": self.samples,
                "method": self.method, "held_out": self.held_out,
                "half_width": {s: None if math.isinf(x) else float(x)
                               for s, x in self.half_width.items()}}  # fmt: skip

    @classmethod
    def from_dict(cls, data: Mapping, where: str = "error band") -> ErrorBand:
        """The band of a model file, validated."""
        try:
            widths = {s: math.inf if data["half_width"][s] is None
                      else float(data["half_width"][s]) for s in STATES}  # fmt: skip
            level, logs, samples = float(data["level"]), int(data["logs"]), int(data["samples"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ShipidError(f"{where}: not an error band ({exc})") from None
        if not 0 < level < 1 or any(not w >= 0 for w in widths.values()):
            raise ShipidError(f"{where}: level must be in (0, 1) and half-widths ≥ 0")
        held_out = str(data.get("held_out", "logs"))
        if held_out not in ("logs", "blocks"):
            raise ShipidError(f"{where}: held_out must be 'logs' or 'blocks', got {held_out!r}")
        return cls(widths, level, logs, samples, str(data.get("method", METHOD)), held_out)


def conformal_quantile(errors: np.ndarray, level: float = LEVEL) -> float:
    """The ⌈(N + 1)·level⌉-th smallest of N absolute errors (∞ if that exceeds N): a new
    exchangeable error is at most this with probability ≥ ``level``."""
    e = np.sort(np.asarray(errors, dtype=float).reshape(-1))
    k = math.ceil((e.size + 1) * level)
    return float(e[k - 1]) if 1 <= k <= e.size else math.inf


def error_band(runs: Sequence[tuple[np.ndarray, np.ndarray]], level: float = LEVEL,
               held_out: str = "logs") -> ErrorBand:  # fmt: skip
    """The band from held-out free runs: pairs of ``measured`` (n, 3) and ``simulated`` (m ≤ n,
    3) u, v, r; the n − m samples after a divergence count as infinite errors. ``held_out``:
    what the runs are ("logs", or "blocks" of logs)."""
    if not runs:
        raise ShipidError("an error band needs at least one held-out free run")
    per_state = {s: [] for s in STATES}
    for measured, simulated in runs:
        n, m = len(measured), len(simulated)
        err = np.abs(simulated - measured[:m])
        for j, s in enumerate(STATES):
            per_state[s].append(np.concatenate([err[:, j], np.full(n - m, np.inf)]))
    widths = {s: conformal_quantile(np.concatenate(per_state[s]), level) for s in STATES}
    return ErrorBand(widths, level, len(runs), int(sum(len(m) for m, _ in runs)), METHOD,
                     held_out)


def cross_validated_band(fit, logs, names, cv: str = "auto", method: str = "euler",
                         level: float = LEVEL) -> ErrorBand:  # fmt: skip
    """The band of a fixed fit (``fit(training logs) -> model``, e.g. ``identify`` with its
    structure, γ and prefilter): each log fitted without and run free over (``cv='logo'``), or,
    with ``'blocks:K'``, every log cut into K blocks and each block left out. ``'auto'``: logo
    from two logs, four blocks of one."""
    from shipid.dynamics.simulate import simulate_log
    from shipid.identification.cross_validation import held_out_logs

    logs, names, _, held_out = held_out_logs(logs, names, cv, "--error-band")
    runs = []
    for k, held in enumerate(logs):
        model = fit([x for j, x in enumerate(logs) if j != k])
        sim = simulate_log(model, held, method).log
        runs.append((held[list(STATES)].to_numpy(dtype=float), sim[list(STATES)].to_numpy()))
    return error_band(runs, level, held_out)
