"""Nyström feature map for fixed-size LS-SVM (Suykens et al. 2002, ch. 6; Williams & Seeger 2001).

With m landmarks L and K_mm = U Λ Uᵀ, the map φ(x) = Λ^{-1/2} Uᵀ K(L, x) satisfies
φ(x)ᵀφ(z) = K(x, L) K_mm⁻¹ K(L, z), which equals K(x, z) whenever x or z is a landmark. The primal
LS-SVM with bias on φ is then solved in row blocks, so no N×N (or N×m) matrix is ever held.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from .kernels import kernel_matrix, row_blocks

# Eigenvalues of K_mm below this fraction of the largest are dropped: they carry no information
# at double precision and would blow up Λ^{-1/2}.
EIGEN_RTOL = 1e-12


class NystromMap:
    """Feature map of a kernel restricted to landmarks."""

    def __init__(self, landmarks: np.ndarray, kernel: str, **kernel_params: float) -> None:
        self.landmarks = landmarks
        self.kernel = kernel
        self.kernel_params = kernel_params
        K_mm = kernel_matrix(landmarks, landmarks, kernel, **kernel_params)
        lam, U = np.linalg.eigh(K_mm)
        keep = lam > EIGEN_RTOL * lam[-1]
        # (m, k): φ(x) = K(x, L) @ transform
        self.transform = U[:, keep] / np.sqrt(lam[keep])
        self.n_components = int(keep.sum())

    def kernel_to_landmarks(self, X: np.ndarray) -> np.ndarray:
        """K(X, landmarks), (N, m)."""
        return kernel_matrix(X, self.landmarks, self.kernel, **self.kernel_params)

    def features(self, X: np.ndarray) -> np.ndarray:
        """Nyström features φ(X), (N, k)."""
        return self.kernel_to_landmarks(X) @ self.transform

    def feature_blocks(self, X: np.ndarray) -> Iterator[tuple[slice, np.ndarray]]:
        """(rows, φ(X[rows])) over row blocks of bounded size."""
        for rows in row_blocks(X.shape[0], self.landmarks.shape[0]):
            yield rows, self.features(X[rows])


def choose_landmarks(X: np.ndarray, n_landmarks: int, rng: np.random.Generator) -> np.ndarray:
    """A uniform random subset of distinct rows (all rows when n_landmarks ≥ N)."""
    n = X.shape[0]
    if n_landmarks >= n:
        return X.copy()
    idx = np.sort(rng.choice(n, size=n_landmarks, replace=False))
    return X[idx].copy()
