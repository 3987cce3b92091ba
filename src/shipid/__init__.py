"""shipid: semiphysical identification of ship manoeuvring models with LS-SVM.

The public API is re-exported here and imported on first use, so that ``import shipid`` (and every
CLI command) pays only for the modules it touches::

    from shipid import read_log, identify, validate, load_model, zigzag, turning_circle, LSSVR
"""

from __future__ import annotations

import importlib

__version__ = "0.2.0"

# name → module that defines it
_EXPORTS = {
    "ShipidError": "shipid.errors",
    "ShipidWarning": "shipid.errors",
    "read_log": "shipid.data.io",
    "read_trial_log": "shipid.trials.reading",
    "write_log": "shipid.data.io",
    "make_log": "shipid.data.log",
    "lowpass": "shipid.data.preprocess",
    "resample": "shipid.data.preprocess",
    "trim": "shipid.data.trim",
    "ManoeuvringModel": "shipid.dynamics.model",
    "ModelStructure": "shipid.dynamics.model",
    "get_structure": "shipid.dynamics.model",
    "simulate": "shipid.dynamics.simulate",
    "simulate_log": "shipid.dynamics.simulate",
    "SteeringMachine": "shipid.dynamics.steering",
    "zigzag": "shipid.trials.manoeuvres",
    "turning_circle": "shipid.trials.manoeuvres",
    "pull_out": "shipid.trials.manoeuvres",
    "manoeuvre_indices": "shipid.trials.indices",
    "identify": "shipid.identification.identify",
    "weighted_refit": "shipid.identification.identify",
    "common_rudder_convention": "shipid.data.log",
    "select": "shipid.identification.select",
    "auto_structure": "shipid.identification.auto_structure",
    "selection_ensemble": "shipid.identification.selection_ensemble",
    "imo_criteria": "shipid.trials.criteria",
    "Particulars": "shipid.data.particulars",
    "read_particulars": "shipid.data.particulars",
    "stopping": "shipid.trials.manoeuvres",
    "spiral": "shipid.trials.manoeuvres",
    "refine": "shipid.identification.refine",
    "identify_correction": "shipid.identification.correction",
    "output_error": "shipid.identification.output_error",
    "coefficient_intervals": "shipid.identification.output_error",
    "PhysicsOptions": "shipid.identification.physics",
    "clarke_prior": "shipid.identification.priors",
    "prior_from_model": "shipid.identification.priors",
    "bootstrap": "shipid.identification.uncertainty",
    "Ensemble": "shipid.identification.uncertainty",
    "choose_prefilter": "shipid.identification.prefilter",
    "HybridModel": "shipid.dynamics.hybrid",
    "KernelResidual": "shipid.dynamics.hybrid",
    "fit_residual": "shipid.identification.residual",
    "choose_residual": "shipid.identification.residual",
    "check_plausibility": "shipid.identification.plausibility",
    "held_rudder_at": "shipid.identification.plausibility",
    "steady_approach": "shipid.dynamics.equilibrium",
    "validate": "shipid.evaluation.validate",
    "load_model": "shipid.reporting.modelfile",
    "save_model": "shipid.reporting.modelfile",
    "LSSVR": "shipid.lssvm",
    "LSSVRCV": "shipid.lssvm",
    "get_vessel": "shipid.vessels",
    "read_mmg": "shipid.vessels.mmg_file",
    "sister_ship": "shipid.vessels.mmg_file",
}

__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'shipid' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
