"""Uncertainty of an identified model: a moving-block bootstrap of the regression equations gives
an ensemble of coefficient sets, hence intervals on the coefficients, prediction bands on free
runs and intervals on manoeuvring indices and criteria.

Each replicate refits the same regression (structure, form, γ, estimator, priors and constraints)
with the equations resampled in blocks of ``block_s`` seconds within each log (Künsch 1989): the
blocks keep the equation errors' autocorrelation, which resampling single equations would
ignore. With ``block_s="log"`` (the default, ``"auto"``, from five logs on) a replicate draws
whole logs instead, as many as there are, with replacement (a cluster bootstrap, Davison &
Hinkley 1997, §3.8): where the logs differ from one another by more than their equation errors
say (a day's wind, a campaign's loading, a kind of manoeuvre), the replicates differ by that
too. The intervals are percentile intervals of the replicates. They cover what the equation
error makes uncertain; a bias common to all replicates (errors in the measured states, a
structure that lacks a term) is not in them, unless the structure is resampled too: the
ensemble of ``shipid.identification.selection_ensemble`` draws each replicate's terms from the
choices ``select`` makes on resamples of its held-out logs, so its members may hold terms the
point estimate does not (``Ensemble.structure``, a superset of the model's).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shipid.data.log import column_array
from shipid.dynamics.model import DOFS, ManoeuvringModel, ModelStructure
from shipid.errors import ShipidError, require_function

METHOD = "moving-block bootstrap of the regression equations"
SELECTION_METHOD = "selection on resampled held-out logs, then a moving-block bootstrap"
LOG_METHOD = "bootstrap of whole logs"
SELECTION_LOG_METHOD = "selection on resampled held-out logs, then a bootstrap of whole logs"
WHOLE_LOGS = "log"  # block_s of a bootstrap that resamples whole logs
# Fewer logs than this give a log bootstrap too few distinct resamples to say how they vary.
MIN_WHOLE_LOGS = 5
BLOCK_S = 10.0  # the moving blocks' length where there are fewer logs
LEVEL = 0.95


def resolve_block(block_s: float | str, n_logs: int) -> float | str:
    """``"auto"``: whole logs (``"log"``) from ``MIN_WHOLE_LOGS`` logs on, else blocks of
    ``BLOCK_S`` seconds. On the Esso Osaka's logs, held-out ±35° turns' tactical diameters and
    steady yaw rates fell inside the 95 % intervals of whole-log replicates in 27 of 28 cases,
    of 10 s blocks in 23 (``benchmarks/study_selection_uncertainty.py``)."""
    if block_s == "auto":
        return WHOLE_LOGS if n_logs >= MIN_WHOLE_LOGS else BLOCK_S
    return block_s


@dataclass
class Ensemble:
    """Bootstrap replicates of a model's coefficients.

    Attributes
    ----------
    model : the point estimate (the fit of all equations).
    thetas : (R, 3, T) coefficients of the replicates, columns ``structure.all_terms``.
    block_s, seed : the resampling: blocks of ``block_s`` seconds, or whole logs (``"log"``).
    structure : the members' structure: the model's (default) or, when the replicates' terms
        vary, a superset of it per equation (a member's coefficient of a term it lacks is 0).
    """

    model: ManoeuvringModel
    thetas: np.ndarray
    block_s: float | str
    seed: int
    method: str = METHOD
    structure: ModelStructure | None = None
    plausibility: dict | None = None  # ``members_plausibility``'s record, where checked

    def __post_init__(self) -> None:
        if self.structure is None:
            self.structure = getattr(self.model, "structure", None)  # bootstrap takes any fit
            return
        missing = [(d, t) for d, terms in self.model.structure.terms.items() for t in terms
                   if t not in self.structure.terms.get(d, ())]  # fmt: skip
        if missing:
            d, t = missing[0]
            raise ShipidError(f"the ensemble's structure lacks the model's term {t!r} of "
                              f"equation {d}")  # fmt: skip

    @property
    def term_texts(self) -> tuple[str, ...]:
        """The columns of ``thetas``."""
        return self.structure.all_terms

    @property
    def varies_structure(self) -> bool:
        """Whether the members hold different terms (their zero coefficients differ)."""
        held = self.thetas != 0.0
        return bool(np.any(held != held[:1]))

    @property
    def replicates(self) -> int:
        """Number of replicates R."""
        return int(self.thetas.shape[0])

    @property
    def members_label(self) -> str:
        """What the members are, for messages: bootstrap replicates or covariance draws."""
        if self.method in (METHOD, LOG_METHOD):
            return "bootstrap replicates"
        if self.method in (SELECTION_METHOD, SELECTION_LOG_METHOD):
            what = "resamples of whole logs" if self.method == SELECTION_LOG_METHOD \
                else "block resamples"
            return f"replicates (terms chosen on resampled held-out logs, refitted on {what})"
        return "draws of its covariance"

    @property
    def resampling(self) -> str:
        """How the replicates were made, for messages: the method, with its blocks' length."""
        if self.block_s == WHOLE_LOGS or self.method not in (METHOD, SELECTION_METHOD):
            return self.method
        return f"{self.method}, {self.block_s:g} s blocks"

    def members(self) -> list[ManoeuvringModel]:
        """The replicates as models (of ``structure``)."""
        index = {t: j for j, t in enumerate(self.term_texts)}
        out = []
        for theta in self.thetas:
            coefs = {d: {t: float(theta[DOFS.index(d), index[t]]) for t in terms}
                     for d, terms in self.structure.terms.items()}  # fmt: skip
            out.append(ManoeuvringModel(self.structure, coefs, name=self.model.name))
        return out

    def coefficient_table(self, level: float = LEVEL) -> pd.DataFrame:
        """One row per coefficient: estimate, the replicates' standard deviation and interval.
        When the members' terms vary, also the terms only some members hold (estimate 0, not in
        the model) and each term's inclusion: the share of members that hold it."""
        index = {t: j for j, t in enumerate(self.term_texts)}
        rows = []
        for dof, terms in self.structure.terms.items():
            i = DOFS.index(dof)
            in_model = self.model.structure.terms.get(dof, ())
            for t in terms:
                values = self.thetas[:, i, index[t]]
                lo, hi = interval(values, level)
                row = {"equation": dof, "term": t,
                       "value": float(self.model.coefficients[dof][t]) if t in in_model else 0.0,
                       "std": float(np.std(values, ddof=1)), "lower": lo,
                       "upper": hi}  # fmt: skip
                if self.varies_structure:
                    row["in_model"] = t in in_model
                    row["inclusion"] = float(np.mean(values != 0.0))
                rows.append(row)
        return pd.DataFrame(rows)

    def to_dict(self) -> dict:
        """The model file's ``uncertainty`` record."""
        out = {"method": self.method, "replicates": self.replicates, "block_s": self.block_s,
               "seed": self.seed, "terms": list(self.term_texts),
               "thetas": self.thetas.tolist()}  # fmt: skip
        if dict(self.structure.terms) != dict(self.model.structure.terms):
            out["structure"] = {d: list(t) for d, t in self.structure.terms.items()}
        if self.plausibility is not None:
            out["plausibility"] = dict(self.plausibility)
        return out

    @classmethod
    def from_dict(cls, data: Mapping, model: ManoeuvringModel, where: str = "uncertainty"
                  ) -> Ensemble:  # fmt: skip
        """The ensemble of a model file (validated against its model's terms)."""
        try:
            terms = [str(t) for t in data["terms"]]
            thetas = np.asarray(data["thetas"], dtype=float)
            block_s = data["block_s"]
            block_s = WHOLE_LOGS if block_s == WHOLE_LOGS else float(block_s)
            seed = int(data["seed"])
            structure = model.structure
            if data.get("structure") is not None:
                structure = ModelStructure(f"{model.structure.name} (ensemble)",
                                           {str(d): tuple(str(t) for t in ts)
                                            for d, ts in dict(data["structure"]).items()})  # fmt: skip
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise ShipidError(f"{where}: not a bootstrap ensemble ({exc})") from None
        if terms != list(structure.all_terms):
            whose = "its structure's" if data.get("structure") is not None else "the model's"
            raise ShipidError(f"{where}: the ensemble's terms {terms} are not {whose} "
                              f"{list(structure.all_terms)}")  # fmt: skip
        if thetas.ndim != 3 or thetas.shape[1:] != (3, len(terms)) or thetas.shape[0] < 2:
            raise ShipidError(f"{where}: thetas must be R ≥ 2 coefficient sets of shape "
                              f"(3, {len(terms)}), got {thetas.shape}")  # fmt: skip
        if not np.all(np.isfinite(thetas)):
            raise ShipidError(f"{where}: the ensemble contains a non-finite coefficient")
        checked = data.get("plausibility")
        try:
            return cls(model, thetas, block_s, seed, str(data.get("method", METHOD)), structure,
                       dict(checked) if isinstance(checked, Mapping) else None)  # fmt: skip
        except ShipidError as exc:
            raise ShipidError(f"{where}: {exc}") from None


# A share of replicates failing the checks their model passes above which it is said: the logs
# then pin the model's behaviour beyond them loosely (one Esso zig-zag file: 55–79 %; the demo's
# zig-zag of the paper's ship: none; the KVLCC2's MARIN zig-zag with the README's physics: 3 %).
WEAK_REPLICATES = 0.10
# Replicates checked at most: the replicates are independent draws, so the first ones are a
# sample of them; 40 put a share of 70 % within ±7 % (one standard error) at 0.5–1.9 s (a
# check costs 12–46 ms, seven times a replicate's refit on the demo's log).
CHECKED_REPLICATES = 40


def members_plausibility(ensemble: Ensemble, reasons: Callable[[ManoeuvringModel], list[str]],
                         limit: int | None = None) -> dict:  # fmt: skip
    """How many of ``ensemble``'s first ``limit`` (default ``CHECKED_REPLICATES``) members
    fail the checks (``reasons(member)``: the reasons that rule a model out,
    ``shipid.identification.plausibility.disqualifying``), and the first reason of each,
    counted: {"checked", "implausible", "reasons": {reason: count}}."""
    counted: dict[str, int] = {}
    members = ensemble.members()[:CHECKED_REPLICATES if limit is None else limit]
    for member in members:
        found = reasons(member)
        if found:
            counted[found[0]] = counted.get(found[0], 0) + 1
    ranked = dict(sorted(counted.items(), key=lambda kv: -kv[1]))
    return {"checked": len(members), "implausible": sum(counted.values()), "reasons": ranked}


def implausible_members_note(record: Mapping, label: str = "bootstrap replicates"
                             ) -> str | None:  # fmt: skip
    """A warning where more than ``WEAK_REPLICATES`` of the members fail the checks their model
    passes (``members_plausibility``'s ``record``); else None."""
    k, n = int(record.get("implausible", 0)), int(record.get("checked", 0))
    if not n or k <= WEAK_REPLICATES * n:
        return None
    why = "; ".join(f"{reason} ({count})" for reason, count in
                    list((record.get("reasons") or {}).items())[:3])  # fmt: skip
    return (f"{k} of {n} {label} checked fail the plausibility checks the model passes ({why}): "
            "refitted on resamples of its logs the model is often no plausible ship, so what it "
            "predicts beyond them rests on a fit the logs barely choose; the intervals hold "
            "those replicates (validate's may not be bounded). More logs, or logs of the "
            "manoeuvres you need, pin it down")


# Values per block of ``conservative_percentiles``: its temporaries stay within the CPU's cache.
_CHUNK = 1 << 16


def conservative_percentiles(values: np.ndarray, level: float = LEVEL, axis: int = 0
                             ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Central percentile bounds of ``values`` along ``axis`` where a replicate without a value
    (NaN: its run diverged, or never reached the event) counts as below every value for the
    lower bound and above every value for the upper one. Leaving such replicates out would
    make the interval narrower than the ensemble says; counted this way, a share of them larger
    than the tail (1 − level) / 2 makes the bounds −∞ and +∞: not bounded. NaN where no
    replicate has a value."""
    v = np.moveaxis(np.asarray(values, dtype=float), axis, 0)
    if v.ndim > 1 and v.size > _CHUNK:
        # Column blocks: a 200-replicate band over a 45 000-sample log made four 216 MB
        # temporaries at once, and most of its time was the memory's first touch.
        flat = v.reshape(v.shape[0], -1)
        step = max(1, _CHUNK // v.shape[0])
        parts = [conservative_percentiles(flat[:, j : j + step], level)
                 for j in range(0, flat.shape[1], step)]  # fmt: skip
        return tuple(np.concatenate([b[k] for b in parts]).reshape(v.shape[1:]) for k in (0, 1))
    n = v.shape[0]
    missing = ~np.isfinite(v)
    lower_sorted = np.sort(np.where(missing, -np.inf, v), axis=0)
    upper_sorted = np.sort(np.where(missing, np.inf, v), axis=0)
    a = 0.5 * (1.0 - level)
    out = []
    for q, s, worst in ((a, lower_sorted, -np.inf), (1.0 - a, upper_sorted, np.inf)):
        # NumPy's default (linear) percentile, and the infinite bound wherever it would take
        # or interpolate with a missing replicate.
        p = q * (n - 1)
        i = int(math.floor(p))
        f = p - i
        below, above = s[i], s[min(i + 1, n - 1)]
        reached = np.isinf(below) | (f > 0) & np.isinf(above)
        with np.errstate(invalid="ignore"):
            x = np.where(reached, worst, below + f * (above - below))
        out.append(np.where(missing.all(axis=0), np.nan, x))
    return out[0], out[1]


def interval(values: Sequence[float], level: float = LEVEL) -> tuple[float, float]:
    """Central percentile interval of ``values`` (NaN: a replicate without a value, counted as
    ``conservative_percentiles`` does, so many of them give (−∞, +∞); NaN if none is finite)."""
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.size == 0:
        return math.nan, math.nan
    lo, hi = conservative_percentiles(v, level)
    return float(lo), float(hi)


def block_weights(lengths: Sequence[int], block: int, rng: np.random.Generator) -> np.ndarray:
    """Multiplicity of each equation in one moving-block bootstrap replicate: blocks of ``block``
    consecutive equations, never across two logs (of ``lengths`` equations each), drawn until
    they hold as many equations as the data."""
    lengths = [int(n) for n in lengths]
    total = sum(lengths)
    offsets = np.cumsum([0] + lengths[:-1])
    # Block starts: every position of every log at which a whole block (or the whole log) fits.
    starts, sizes = [], []
    for off, n in zip(offsets, lengths, strict=True):
        size = min(block, n)
        k = n - size + 1
        starts.append(off + np.arange(k))
        sizes.append(np.full(k, size))
    starts_a, sizes_a = np.concatenate(starts), np.concatenate(sizes)
    # Enough draws for any mix of block sizes; keep those up to the first that reaches the total.
    draws = rng.integers(len(starts_a), size=-(-total // int(sizes_a.min())))
    used = int(np.searchsorted(np.cumsum(sizes_a[draws]), total)) + 1
    s, m = starts_a[draws[:used]], sizes_a[draws[:used]]
    edges = np.zeros(total + 1)  # +1 at each block's start, −1 after its end
    np.add.at(edges, s, 1.0)
    np.add.at(edges, s + m, -1.0)
    return np.cumsum(edges[:-1])


def log_weights(lengths: Sequence[int], rng: np.random.Generator) -> np.ndarray:
    """Multiplicity of each equation in one bootstrap replicate of whole logs: as many logs as
    there are (of ``lengths`` equations each), drawn with replacement."""
    n = len(lengths)
    counts = rng.multinomial(n, np.full(n, 1.0 / n)).astype(float)
    return np.repeat(counts, [int(k) for k in lengths])


def resampler(logs: Sequence[pd.DataFrame], replicates: int, block_s: float | str
              ) -> tuple[Callable[[np.random.Generator], np.ndarray], float | str]:  # fmt: skip
    """The draw of one replicate's equation multiplicities (moving blocks of ``block_s``
    seconds, whole logs for ``"log"``, ``"auto"`` as ``resolve_block`` says) and the resampling
    it stands for (seconds or ``"log"``), after checking the number of replicates (≥ 10), the
    block length (> 0 s) and, for whole logs, their number (≥ ``MIN_WHOLE_LOGS``)."""
    if not (isinstance(replicates, int) and replicates >= 10):
        raise ShipidError(f"--bootstrap needs at least 10 replicates, got {replicates!r}")
    lengths = [len(log) - 1 for log in logs]
    block_s = resolve_block(block_s, len(logs))
    if block_s == WHOLE_LOGS:
        if len(logs) < MIN_WHOLE_LOGS:
            raise ShipidError(f"--block log resamples whole logs and needs at least "
                              f"{MIN_WHOLE_LOGS} of them, got {len(logs)}: give a block length "
                              "in seconds")  # fmt: skip
        return (lambda rng: log_weights(lengths, rng)), WHOLE_LOGS
    if not (isinstance(block_s, int | float) and math.isfinite(block_s) and block_s > 0):
        raise ShipidError(f"--block must be > 0 s or 'log', got {block_s!r}")
    dt = float(np.median(np.diff(logs[0]["t"].to_numpy())))
    block = max(1, int(round(block_s / dt)))
    return (lambda rng: block_weights(lengths, block, rng)), float(block_s)


def bootstrap(
    logs: Sequence[pd.DataFrame],
    fit: Callable[[np.ndarray | None], ManoeuvringModel],
    replicates: int = 200,
    block_s: float | str = "auto",
    seed: int = 0,
    progress: bool = False,
) -> Ensemble:
    """Bootstrap ensemble of the fit ``fit(weights) -> model`` (e.g. ``identify`` with
    ``sample_weight``) over the equations of ``logs`` (one per sample but the last of each):
    moving blocks of ``block_s`` seconds, or whole logs (``block_s="log"``; ``"auto"``: as
    ``resolve_block`` says)."""
    require_function(fit, "bootstrap",
                     "lambda w: identify(logs, STRUCTURE, sample_weight=w).model")  # fmt: skip
    draw, block_s = resampler(logs, replicates, block_s)
    rng = np.random.default_rng(seed)
    point = fit(None)
    thetas = np.empty((replicates, *point.theta.shape))
    bar = _bar(progress, replicates)
    for k in range(replicates):
        thetas[k] = fit(draw(rng)).theta
        bar.update()
    bar.close()
    return Ensemble(point, thetas, block_s, int(seed),
                    LOG_METHOD if block_s == WHOLE_LOGS else METHOD)


def _bar(progress: bool, total: int):
    """The bootstrap's bar, shown only on a terminal where ``progress`` asks for it."""
    from shipid.progress import progress_bar

    return progress_bar(total, "bootstrap", "fit", shown=bool(progress))


Bands = dict[str, tuple[np.ndarray, np.ndarray]]


def ensemble_runs(ensemble: Ensemble, log: pd.DataFrame, method: str = "euler") -> list:
    """The replicates' free runs on ``log`` (``simulate_log`` of each member; a corrected
    ship's replicates are ships, their dynamics run)."""
    from shipid.dynamics.simulate import simulate_log
    from shipid.vessels.vessel import Vessel

    return [simulate_log(member.dynamics if isinstance(member, Vessel) else member, log, method)
            for member in ensemble.members()]  # fmt: skip


def free_run_bands(runs: Sequence, n: int, level: float = LEVEL) -> tuple[Bands, int]:
    """Prediction bands from the replicates' free runs (``ensemble_runs``) on a log of ``n``
    samples: per state u, v, r the pointwise percentile interval, and how many replicates
    diverged. A diverged replicate has no value after its divergence, which counts as
    ``conservative_percentiles`` does: where more than the tail's share of replicates have
    diverged, the band is not bounded (±∞)."""
    values = np.full((len(runs), n, 3), np.nan)
    for k, sim in enumerate(runs):
        m = len(sim.log)
        values[k, :m] = column_array(sim.log, ("u", "v", "r"))
    lo, hi = conservative_percentiles(values, level)
    bands = {s: (lo[:, j], hi[:, j]) for j, s in enumerate(("u", "v", "r"))}
    return bands, sum(int(sim.diverged) for sim in runs)


def index_intervals(samples: Sequence[Mapping[str, float]], level: float = LEVEL
                    ) -> dict[str, tuple[float, float]]:  # fmt: skip
    """Per index name: the percentile interval over the replicates' indices (a replicate that
    diverged or lacks the index counts as ``interval`` says: too many give (−∞, +∞)). The
    bookkeeping of a measurement (``shipid.trials.indices.BOOKKEEPING``) gets none."""
    from shipid.trials.indices import BOOKKEEPING

    names = sorted({k for s in samples for k, v in s.items()
                    if isinstance(v, int | float) and k not in BOOKKEEPING})  # fmt: skip
    return {k: interval([s.get(k, math.nan) for s in samples], level) for k in names}
