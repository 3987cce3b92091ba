"""LS-SVM regression (paper section 1): exact dense and primal solvers, weighted and robust
fits, fixed-size (Nyström) LS-SVM for large N, and closed-form leave-one-out model selection.

The estimators (scikit-learn based) are imported on first use, so that code needing only the
solvers (``shipid.lssvm.solvers``) does not pay for scikit-learn.
"""

import importlib

_EXPORTS = {"LSSVR": "estimator", "LSSVRCV": "selection", "loo_residuals": "selection",
            "KERNELS": "kernels", "kernel_matrix": "kernels", "NumericalWarning": "solvers"}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'shipid.lssvm' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"shipid.lssvm.{module}"), name)
    globals()[name] = value
    return value
