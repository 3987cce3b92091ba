"""Mercer kernels of the LS-SVM (paper section 1, eq. 6).

Conventions follow LS-SVMlab, not scikit-learn:

* ``"linear"``: K(x, z) = xᵀz
* ``"rbf"``:    K(x, z) = exp(−‖x − z‖² / σ²)     (LS-SVMlab ``sig2`` = σ²;
  scikit-learn's ``gamma`` of ``rbf_kernel`` = 1/σ²)
* ``"poly"``:   K(x, z) = (xᵀz + coef0)^degree
"""

from __future__ import annotations

import numpy as np

KERNELS = ("linear", "rbf", "poly")

# Rows of a kernel block computed at once when the other side is long: bounds temporaries.
BLOCK_ELEMENTS = 4_000_000


def kernel_matrix(
    X: np.ndarray,
    Z: np.ndarray,
    kernel: str,
    sigma: float = 1.0,
    degree: int = 3,
    coef0: float = 1.0,
) -> np.ndarray:
    """Kernel matrix K[i, j] = K(X[i], Z[j]) as a new C-contiguous float64 array."""
    K = X @ Z.T
    if kernel == "linear":
        return K
    if kernel == "rbf":
        # ‖x − z‖² = ‖x‖² + ‖z‖² − 2xᵀz: the product from BLAS, the rest in place over the
        # N×M buffer by NumPy, whose exp is vectorised (SIMD): 1.6× faster than one compiled
        # pass calling exp per element (NumPy 2.4, numba 0.6x).
        K *= -2.0
        K += np.einsum("ij,ij->i", X, X)[:, None]
        K += np.einsum("ij,ij->i", Z, Z)[None, :]
        np.maximum(K, 0.0, out=K)  # rounding can make a distance slightly negative
        K *= -1.0 / (sigma * sigma)
        return np.exp(K, out=K)
    if kernel == "poly":
        K += coef0
        return np.power(K, degree, out=K)
    raise ValueError(f"kernel must be one of {KERNELS}, got {kernel!r}")


def row_blocks(n_rows: int, n_cols: int) -> list[slice]:
    """Slices of rows such that each block has at most ``BLOCK_ELEMENTS`` kernel entries."""
    step = max(1, BLOCK_ELEMENTS // max(1, n_cols))
    return [slice(i, min(i + step, n_rows)) for i in range(0, n_rows, step)]
