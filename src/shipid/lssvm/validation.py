"""Input checks at the boundary of the LS-SVM estimators: one-line errors that say where."""

from __future__ import annotations

import numbers

import numpy as np


def first_non_finite(a: np.ndarray) -> tuple[str, tuple[int, ...]] | None:
    """('NaN' or 'inf', index) of the first non-finite entry, or None."""
    bad = ~np.isfinite(a)
    if not bad.any():
        return None
    idx = np.unravel_index(int(np.flatnonzero(bad.ravel())[0]), a.shape)
    kind = "NaN" if np.isnan(a[idx]) else "inf"
    return kind, tuple(int(i) for i in idx)


def check_finite(a: np.ndarray, name: str) -> None:
    """ValueError naming the row (and column) of the first NaN or inf in ``a``."""
    found = first_non_finite(a)
    if found is None:
        return
    kind, idx = found
    where = f"row {idx[0]}" + (f", column {idx[1]}" if len(idx) > 1 else "")
    raise ValueError(f"{name} contains {kind} at {where}")


def check_target_finite(y: object) -> None:
    """Check y for NaN/inf before scikit-learn's validation, which does not say where."""
    try:
        arr = np.asarray(y)
        if np.iscomplexobj(arr):
            return  # scikit-learn's validation refuses complex targets
        arr = arr.astype(float)
    except (TypeError, ValueError):
        return  # not numeric: scikit-learn's validation gives the error
    check_finite(arr, "y")


def validated_training_data(estimator, X, y, sample_weight):
    """X (float64, finite), y, and finite sample weights, with errors that name the row.

    ``estimator`` is the scikit-learn estimator whose ``n_features_in_`` is set.
    """
    from sklearn.utils.validation import _check_sample_weight, validate_data

    if y is not None:
        check_target_finite(y)
    X, y = validate_data(estimator, X, y, multi_output=True, y_numeric=True,
                         ensure_min_samples=2, ensure_all_finite=False, dtype=np.float64)
    check_finite(X, "X")
    w = _check_sample_weight(sample_weight, X, dtype=np.float64)
    check_finite(w, "sample_weight")
    return X, y, w


def check_positive(value: object, name: str) -> float:
    """``value`` as a float if it is a finite number > 0, else a ValueError naming it."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise ValueError(f"{name} must be a positive number, got {value!r}")
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    return float(value)


def check_choice(value: object, name: str, choices: tuple[str, ...]) -> str:
    """``value`` if it is one of ``choices``, else a ValueError naming it."""
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return str(value)


def check_positive_int(value: object, name: str, minimum: int = 1) -> int:
    """``value`` if it is an integer ≥ ``minimum``, else a ValueError naming it."""
    if not isinstance(value, numbers.Integral) or isinstance(value, bool) or value < minimum:
        raise ValueError(f"{name} must be an integer ≥ {minimum}, got {value!r}")
    return int(value)
