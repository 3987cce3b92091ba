"""LS-SVM regression (paper section 1): exact dense and primal solvers, weighted and robust
fits, fixed-size (Nyström) LS-SVM for large N, and closed-form leave-one-out model selection."""

from .estimator import LSSVR
from .kernels import KERNELS, kernel_matrix
from .selection import LSSVRCV, loo_residuals
from .solvers import NumericalWarning

__all__ = ["KERNELS", "LSSVR", "LSSVRCV", "NumericalWarning", "kernel_matrix", "loo_residuals"]
