"""Monte Carlo identifiability studies of the paper's experiment, serial or fanned out on Dask.

A study is a grid (noise level × γ × structure × estimator × prefilter) crossed with seeds.
Each trial synthesises the paper's four noisy trials on the scale ship (``shipid.demo``) with
its own noise realisation, identifies a model from the 20/20 zig-zag and predicts the three
held-out manoeuvres in free run; the true model predicts the same noisy logs, which gives the
noise floor each error is measured against. With ``bootstrap`` replicates, or with the
``output-error`` estimator (maximum-likelihood output error from the LS-SVM start, on the
unfiltered log, with standard errors), the trial also records whether the 95 % intervals cover
the true coefficients.

Every trial is a pure function of its parameters (its seed fixes the noise and the
bootstrap), and runs with one BLAS thread, so the results do not depend on where it ran:
serially in this process, on a ``LocalCluster`` or on a cluster given by its scheduler address.

Specification (YAML; every key optional)::

    seeds: 200              # an integer n (seeds 0 … n−1) or a list of seeds
    noise: [1.0]            # multiples of the paper's sensor noise (``PAPER_IMU``)
    gamma: [1.0e4]          # LS-SVM regularisation γ
    structure: [blanke]     # named term libraries (blanke: r² dropped from surge, as the paper)
    estimator: [lssvm]      # lssvm, ols, ridge, lasso, svr, output-error
    filter: [auto]          # prefilter of u, v, r: auto (chosen from the data), none, or Hz
    bootstrap: 0            # replicates per trial for coefficient intervals (0: none)
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np
import pandas as pd

from shipid.errors import ShipidError

ESTIMATORS = ("lssvm", "ols", "ridge", "lasso", "svr", "output-error")
OUTPUT_ERROR = "output-error"
LEVEL = 0.95


@dataclass(frozen=True)
class Trial:
    """One identification experiment: a grid point and a seed."""

    index: int
    seed: int
    noise: float = 1.0
    gamma: float = 1e4
    structure: str = "blanke"
    estimator: str = "lssvm"
    filter: str = "auto"
    bootstrap: int = 0


GRID_KEYS = ("noise", "gamma", "structure", "estimator", "filter")


@dataclass(frozen=True)
class StudySpec:
    """The grid and seeds of a study (see the module docstring for the file format)."""

    seeds: tuple[int, ...] = tuple(range(20))
    noise: tuple[float, ...] = (1.0,)
    gamma: tuple[float, ...] = (1e4,)
    structure: tuple[str, ...] = ("blanke",)
    estimator: tuple[str, ...] = ("lssvm",)
    filter: tuple[str, ...] = ("auto",)
    bootstrap: int = 0
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        where = f"{self.source}: " if self.source else ""
        if not self.seeds or any(int(s) != s or s < 0 for s in self.seeds):
            raise ShipidError(f"{where}seeds: a positive count or a list of integers ≥ 0")
        if len(set(self.seeds)) != len(self.seeds):
            raise ShipidError(f"{where}seeds: repeated seeds {sorted(self.seeds)}")
        for key in GRID_KEYS:
            if not getattr(self, key):
                raise ShipidError(f"{where}{key}: give at least one value")
        for x in self.noise:
            if not (math.isfinite(x) and x >= 0):
                raise ShipidError(f"{where}noise: {x!r} is not a multiple ≥ 0 of the paper's noise")
        for g in self.gamma:
            if not (math.isfinite(g) and g > 0):
                raise ShipidError(f"{where}gamma: {g!r} must be > 0")
        from shipid.dynamics.model import get_structure

        for name in self.structure:
            try:
                get_structure(name)
            except ValueError as exc:
                raise ShipidError(f"{where}structure: {exc}") from None
        for name in self.estimator:
            if name not in ESTIMATORS:
                raise ShipidError(f"{where}estimator: {name!r} is not one of {', '.join(ESTIMATORS)}")
        for value in self.filter:
            _cutoff(value, where)
        if int(self.bootstrap) != self.bootstrap or not (self.bootstrap == 0 or self.bootstrap >= 10):
            raise ShipidError(f"{where}bootstrap: 0 (none) or an integer ≥ 10 replicates")

    @classmethod
    def from_dict(cls, spec: dict, source: str = "") -> StudySpec:
        """A spec from a parsed YAML mapping; unknown keys and wrong types are named."""
        where = f"{source}: " if source else ""
        if not isinstance(spec, dict):
            raise ShipidError(f"{where}a study specification is a mapping of keys to values")
        known = {f.name for f in fields(cls)} - {"source"}
        spec = {k: v for k, v in spec.items() if k != "kind"}
        unknown = sorted(set(spec) - known)
        if unknown:
            raise ShipidError(f"{where}unknown key {unknown[0]!r} (known: {', '.join(sorted(known))})")
        kw: dict = {"source": source}
        if "seeds" in spec:
            seeds = spec["seeds"]
            if isinstance(seeds, bool) or not isinstance(seeds, int | list):
                raise ShipidError(f"{where}seeds: a positive count or a list of integers ≥ 0")
            if isinstance(seeds, int):
                if seeds < 1:
                    raise ShipidError(f"{where}seeds: a positive count or a list of integers ≥ 0")
                seeds = range(seeds)
            kw["seeds"] = tuple(_typed(s, int, "seeds", where) for s in seeds)
        for key, kind in (("noise", float), ("gamma", float), ("structure", str),
                          ("estimator", str), ("filter", str)):  # fmt: skip
            if key in spec:
                values = spec[key] if isinstance(spec[key], list) else [spec[key]]
                kw[key] = tuple(_typed(v, kind, key, where) for v in values)
        if "bootstrap" in spec:
            kw["bootstrap"] = _typed(spec["bootstrap"], int, "bootstrap", where)
        return cls(**kw)

    @classmethod
    def read(cls, path: str | Path) -> StudySpec:
        """Read a YAML study specification (a Monte Carlo one)."""
        spec = read_spec(path)
        if not isinstance(spec, cls):
            raise ShipidError(f"{path}: a study of kind logs, not a Monte Carlo study")
        return spec

    def trials(self) -> list[Trial]:
        """Every grid point × seed, grid point outermost, in a fixed order."""
        grid = itertools.product(*(getattr(self, k) for k in GRID_KEYS))
        combos = [(point, seed) for point in grid for seed in self.seeds]
        return [Trial(i, seed, *point, bootstrap=self.bootstrap)
                for i, (point, seed) in enumerate(combos)]  # fmt: skip


KINDS = ("monte-carlo", "logs")


def read_spec(path: str | Path):
    """A YAML study file: a ``StudySpec`` (kind monte-carlo, the default) or, with
    ``kind: logs``, a ``shipid.identification.batch.BatchSpec`` (paths relative to the file)."""
    import yaml

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ShipidError(f"{path}: {exc.strerror or exc}") from None
    from shipid.data.mappings import DuplicateKeyError, duplicate_key_error, load_yaml

    try:
        spec = load_yaml(text)
    except DuplicateKeyError as exc:
        raise duplicate_key_error(path, exc) from None
    except yaml.YAMLError as exc:
        raise ShipidError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None
    spec = {} if spec is None else spec
    if not isinstance(spec, dict):
        raise ShipidError(f"{path}: a study specification is a mapping of keys to values")
    kind = spec.get("kind", "monte-carlo")
    if kind not in KINDS:
        raise ShipidError(f"{path}: kind {kind!r} is not one of {', '.join(KINDS)}")
    if kind == "logs":
        from shipid.identification.batch import BatchSpec

        return BatchSpec.from_dict(spec, source=str(path), base=path.parent)
    return StudySpec.from_dict(spec, source=str(path))


def _typed(value, kind, key: str, where: str):
    if kind is str:
        if isinstance(value, bool) or not isinstance(value, str | int | float):
            raise ShipidError(f"{where}{key}: {value!r} is not a name")
        return str(value)
    if isinstance(value, str):  # YAML 1.1 reads 1.0e4 (no exponent sign) as text
        try:
            value = float(value)
        except ValueError:
            raise ShipidError(f"{where}{key}: {value!r} is not a number") from None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ShipidError(f"{where}{key}: {value!r} is not a number")
    if kind is int and float(value) != int(value):
        raise ShipidError(f"{where}{key}: {value!r} is not an integer")
    return kind(value)


def _cutoff(value: str, where: str = "") -> float | str | None:
    """The prefilter setting: 'auto', None (no filter) or a cut-off in Hz."""
    if value in ("auto", "none"):
        return None if value == "none" else "auto"
    try:
        hz = float(value)
    except ValueError:
        raise ShipidError(f"{where}filter: {value!r} is not auto, none or a cut-off in Hz") from None
    if not (math.isfinite(hz) and hz > 0):
        raise ShipidError(f"{where}filter: {value!r} must be a cut-off > 0 Hz")
    return hz


def run_trial(trial: Trial) -> dict:
    """Run one trial; a failure is recorded in its row (``error``), never raised.

    Returns one flat row: the trial's parameters, the prefilter chosen, per held-out manoeuvre
    and signal the error std of the identified model and of the truth on the same noisy log,
    whether it beats the paper's table, every identified coefficient and, with bootstrap, the
    coverage of the true coefficients.
    """
    from shipid.parallel import single_threaded

    start = time.perf_counter()
    row: dict = asdict(trial) | {"error": ""}
    try:
        row |= single_threaded(_trial_results, trial)
    except Exception as exc:  # one failed trial must not lose the study; its row says why
        row["error"] = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
    row["seconds"] = time.perf_counter() - start
    return row


def _trial_results(trial: Trial) -> dict:
    from shipid.data.preprocess import lowpass
    from shipid.demo import PAPER_TABLE, TRAINING, synthesise_trials
    from shipid.evaluation.validate import validate
    from shipid.identification.identify import identify
    from shipid.vessels import PAPER_IMU, scale_ship_model

    truth = scale_ship_model()
    logs = synthesise_trials(trial.seed, sensor=PAPER_IMU.scaled(trial.noise))
    drop = {"u": ["r^2"]} if trial.structure == "blanke" else None

    # The output-error fit starts from the LS-SVM model (chosen and prefiltered as usual).
    equation_error = "lssvm" if trial.estimator == OUTPUT_ERROR else trial.estimator

    def fit(train, weights=None):
        return identify(train, model=trial.structure, gamma=trial.gamma, drop=drop,
                        estimator=equation_error, force=True, sample_weight=weights).model  # fmt: skip

    cutoff = _cutoff(trial.filter)
    out: dict = {}
    if cutoff == "auto":
        from shipid.identification.prefilter import choose_prefilter

        cutoff, _ = choose_prefilter([logs[TRAINING]], fit)
    out["cutoff_hz"] = math.nan if cutoff is None else float(cutoff)
    train = logs[TRAINING] if cutoff is None else lowpass(logs[TRAINING], cutoff)
    model = fit(train)
    table = None
    if trial.estimator == OUTPUT_ERROR:
        from shipid.identification.output_error import coefficient_intervals, output_error

        fitted, _ = output_error(model, logs[TRAINING], draws=10, seed=trial.seed)
        model, table = fitted.model, coefficient_intervals(fitted, LEVEL)
    held = [k for k in logs if k != TRAINING]
    # The errors alone are kept: no closed-loop start spread (ten runs per log) is drawn.
    ours = validate(model, [logs[k] for k in held], held, start_draws=False)
    true = validate(truth, [logs[k] for k in held], held, start_draws=False)
    for a, b in zip(ours, true, strict=True):
        for s in "uvr":
            out[f"{a.name}: {s} error std"] = a.metrics[s]["std"]
            out[f"{a.name}: {s} truth error std"] = b.metrics[s]["std"]
        out[f"{a.name}: beats paper"] = all(a.metrics[s]["std"] <= p
                                            for s, p in zip("uvr", PAPER_TABLE[a.name], strict=True))
    for dof, terms in model.coefficients.items():
        for term, value in terms.items():
            out[f"{dof}: {term}"] = float(value)
    if trial.bootstrap and table is None:
        from shipid.identification.identify import weighted_refit
        from shipid.identification.uncertainty import bootstrap

        refit = weighted_refit(train, model=trial.structure, gamma=trial.gamma, drop=drop,
                               estimator=equation_error)  # fmt: skip
        ens = bootstrap([train], refit, replicates=trial.bootstrap, seed=trial.seed)
        table = ens.coefficient_table(LEVEL)
    if table is not None:
        covered, wrong_sign = [], 0
        for _, c in table.iterrows():
            true_value = truth.coefficients.get(c["equation"], {}).get(c["term"], 0.0)
            inside = bool(c["lower"] <= true_value <= c["upper"])
            covered.append(inside)
            wrong_sign += bool(not inside and np.sign(c["value"]) * np.sign(true_value) < 0)
        out["coverage"] = float(np.mean(covered))
        out["wrong sign outside"] = int(wrong_sign)
    return out


def run_study(
    spec: StudySpec,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool = True,
) -> pd.DataFrame:
    """Run every trial of ``spec``; one row per trial, in trial order whatever ran them.

    Parameters
    ----------
    scheduler : None (a ``LocalCluster`` of ``workers`` processes), 'serial' (this process,
        no Dask) or the address of a running Dask scheduler (``tcp://host:8786``), whose
        workers must have shipid installed (``shipid.parallel.run_tasks``).
    workers : worker processes of the local cluster (default: the machine's cores).
    progress : a progress bar on standard error.
    """
    from shipid.parallel import run_tasks

    rows = run_tasks(run_trial, spec.trials(), scheduler, workers, progress, unit="trial")
    return pd.DataFrame(rows).drop(columns="index")


def summary(results: pd.DataFrame) -> pd.DataFrame:
    """Per grid point: trials, failures, prefilter, error ratios to the truth's and paper wins.

    The ratio is the identified model's error std over the true model's on the same noisy
    held-out log (1 = as good as the truth): ``median ≤ largest`` over the seeds, u / v / r.
    """
    keys = [k for k in GRID_KEYS if k in results]
    manoeuvres = [c[: -len(": beats paper")] for c in results if c.endswith(": beats paper")]
    rows = []
    for point, group in results.groupby(keys, sort=False):
        ok = group[group["error"] == ""]
        row = dict(zip(keys, point, strict=True)) | {"trials": len(group),
                                                     "failed": len(group) - len(ok)}
        for m in manoeuvres:
            ratios = np.column_stack([ok[f"{m}: {s} error std"] / ok[f"{m}: {s} truth error std"]
                                      for s in "uvr"]) if len(ok) else np.full((0, 3), np.nan)
            row[f"{m}: u/v/r"] = (" / ".join(_fmt(x) for x in _stat(np.median, ratios)) + " ≤ "
                                  + " / ".join(_fmt(x) for x in _stat(np.max, ratios)))
            row[f"{m}: beats paper"] = f"{int(ok[f'{m}: beats paper'].sum())} of {len(ok)}"
        if "coverage" in ok:
            row["coverage"] = float(ok["coverage"].mean()) if len(ok) else math.nan
            row["wrong sign outside"] = int(ok["wrong sign outside"].sum())
        row["seconds per trial"] = round(float(group["seconds"].median()), 3)
        rows.append(row)
    return pd.DataFrame(rows)


def _stat(fn: Callable, ratios: np.ndarray) -> Iterable[float]:
    return fn(ratios, axis=0) if len(ratios) else [math.nan] * 3


def _fmt(x: float) -> str:
    return "–" if not math.isfinite(x) else f"{x:.2f}"
