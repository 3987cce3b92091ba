"""Mercer kernels of the LS-SVM (paper section 1, eq. 6).

Conventions follow LS-SVMlab, not scikit-learn:

* ``"linear"``: K(x, z) = xᵀz
* ``"rbf"``:    K(x, z) = exp(−‖x − z‖² / σ²)     (LS-SVMlab ``sig2`` = σ²;
  scikit-learn's ``gamma`` of ``rbf_kernel`` = 1/σ²)
* ``"poly"``:   K(x, z) = (xᵀz + coef0)^degree
"""

from __future__ import annotations

import numba
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
        # ‖x − z‖² = ‖x‖² + ‖z‖² − 2xᵀz: the product from BLAS, the rest in one compiled pass
        # over the N×M buffer (in place) instead of five NumPy passes.
        _rbf_from_products(K, np.einsum("ij,ij->i", X, X), np.einsum("ij,ij->i", Z, Z),
                           1.0 / (sigma * sigma))  # fmt: skip
        return K
    if kernel == "poly":
        K += coef0
        return np.power(K, degree, out=K)
    raise ValueError(f"kernel must be one of {KERNELS}, got {kernel!r}")


@numba.njit(cache=True, fastmath=True)
def _rbf_from_products(K: np.ndarray, x_norms: np.ndarray, z_norms: np.ndarray,
                       inv_sigma2: float) -> None:  # fmt: skip
    """K[i, j] ← exp(−max(‖xᵢ‖² + ‖zⱼ‖² − 2 K[i, j], 0) / σ²) in place (K holds xᵢᵀzⱼ)."""
    n, m = K.shape
    for i in range(n):
        xi = x_norms[i]
        for j in range(m):
            d = xi + z_norms[j] - 2.0 * K[i, j]
            # rounding can make a distance slightly negative
            K[i, j] = np.exp(-(d if d > 0.0 else 0.0) * inv_sigma2)


def row_blocks(n_rows: int, n_cols: int) -> list[slice]:
    """Slices of rows such that each block has at most ``BLOCK_ELEMENTS`` kernel entries."""
    step = max(1, BLOCK_ELEMENTS // max(1, n_cols))
    return [slice(i, min(i + step, n_rows)) for i in range(0, n_rows, step)]
