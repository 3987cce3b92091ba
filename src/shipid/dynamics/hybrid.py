"""A physical model plus a kernel residual: the grey-box model of issue #10 item 4.

The physical model's accelerations (``ManoeuvringModel``) plus an RBF expansion on what they
miss, fitted by ``shipid.identification.residual``::

    ν̇ = f_phys(ν, δ, …) + w(z) · (Σᵢ aᵢ exp(−‖z − cᵢ‖² / σ²) + b),   z = (x − μ) / s,

with x the residual's features (u, v, r, δ and, where it varies in the training logs, n),
standardised by the training logs' mean μ and spread s; cᵢ are the LS-SVM's support vectors or,
over ``shipid.identification.residual.DENSE_LIMIT`` samples, its fixed-size landmarks, so a step
costs M ≤ a few hundred kernel evaluations. Outside the training envelope the residual fades
out: w(z) = min(1, k(z)/k₀), where k(z) = maxᵢ exp(−‖z − cᵢ‖² / σ²) is the kernel's reach at z
and k₀ the 5th percentile of it over the training samples, so the physical model alone is left
where the residual has seen no data.
``fade`` says how far a run went there.

A hybrid runs compiled (``shipid.dynamics.hybrid_kernel``: the term model's state derivative plus
the residual, through the kernel's integrators) in ``shipid.dynamics.simulate`` and in the
manoeuvres' closed loop; ``HybridModel.derivatives`` is the same function in NumPy.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from shipid.data.log import column_array, column_values
from shipid.dynamics.kernel import c_array
from shipid.dynamics.model import DOFS, ManoeuvringModel, ModelStructure
from shipid.dynamics.terms import INPUT_SIGNALS
from shipid.errors import ShipidError
from shipid.lssvm.kernels import kernel_matrix

FEATURES = ("u", "v", "r", "delta", "n")


@dataclass(frozen=True, eq=False)
class KernelResidual:
    """An RBF expansion on standardised features giving three accelerations [u̇, v̇, ṙ].

    Attributes
    ----------
    features : names of the inputs (from ``FEATURES``), in the columns' order.
    mean, scale : (d,) standardisation of the features.
    sigma, gamma : the RBF width (on standardised features) and the LS-SVM's γ.
    centres : (M, d) standardised centres; weights : (M, 3); intercept : (3,).
    reach : k₀, below which the residual fades out.
    """

    features: tuple[str, ...]
    mean: np.ndarray
    scale: np.ndarray
    sigma: float
    gamma: float
    centres: np.ndarray
    weights: np.ndarray
    intercept: np.ndarray
    reach: float

    def __post_init__(self) -> None:
        d = len(self.features)
        unknown = [f for f in self.features if f not in FEATURES]
        if unknown or d == 0:
            raise ShipidError(f"kernel residual: features must be among {', '.join(FEATURES)}, "
                              f"got {list(self.features)}")  # fmt: skip
        shapes = {"mean": (d,), "scale": (d,), "intercept": (3,)}
        for name, shape in shapes.items():
            if np.shape(getattr(self, name)) != shape:
                raise ShipidError(f"kernel residual: {name} must have shape {shape}")
        m = np.shape(self.centres)[0] if np.ndim(self.centres) == 2 else -1
        if np.shape(self.centres) != (m, d) or m < 1 or np.shape(self.weights) != (m, 3):
            raise ShipidError(f"kernel residual: centres must be (M, {d}) and weights (M, 3)")
        numbers = (self.mean, self.scale, self.centres, self.weights, self.intercept)
        if not all(np.all(np.isfinite(a)) for a in numbers) or np.any(self.scale <= 0):
            raise ShipidError("kernel residual: non-finite values or a scale ≤ 0")
        if not (self.sigma > 0 and self.gamma > 0 and 0 < self.reach <= 1):
            raise ShipidError("kernel residual: sigma and gamma must be > 0, reach in (0, 1]")

    @property
    def n_centres(self) -> int:
        """M, the number of RBF centres."""
        return int(self.centres.shape[0])

    def _kernel(self, x: np.ndarray) -> np.ndarray:
        """K(z, cᵢ) (B, M) at raw features ``x`` (B, d): the LS-SVM's own RBF kernel."""
        return kernel_matrix((x - self.mean) / self.scale, self.centres, "rbf", sigma=self.sigma)

    def fade(self, x: np.ndarray) -> np.ndarray:
        """(B,) weight w(z) in [0, 1] at raw features ``x`` (B, d): 1 inside the envelope."""
        return np.minimum(1.0, self._kernel(np.atleast_2d(x)).max(axis=1) / self.reach)

    def accelerations(self, x: np.ndarray, fade: bool = True) -> np.ndarray:
        """(B, 3) residual accelerations at raw features ``x`` (B, d), faded outside the
        training envelope unless ``fade`` is False (the fitted expansion itself)."""
        K = self._kernel(np.atleast_2d(x))
        out = K @ self.weights + self.intercept
        if fade:
            out *= np.minimum(1.0, K.max(axis=1) / self.reach)[:, None]
        return out

    def to_dict(self) -> dict:
        """JSON-ready."""
        return {"kind": "rbf", "features": list(self.features), "mean": self.mean.tolist(),
                "scale": self.scale.tolist(), "sigma": self.sigma, "gamma": self.gamma,
                "reach": self.reach, "centres": self.centres.tolist(),
                "weights": self.weights.tolist(), "intercept": self.intercept.tolist()}  # fmt: skip

    @classmethod
    def from_dict(cls, data: Mapping, where: str = "kernel residual") -> KernelResidual:
        """From ``to_dict``'s record; a malformed one is a ``ShipidError`` naming ``where``."""
        try:
            if data.get("kind") != "rbf":
                raise ShipidError(f"{where}: kind must be 'rbf', got {data.get('kind')!r}")
            return cls(tuple(str(f) for f in data["features"]),
                       np.asarray(data["mean"], float), np.asarray(data["scale"], float),
                       float(data["sigma"]), float(data["gamma"]),
                       np.asarray(data["centres"], float), np.asarray(data["weights"], float),
                       np.asarray(data["intercept"], float), float(data["reach"]))  # fmt: skip
        except ShipidError as exc:
            raise ShipidError(f"{where}: {exc}") from None
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise ShipidError(f"{where}: malformed record ({exc})") from None


class HybridModel:
    """A ``ManoeuvringModel`` plus a ``KernelResidual`` (the dynamics protocol of
    ``shipid.dynamics.simulate``: ``derivatives``, ``uses_thrust``, ``uses_rps``, ``inputs``)."""

    def __init__(self, physical: ManoeuvringModel, residual: KernelResidual,
                 name: str | None = None) -> None:  # fmt: skip
        if not isinstance(physical, ManoeuvringModel):
            raise ShipidError("a hybrid model's physical part must be a ManoeuvringModel")
        self.physical, self.residual = physical, residual
        self.name = name or f"{physical.name} + kernel residual"
        uses_n = "n" in residual.features
        self.uses_rps = physical.uses_rps or uses_n
        self.uses_thrust = physical.uses_thrust
        self.inputs = tuple(dict.fromkeys((*physical.inputs, *(("n",) if uses_n else ()))))
        r = residual
        # A DOF the physical model holds (a Nomoto model's u and v) stays held.
        self._moves = np.array([d in physical.structure.dofs for d in DOFS], dtype=float)
        # The compiled runs' arguments (``shipid.dynamics.hybrid_kernel``), built once.
        self.kernel_arguments = (
            c_array(r.mean), c_array(r.scale), c_array(r.centres),
            c_array(r.weights * self._moves), c_array(r.intercept * self._moves),
            1.0 / (r.sigma * r.sigma), 1.0 / r.reach,
            np.array([FEATURES.index(f) for f in r.features], dtype=np.int64))  # fmt: skip

    @property
    def structure(self) -> ModelStructure:
        """The physical model's structure (which DOFs move; the residual moves no other)."""
        return self.physical.structure

    @property
    def uses_wind(self) -> bool:
        """Whether the physical model has wind terms."""
        return self.physical.uses_wind

    def features(self, nu: np.ndarray, delta, rps=None) -> np.ndarray:
        """(B, d) raw residual features at states ``nu`` (B, 3)."""
        nu = np.atleast_2d(np.asarray(nu, dtype=float))
        cols = {"u": nu[:, 0], "v": nu[:, 1], "r": nu[:, 2],
                "delta": np.broadcast_to(np.asarray(delta, dtype=float), nu.shape[:1])}  # fmt: skip
        if "n" in self.residual.features:
            if rps is None:
                raise ShipidError("this hybrid model's residual uses the propeller speed: give "
                                  "an rps series (log column n)")  # fmt: skip
            cols["n"] = np.broadcast_to(np.asarray(rps, dtype=float), nu.shape[:1])
        return np.column_stack([cols[f] for f in self.residual.features])

    def derivatives(self, nu: np.ndarray, delta: np.ndarray, thrust=None, rps=None,
                    **inputs) -> np.ndarray:  # fmt: skip
        """(B, 3) body accelerations: the physical model's (on its compiled kernel) plus the
        faded residual."""
        nu = np.atleast_2d(np.asarray(nu, dtype=float))
        given = {"delta": delta, "n": rps, "thrust": thrust, **inputs}
        columns = np.zeros((nu.shape[0], len(INPUT_SIGNALS)))
        for j, name in enumerate(INPUT_SIGNALS):
            if given.get(name) is not None:
                columns[:, j] = given[name]
        base = self.physical.compiled_accelerations(nu, columns)
        return base + self.residual.accelerations(self.features(nu, delta, rps)) * self._moves

    def accelerations(self, u, v, r, delta, thrust=None, rps=None, **inputs) -> np.ndarray:
        """(n, 3) accelerations for arrays of states and inputs (``ManoeuvringModel``'s form)."""
        nu = np.column_stack([np.atleast_1d(np.asarray(x, dtype=float)) for x in (u, v, r)])
        return self.derivatives(nu, delta, thrust, rps, **inputs)

    def faded_share(self, log) -> float:
        """Share of a (simulated) log's samples where the residual is faded below half."""
        if len(log) == 0:
            return 0.0
        rps = column_values(log, "n") if "n" in log.columns else None
        x = self.features(column_array(log, ("u", "v", "r")), column_values(log, "delta"), rps)
        return float(np.mean(self.residual.fade(x) < 0.5))

    def rudder_positive_turns_at(self, speed: float = 1.0, rps: float | None = None) -> str:
        """The physical model's rudder convention (the residual is a correction to it)."""
        return self.physical.rudder_positive_turns_at(speed, rps)

    def equations(self, precision: int = 4, std_errors: Mapping | None = None) -> str:
        """The physical equations and a line for the residual."""
        r = self.residual
        return (self.physical.equations(precision, std_errors) + "\n+ kernel residual on "
                f"({', '.join(r.features)}): RBF σ = {r.sigma:g} (standardised), γ = "
                f"{r.gamma:g}, {r.n_centres} centres, faded outside its training envelope")

    def __repr__(self) -> str:
        return f"HybridModel({self.physical!r}, {self.residual.n_centres} centres)"
