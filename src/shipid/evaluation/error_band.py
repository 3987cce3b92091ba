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

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from shipid.data.log import column_array
from shipid.errors import ShipidError

STATES = ("u", "v", "r")
LEVEL = 0.95
METHOD = "conformal quantile of the absolute free-run errors on held-out logs"


@dataclass(frozen=True)
class HeldOutRun:
    """How one held-out free run of a band fared: the log (or block) ``name``, its ``samples``,
    how many of them the free run reached (``simulated``; fewer where it diverged) and, per
    state, the rms error over that part divided by the log's standard deviation: 1 is no better
    than the log's own mean, the error's bias included."""

    name: str
    samples: int
    simulated: int
    error_over_spread: Mapping[str, float]
    # A held-out zig-zag's or turn's indices, measured and predicted (its closed loop on the
    # fit without it): {index: (measured, predicted)}, None where one has none
    indices: Mapping[str, tuple[float | None, float | None]] = field(default_factory=dict)

    @property
    def diverged(self) -> bool:
        """Whether the free run stopped short of the log's end."""
        return self.simulated < self.samples

    def to_dict(self) -> dict:
        """JSON-ready (a ratio that cannot be formed, a log without spread, as null)."""
        return {"name": self.name, "samples": self.samples, "simulated": self.simulated,
                "error_over_spread": {s: None if not math.isfinite(x) else float(x)
                                      for s, x in self.error_over_spread.items()},
                "indices": {k: [_finite_or_none(a), _finite_or_none(b)]
                            for k, (a, b) in self.indices.items()}}  # fmt: skip

    @classmethod
    def from_dict(cls, data: Mapping, where: str) -> HeldOutRun:
        """A run of a model file's band, validated."""
        try:
            ratios = {s: math.nan if data["error_over_spread"][s] is None
                      else float(data["error_over_spread"][s]) for s in STATES}  # fmt: skip
            indices = {str(k): (_finite_or_none(a), _finite_or_none(b))
                       for k, (a, b) in (data.get("indices") or {}).items()}  # fmt: skip
            run = cls(str(data["name"]), int(data["samples"]), int(data["simulated"]), ratios,
                      indices)  # fmt: skip
        except (KeyError, TypeError, ValueError) as exc:
            raise ShipidError(f"{where}: not a held-out run ({exc})") from None
        if not 0 < run.simulated <= run.samples:
            raise ShipidError(f"{where}: simulated must be within 1…samples ({run.samples}), "
                              f"got {run.simulated}")  # fmt: skip
        return run


def _finite_or_none(x) -> float | None:
    return None if x is None or not math.isfinite(float(x)) else float(x)


# The indices a held-out run reports, by the kind of trial it is.
KEY_INDICES = {"zigzag": ("first_overshoot_deg", "second_overshoot_deg"),
               "turning": ("tactical_diameter", "steady_yaw_rate"),
               "pull-out": ("yaw_rate_at_release", "residual_yaw_rate")}  # fmt: skip
# How each reported index scales with a Froude-similar ship whose speeds are k times these:
# lengths with k², rates with 1/k, angles not at all.
INDEX_POWERS = {"first_overshoot_deg": 0, "second_overshoot_deg": 0, "tactical_diameter": 2,
                "steady_yaw_rate": -1, "yaw_rate_at_release": -1, "residual_yaw_rate": -1}
INDEX_LABELS = {"first_overshoot_deg": "overshoots", "tactical_diameter": "tactical diameter, "
                "steady r", "yaw_rate_at_release": "yaw rate held, left"}  # fmt: skip


def key_indices(kind: str | None, indices: Mapping) -> dict[str, tuple[float | None, float | None]]:
    """{index: (measured, predicted)} of a validation's ``indices`` (``validate_log``'s: the
    closed loop is the prediction) for the ``KEY_INDICES`` of its ``kind``; {} for other logs."""
    measured, predicted = indices.get("measured") or {}, indices.get("closed_loop") or {}
    return {k: (_finite_or_none(measured.get(k)), _finite_or_none(predicted.get(k)))
            for k in KEY_INDICES.get(kind or "", ()) if k in measured}  # fmt: skip


def held_out_run(name: str, measured: np.ndarray, simulated: np.ndarray,
                 indices: Mapping | None = None) -> HeldOutRun:  # fmt: skip
    """The ``HeldOutRun`` of one free run: ``measured`` (n, 3) u, v, r of the held-out log and
    ``simulated`` (m ≤ n, 3), its free run up to where it stopped; ``indices`` its
    (measured, predicted) ``key_indices``."""
    n, m = len(measured), len(simulated)
    err = simulated - measured[:m]
    ratios = {}
    for j, s in enumerate(STATES):
        spread = float(np.std(measured[:, j]))
        rms = float(np.sqrt(np.mean(err[:, j] ** 2))) if m else math.nan
        ratios[s] = rms / spread if spread > 0 else math.nan
    return HeldOutRun(name, n, m, ratios, dict(indices or {}))


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
    # How each held-out run fared (none in files written before they were kept)
    runs: tuple[HeldOutRun, ...] = ()

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
        runs = tuple(dataclasses.replace(r, indices={
            k: tuple(None if x is None else x * speed_ratio ** INDEX_POWERS.get(k, 0)
                     for x in pair) for k, pair in r.indices.items()}) for r in self.runs)  # fmt: skip
        return ErrorBand({"u": w["u"] * speed_ratio, "v": w["v"] * speed_ratio,
                          "r": w["r"] / speed_ratio}, self.level, self.logs, self.samples,
                         self.method, self.held_out, runs)  # fmt: skip

    def describe(self) -> str:
        """One line: the half-widths and where they come from."""
        def fmt(x: float) -> str:
            return "not bounded" if math.isinf(x) else f"±{x:.4g}"

        caveat = "; whole logs stray further" if self.held_out == "blocks" else ""
        return (f"cross-validated {100 * self.level:g} % error band (free runs of "
                f"{self.logs} held-out {self.held_out}, {self.samples} samples{caveat}): "
                f"u {fmt(self.half_width['u'])} m/s, v {fmt(self.half_width['v'])} m/s, "
                f"r {fmt(self.half_width['r'])} rad/s")

    def runs_summary(self) -> str | None:
        """One clause on how the held-out runs fared: the range of their yaw rate's rms error
        over spread and how many diverged; None for a band without runs (older files)."""
        if not self.runs:
            return None
        r = [x.error_over_spread["r"] for x in self.runs if math.isfinite(x.error_over_spread["r"])]
        diverged = sum(x.diverged for x in self.runs)
        span = f"{min(r):.2g}–{max(r):.2g}" if len(r) > 1 else (f"{r[0]:.2g}" if r else "–")
        return (f"its {len(self.runs)} held-out {self.held_out}, each run free on the fit "
                f"without it, missed their yaw rate by {span} of its spread (rms)"
                + (f", {diverged} diverged" if diverged else ""))

    def run_rows(self) -> list[dict]:
        """One row per held-out run, for a table: its name, the rms error over its spread of u,
        v and r, and where its free run diverged."""
        rows = [{f"held-out {self.held_out[:-1]}": r.name,
                 **{f"{s} error / spread": r.error_over_spread[s] for s in STATES},
                 "diverged": (f"after {r.simulated} of {r.samples} samples" if r.diverged
                              else "no")} for r in self.runs]  # fmt: skip
        if any(r.indices for r in self.runs):
            for row, r in zip(rows, self.runs, strict=True):
                row["indices: measured → predicted (closed loop)"] = _indices_text(r.indices)
        return rows

    def to_dict(self) -> dict:
        """JSON-ready (∞ as null)."""
        return {"level": self.level, "logs": self.logs, "samples": self.samples,
                "method": self.method, "held_out": self.held_out,
                "half_width": {s: None if math.isinf(x) else float(x)
                               for s, x in self.half_width.items()},
                "runs": [r.to_dict() for r in self.runs]}  # fmt: skip

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
        found = data.get("runs") or []
        if not isinstance(found, list):
            raise ShipidError(f"{where}: runs must be a list")
        runs = tuple(HeldOutRun.from_dict(r, f"{where}: runs[{i}]") for i, r in enumerate(found))
        return cls(widths, level, logs, samples, str(data.get("method", METHOD)), held_out, runs)


def _indices_text(indices: Mapping[str, tuple[float | None, float | None]]) -> str:
    """'overshoots 13.2, 16.4 → 13.6, 15.4' (``KEY_INDICES``' pairs, 3 significant digits)."""
    if not indices:
        return "–"

    def fmt(x: float | None) -> str:
        return "–" if x is None else f"{x:.3g}"

    keys = list(indices)
    label = INDEX_LABELS.get(keys[0], keys[0])
    return (f"{label} {', '.join(fmt(indices[k][0]) for k in keys)} → "
            f"{', '.join(fmt(indices[k][1]) for k in keys)}")


def conformal_quantile(errors: np.ndarray, level: float = LEVEL) -> float:
    """The ⌈(N + 1)·level⌉-th smallest of N absolute errors (∞ if that exceeds N): a new
    exchangeable error is at most this with probability ≥ ``level``."""
    e = np.sort(np.asarray(errors, dtype=float).reshape(-1))
    k = math.ceil((e.size + 1) * level)
    return float(e[k - 1]) if 1 <= k <= e.size else math.inf


def error_band(runs: Sequence[tuple[np.ndarray, np.ndarray]], level: float = LEVEL,
               held_out: str = "logs", names: Sequence[str] | None = None,
               indices: Sequence[Mapping | None] | None = None) -> ErrorBand:  # fmt: skip
    """The band from held-out free runs: pairs of ``measured`` (n, 3) and ``simulated`` (m ≤ n,
    3) u, v, r; the n − m samples after a divergence count as infinite errors. ``held_out``:
    what the runs are ("logs", or "blocks" of logs); ``names``: theirs, for the runs' summary
    (``ErrorBand.runs``; by default "1", "2", ...); ``indices``: each run's (measured,
    predicted) ``key_indices``."""
    if not runs:
        raise ShipidError("an error band needs at least one held-out free run")
    names = list(names) if names is not None else [str(i + 1) for i in range(len(runs))]
    if len(names) != len(runs):
        raise ShipidError(f"an error band of {len(runs)} runs got {len(names)} names")
    per_state = {s: [] for s in STATES}
    for measured, simulated in runs:
        n, m = len(measured), len(simulated)
        err = np.abs(simulated - measured[:m])
        for j, s in enumerate(STATES):
            per_state[s].append(np.concatenate([err[:, j], np.full(n - m, np.inf)]))
    widths = {s: conformal_quantile(np.concatenate(per_state[s]), level) for s in STATES}
    indices = list(indices) if indices is not None else [None] * len(runs)
    summary = tuple(held_out_run(name, np.asarray(m, float), np.asarray(sim, float), ind)
                    for name, (m, sim), ind in zip(names, runs, indices, strict=True))  # fmt: skip
    return ErrorBand(widths, level, len(runs), int(sum(len(m) for m, _ in runs)), METHOD,
                     held_out, summary)


def cross_validated_band(fit, logs, names, cv: str = "auto", method: str = "euler",
                         level: float = LEVEL) -> ErrorBand:  # fmt: skip
    """The band of a fixed fit (``fit(training logs) -> model``, e.g. ``identify`` with its
    structure, γ and prefilter): each log fitted without and run free over (``cv='logo'``), or,
    with ``'blocks:K'``, every log cut into K blocks and each block left out. ``'auto'``: logo
    from two logs, four blocks of one."""
    from shipid.dynamics.simulate import simulate_log
    from shipid.evaluation.validate import validate
    from shipid.identification.cross_validation import held_out_logs

    logs, names, _, held_out = held_out_logs(logs, names, cv, "--error-band")
    runs, indices = [], []
    for k, held in enumerate(logs):
        model = fit([x for j, x in enumerate(logs) if j != k])
        # Validated, a held-out zig-zag or turn is also run closed loop: its indices predicted.
        v = validate(model, held, [names[k]], method, start_draws=False)[0]
        sim = v.simulation.log if v.error is None else simulate_log(model, held, method).log
        runs.append((column_array(held, STATES), column_array(sim, STATES)))
        indices.append(key_indices(v.kind, v.indices) if v.error is None else None)
    return error_band(runs, level, held_out, names, indices)
