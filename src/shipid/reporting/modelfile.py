"""Versioned JSON model files: structure, named coefficients, Δk, γ, form, the raw LS-SVM solution,
diagnostics and provenance (training files with their sha256). The round trip is exact."""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from pathlib import Path

from shipid import __version__
from shipid.dynamics.model import ManoeuvringModel
from shipid.errors import ShipidError
from shipid.identification.identify import Identification
from shipid.identification.refine import Refinement
from shipid.outputs import atomic_write_text

FORMAT = "shipid-model"
VERSION = 1


def sha256(path: str | Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def json_safe(obj):
    """JSON cannot hold inf/NaN: write them as null."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [json_safe(v) for v in obj]
    return obj


def model_document(ident: Identification, training_files: Sequence[str | Path] = (),
                   preprocessing: dict | None = None, refinement: Refinement | None = None,
                   plausibility: dict | None = None,
                   model: ManoeuvringModel | None = None) -> dict:  # fmt: skip
    """The model file. ``model`` is the one users get (default: the refined model when there is a
    refinement, else the LS-SVM one); the LS-SVM model stays in ``refinement.initial_model`` and
    the refined one in ``refinement.refined_model``."""
    if model is None:
        model = refinement.model if refinement is not None else ident.model
    return json_safe({
        "format": FORMAT, "version": VERSION, "shipid": __version__,
        "model": model.to_dict(),
        "identification": {"form": ident.form, "gamma": ident.gamma, "dt": ident.dt,
                           "discrete": ident.discrete, "diagnostics": ident.diagnostics,
                           "warnings": ident.warnings, "preprocessing": preprocessing or {},
                           "refinement": refinement.to_dict() if refinement else None,
                           "plausibility": plausibility},
        "provenance": {"training_files": [{"path": str(p), "sha256": sha256(p)}
                                          for p in training_files]},
    })  # fmt: skip


def save_model(path: str | Path, ident: Identification, training_files: Sequence[str | Path] = (),
               preprocessing: dict | None = None, refinement: Refinement | None = None,
               plausibility: dict | None = None,
               model: ManoeuvringModel | None = None) -> Path:  # fmt: skip
    doc = model_document(ident, training_files, preprocessing, refinement, plausibility, model)
    # repr of a float is exact, so the coefficients survive the round trip bit for bit.
    return atomic_write_text(path, json.dumps(doc, indent=2, ensure_ascii=False) + "\n")


def load_document(path: str | Path) -> dict:
    path = Path(path)
    if not path.exists():
        raise ShipidError(f"{path}: no such model file")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ShipidError(f"{path}: not a JSON model file ({exc})") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise ShipidError(f"{path}: not a shipid model file (no \"format\": \"{FORMAT}\")")
    if doc.get("version") != VERSION:
        raise ShipidError(f"{path}: model file version {doc.get('version')!r} is not supported "
                          f"(this shipid reads version {VERSION})")  # fmt: skip
    return doc


def load_model(path: str | Path, which: str = "model") -> ManoeuvringModel:
    """The file's model, or with ``which="lssvm"`` the LS-SVM model a refinement started from."""
    return model_from_document(load_document(path), path, which)


def model_from_document(doc: dict, path: str | Path, which: str = "model") -> ManoeuvringModel:
    if which not in ("model", "lssvm"):
        raise ShipidError(f"which must be 'model' or 'lssvm', got {which!r}")
    data = doc.get("model")
    if which == "lssvm":
        refinement = (doc.get("identification") or {}).get("refinement")
        if refinement:
            data = refinement.get("initial_model")
    try:
        return ManoeuvringModel.from_dict(data)
    except (KeyError, TypeError, ValueError) as exc:
        raise ShipidError(f"{path}: malformed model ({exc})") from None
