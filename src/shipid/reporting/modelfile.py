"""Versioned JSON model files: structure (term texts), named coefficients, Δk, γ, form, the raw
LS-SVM solution, diagnostics, the training envelope and provenance (training files with their
sha256). The round trip is exact.

Loading checks the file against its schema: a wrong type, a missing key or a non-finite coefficient
gives one message naming the key (``model.coefficients.r.delta``) and what was expected.
Version 1 files (before the term algebra) load unchanged: their term names parse.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from shipid import __version__
from shipid.dynamics.hybrid import HybridModel, KernelResidual
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.dynamics.terms import CROSSFLOW, RUDDER, parse_term
from shipid.errors import ShipidError
from shipid.outputs import atomic_write_text

if TYPE_CHECKING:  # loading a model file needs neither (nor scikit-learn behind them)
    from shipid.identification.identify import Identification
    from shipid.identification.refine import Refinement

FORMAT = "shipid-model"
VERSION = 2
READABLE_VERSIONS = (1, 2)


def sha256(path: str | Path) -> str:
    """SHA-256 of a file, read in 1 MiB chunks."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def model_fingerprint(model_data) -> str:
    """SHA-256 of a model file's structure and coefficients (JSON, sorted keys; not its name):
    what the fit's records (intervals, error band, standard errors) were computed for."""
    data = model_data if isinstance(model_data, Mapping) else {}
    text = json.dumps(json_safe({k: data.get(k) for k in ("structure", "coefficients")}),
                      sort_keys=True, ensure_ascii=False)  # fmt: skip
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def json_safe(obj):
    """JSON-ready data: NumPy scalars and arrays become Python ones, inf/NaN become null."""
    if hasattr(obj, "tolist") and not isinstance(obj, str):  # NumPy scalars and arrays
        obj = obj.tolist()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [json_safe(v) for v in obj]
    return obj


def model_document(ident: Identification, training_files: Sequence[str | Path] = (),
                   preprocessing: dict | None = None, refinement: Refinement | None = None,
                   plausibility: dict | None = None, model: ManoeuvringModel | None = None,
                   selection: dict | None = None, particulars: dict | None = None,
                   uncertainty: dict | None = None, error_band: dict | None = None,
                   residual: dict | None = None, structure_choice: dict | None = None
                   ) -> dict:  # fmt: skip
    """The model file. ``model`` is the one users get (default: the refined model when there is a
    refinement, else the LS-SVM one); the LS-SVM model stays in ``refinement.initial_model`` and
    the refined one in ``refinement.refined_model``. ``residual``: the model's kernel residual
    and its selection (``{"residual": KernelResidual.to_dict(), "selection": ...}``)."""
    if model is None:
        model = refinement.model if refinement is not None else ident.model
    return _fingerprinted({
        "format": FORMAT, "version": VERSION, "shipid": __version__,
        "model": model.to_dict(),
        "particulars": particulars,
        "prime": prime_record(model, particulars, (preprocessing or {}).get("approach_speed")),
        "uncertainty": uncertainty,
        "kernel_residual": residual,
        "identification": {"form": ident.form, "gamma": ident.gamma, "dt": ident.dt,
                           "estimator": ident.estimator, "selection": selection,
                           "physics": ident.physics,
                           "discrete": ident.discrete, "diagnostics": ident.diagnostics,
                           "warnings": ident.warnings, "preprocessing": preprocessing or {},
                           "envelope": ident.envelope,
                           "refinement": refinement.to_dict() if refinement else None,
                           "plausibility": plausibility, "error_band": error_band,
                           "structure_choice": structure_choice},
        "provenance": {"training_files": [{"path": str(p), "sha256": sha256(p)}
                                          for p in training_files]},
    })  # fmt: skip


def _fingerprinted(doc: dict) -> dict:
    """``json_safe(doc)`` with its model's fingerprint in ``provenance.model_sha256``."""
    doc = json_safe(doc)
    doc.setdefault("provenance", {})["model_sha256"] = model_fingerprint(doc["model"])
    return doc


def stale_fit_records(doc: dict, path: str | Path) -> str | None:
    """Where a model file's coefficients are not those it was fitted with (edited by hand),
    leave out what describes the fitted ones: the bootstrap ensemble, the cross-validated error
    band and the fit's standard errors; returns the warning, or None for an unedited file (or
    one written without a fingerprint, by earlier versions or ``ManoeuvringModel.save``)."""
    stated = (doc.get("provenance") or {}).get("model_sha256")
    if not stated or stated == model_fingerprint(doc.get("model")):
        return None
    dropped = []
    if doc.get("uncertainty"):
        doc["uncertainty"] = None
        dropped.append("the bootstrap intervals")
    holder, _, band = _error_band_record(doc)
    if band:
        holder["error_band"] = None
        dropped.append("the cross-validated error band")
    ident = doc.get("identification") or {}
    stats = (ident.get("refinement") or {}).get("statistics") or {}
    diagnostics = [d for d in (ident.get("diagnostics") or {}).values()
                   if isinstance(d, Mapping) and d.get("std_errors")]  # fmt: skip
    if stats.get("standard_errors") or diagnostics:
        stats.pop("standard_errors", None)
        for d in diagnostics:
            d["std_errors"] = None
        dropped.append("the standard errors")
    kept = ("; its kernel residual was fitted to the misses of the coefficients before the edit"
            if (doc.get("kernel_residual") or {}).get("residual") else "")  # fmt: skip
    listed = " and ".join([", ".join(dropped[:-1]), dropped[-1]] if len(dropped) > 1 else dropped)
    return (f"{path}: the model's coefficients are not those it was fitted with (edited?): "
            + (f"{listed} of the fit are left out, as they describe those" if dropped
               else "the file's fit records describe those") + kept)


def prime_record(model: ManoeuvringModel, particulars: dict | None,
                 approach_speed: float | None) -> dict | None:  # fmt: skip
    """The model's coefficients in prime form (``shipid.dynamics.prime``), for the length of the
    particulars and their design speed, else the training approach speed; None without them.
    Written for reading and for transfer to other ships; the dimensional coefficients rule."""
    if not particulars:
        return None
    from shipid.data.particulars import Particulars
    from shipid.dynamics.prime import prime_coefficients

    p = Particulars.from_mapping(particulars)
    speed, basis = p.design_speed, "design speed"
    if speed is None:
        speed, basis = approach_speed, "training approach speed"
    if speed is None or not speed > 0:
        return None
    return {"length": p.length, "speed": speed, "speed_basis": basis, "rho": p.rho,
            "coefficients": prime_coefficients(model, p.length, speed, p.rho)}


def training_files(doc: Mapping) -> dict[str, str]:
    """SHA-256 → path of the files the model was fitted to (``provenance``; {} if not kept)."""
    files = (doc.get("provenance") or {}).get("training_files") or []
    return {str(f["sha256"]): str(f.get("path", "")) for f in files
            if isinstance(f, Mapping) and f.get("sha256")}  # fmt: skip


def model_text(ident: Identification, training_files: Sequence[str | Path] = (), **kw) -> str:
    """The model file's JSON text (``model_document`` serialised; floats exact)."""
    # repr of a float is exact, so the coefficients survive the round trip bit for bit.
    return json.dumps(model_document(ident, training_files, **kw), indent=2,
                      ensure_ascii=False) + "\n"  # fmt: skip


def save_model(path: str | Path, ident: Identification, training_files: Sequence[str | Path] = (),
               preprocessing: dict | None = None, refinement: Refinement | None = None,
               plausibility: dict | None = None,
               model: ManoeuvringModel | None = None,
               residual: KernelResidual | None = None) -> Path:  # fmt: skip
    """Write the model file of an identification atomically (with a kernel residual of its
    model: ``load_model`` then gives the ``HybridModel``). A bare model writes itself:
    ``ManoeuvringModel.save(path)``."""
    if not hasattr(ident, "model") or not hasattr(ident, "diagnostics"):
        # save_model(model, path), as write_log(log, path) reads, failed inside on a 'str'.
        hint = (" (the path comes first: save_model(path, identify(logs)), or model.save(path) "
                "for a bare model)" if isinstance(ident, str | Path) else "")  # fmt: skip
        raise ShipidError(f"save_model: ident must be what identify returns, got "
                          f"{type(ident).__name__}{hint}")  # fmt: skip
    record = None if residual is None else {"residual": residual.to_dict(), "selection": None}
    text = model_text(ident, training_files, preprocessing=preprocessing, refinement=refinement,
                      plausibility=plausibility, model=model, residual=record)  # fmt: skip
    return atomic_write_text(path, text)


# ---------------------------------------------------------------------------- schema
def _type_name(value) -> str:
    return "null" if value is None else type(value).__name__


def _expect(value, kind, key: str, path) -> None:
    ok = {
        "mapping": isinstance(value, Mapping),
        "list": isinstance(value, list),
        "text": isinstance(value, str),
        "number": isinstance(value, int | float) and not isinstance(value, bool),
        "number|null": value is None or (isinstance(value, int | float)
                                         and not isinstance(value, bool)),
        "mapping|null": value is None or isinstance(value, Mapping),
    }[kind]
    if not ok:
        raise ShipidError(f"{path}: {key} must be a {kind.replace('mapping', 'JSON object')}, "
                          f"got {_type_name(value)} {str(value)[:40]!r}")


def _check_model_data(data, key: str, path) -> None:
    _expect(data, "mapping", key, path)
    for k in ("structure", "coefficients"):
        if k not in data:
            raise ShipidError(f"{path}: {key} has no {k!r}")
    structure = data["structure"]
    _expect(structure, "mapping", f"{key}.structure", path)
    _expect(structure.get("name", ""), "text", f"{key}.structure.name", path)
    if "terms" not in structure:
        raise ShipidError(f"{path}: {key}.structure has no 'terms'")
    _expect(structure["terms"], "mapping", f"{key}.structure.terms", path)
    for dof, terms in structure["terms"].items():
        _expect(terms, "list", f"{key}.structure.terms.{dof}", path)
        for i, t in enumerate(terms):
            _expect(t, "text", f"{key}.structure.terms.{dof}[{i}]", path)
    coefs = data["coefficients"]
    _expect(coefs, "mapping", f"{key}.coefficients", path)
    for dof, values in coefs.items():
        _expect(values, "mapping", f"{key}.coefficients.{dof}", path)
        for term, c in values.items():
            where = f"{key}.coefficients.{dof}.{term}"
            _expect(c, "number", where, path)
            if not math.isfinite(c):
                raise ShipidError(f"{path}: {where} is {c}; coefficients must be finite")
    if "name" in data:
        _expect(data["name"], "text", f"{key}.name", path)
    if data.get("similar_at_rps") is not None:
        _expect(data["similar_at_rps"], "number", f"{key}.similar_at_rps", path)
        if not (math.isfinite(data["similar_at_rps"]) and data["similar_at_rps"] > 0):
            raise ShipidError(f"{path}: {key}.similar_at_rps is {data['similar_at_rps']}; it "
                              "must be a positive propeller speed")  # fmt: skip


def check_document(doc, path) -> None:
    """Refuse a model file that does not follow the schema, naming the first bad key."""
    _expect(doc, "mapping", "the file", path)
    _check_model_data(doc.get("model"), "model", path)
    if doc.get("particulars") is not None:
        from shipid.data.particulars import Particulars

        _expect(doc["particulars"], "mapping", "particulars", path)
        Particulars.from_mapping(doc["particulars"], f"{path}: particulars")
    ident = doc.get("identification")
    _expect(ident, "mapping|null", "identification", path)
    if ident:
        prep = ident.get("preprocessing")
        _expect(prep, "mapping|null", "identification.preprocessing", path)
        for k in ("approach_speed", "approach_rps"):
            if prep and k in prep:
                _expect(prep[k], "number|null", f"identification.preprocessing.{k}", path)
        env = ident.get("envelope")
        _expect(env, "mapping|null", "identification.envelope", path)
        for s, bounds in (env or {}).items():
            _expect(bounds, "list", f"identification.envelope.{s}", path)
            for b in bounds:
                _expect(b, "number", f"identification.envelope.{s}", path)
        refinement = ident.get("refinement")
        _expect(refinement, "mapping|null", "identification.refinement", path)
        if refinement:
            _check_model_data(refinement.get("initial_model"),
                              "identification.refinement.initial_model", path)  # fmt: skip


def _no_constants(token: str):
    raise ValueError(f"{token} is not a number JSON allows")


def load_document(path: str | Path) -> dict:
    """The parsed model file, checked against its schema (one-line errors)."""
    path = Path(path)
    if not path.exists():
        raise ShipidError(f"{path}: no such model file")
    if path.is_dir():
        raise ShipidError(f"{path}: is a directory, not a model file")
    from shipid.data.mappings import DuplicateKeyError, duplicate_key_error, load_json

    try:
        text = path.read_text(encoding="utf-8")
        doc = load_json(text, parse_constant=_no_constants)
    except DuplicateKeyError as exc:
        raise duplicate_key_error(path, exc) from None
    except UnicodeDecodeError:
        raise ShipidError(f"{path}: not a JSON model file (not UTF-8 text)") from None
    except (json.JSONDecodeError, ValueError, RecursionError) as exc:
        raise ShipidError(f"{path}: not a JSON model file ({str(exc)[:120]})") from None
    if isinstance(doc, dict) and doc.get("format") == "shipid-corrected-ship":
        raise ShipidError(f"{path}: a reference ship corrected by its logs (shipid correct), not "
                          "an identified model: validate, simulate, manoeuvre, criteria, "
                          "linearise, autopilot and follow run it")  # fmt: skip
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise ShipidError(f"{path}: not a shipid model file (no \"format\": \"{FORMAT}\")")
    if doc.get("version") not in READABLE_VERSIONS:
        raise ShipidError(f"{path}: model file version {doc.get('version')!r} is not supported "
                          f"(this shipid reads versions {', '.join(map(str, READABLE_VERSIONS))})")
    check_document(doc, path)
    stale = stale_fit_records(doc, path)
    if stale and _parses(doc):  # a model that does not parse has its own error, alone
        import warnings

        from shipid.errors import ShipidWarning

        warnings.warn(stale, ShipidWarning, stacklevel=2)
    return doc


def _parses(doc: Mapping) -> bool:
    try:
        _check_every_term(doc["model"], ManoeuvringModel.from_dict(doc["model"]), "")
    except (ShipidError, KeyError, TypeError, ValueError):
        return False
    return True


def load_model(path: str | Path, which: str = "model") -> ManoeuvringModel | HybridModel:
    """The file's model, or with ``which="lssvm"`` the LS-SVM model a refinement started from.
    A model identified with a kernel residual (``identify --residual``) is a ``HybridModel``."""
    return model_from_document(load_document(path), path, which, hybrid=True)


def has_refinement(doc: Mapping) -> bool:
    """Whether the model file keeps an output-error refinement."""
    return bool((doc.get("identification") or {}).get("refinement"))


def _check_every_term(data: Mapping, model: ManoeuvringModel, path: str | Path) -> None:
    """A model file gives a coefficient for every term of its structure (0 where it has none):
    the constructor's zero for a term not given (a convenience of the Python API) made a file
    with its yaw coefficients cut out a ship that never turns, without a word."""
    from shipid.dynamics.terms import parse_term

    given = data.get("coefficients") or {}
    for dof, names in model.structure.terms.items():
        raw = given.get(dof)
        have = {parse_term(k).text for k in raw} if isinstance(raw, Mapping) else set()
        missing = [n for n in names if n not in have]
        if missing:
            raise ShipidError(f"{path}: model.coefficients.{dof} has no value for "
                              f"{', '.join(map(repr, missing))}, a term of its {dof} equation "
                              "(a model file gives every term's coefficient, 0 where it has "
                              "none): a damaged or hand-edited file?")  # fmt: skip


def model_from_document(doc: dict, path: str | Path, which: str = "model",
                        hybrid: bool = False) -> ManoeuvringModel | HybridModel:  # fmt: skip
    """The model (or, with ``which='lssvm'``, the LS-SVM one) of a parsed model file. A file with
    a kernel residual gives a ``HybridModel`` where the caller runs one (``hybrid``); elsewhere
    it is refused, since its term model alone is not the model identified."""
    if which not in ("model", "lssvm"):
        raise ShipidError(f"which must be 'model' or 'lssvm', got {which!r}")
    data = doc.get("model")
    if which == "lssvm" and has_refinement(doc):
        data = doc["identification"]["refinement"]["initial_model"]
    try:
        model = ManoeuvringModel.from_dict(data)
    except ShipidError as exc:
        raise ShipidError(f"{path}: {exc}") from None
    except (KeyError, TypeError, ValueError) as exc:
        raise ShipidError(f"{path}: malformed model ({exc})") from None
    _check_every_term(data, model, path)
    record = doc.get("kernel_residual")
    if record is None:
        return model
    if not isinstance(record, Mapping):
        raise ShipidError(f"{path}: kernel_residual must be a mapping")
    if record.get("residual") is None:
        return model  # the search chose no residual; its record is kept
    if not hybrid:
        raise ShipidError(f"{path}: the model has a kernel residual (identify --residual); this "
                          "command needs a term model: validate, simulate, manoeuvre, "
                          "criteria and export run it, the others take a model identified "
                          "without --residual")  # fmt: skip
    if not isinstance(record["residual"], Mapping):
        raise ShipidError(f"{path}: kernel_residual.residual must be a mapping")
    residual = KernelResidual.from_dict(record["residual"], f"{path}: kernel_residual")
    return HybridModel(model, residual)


def ensemble_from_document(doc: Mapping, path: str | Path, model: ManoeuvringModel):
    """The bootstrap ensemble of a model file (``shipid identify --bootstrap``), or None."""
    data = doc.get("uncertainty")
    if not data:
        return None
    from shipid.identification.uncertainty import Ensemble

    if not isinstance(data, Mapping):
        raise ShipidError(f"{path}: uncertainty must be a mapping")
    return Ensemble.from_dict(data, model, f"{path}: uncertainty")


def alternatives_fit(doc: Mapping) -> str:
    """How the file's tied structures were fitted, in words: LS-SVM fits with the model's
    prefilter, γ and physics, or (files of earlier versions, or a structure that refused the
    refit) the inflow comparison's own fits."""
    choice = (doc.get("identification") or {}).get("structure_choice") or {}
    if isinstance(choice, Mapping) and choice.get("alternatives_fit") == "model":
        return "LS-SVM fits with the model's prefilter and γ"
    return "identify's comparison fits: γ 1e4, unfiltered"


def alternatives_from_document(doc: Mapping, path: str | Path) -> dict[str, ManoeuvringModel]:
    """The structures that tied with the file's in ``identify``'s inflow comparison, LS-SVM fits
    with its model's prefilter, γ and physics (``identification.structure_choice.alternatives``);
    {} for none."""
    choice = (doc.get("identification") or {}).get("structure_choice") or {}
    found = choice.get("alternatives") if isinstance(choice, Mapping) else None
    if not found:
        return {}
    if not isinstance(found, Mapping):
        raise ShipidError(f"{path}: identification.structure_choice.alternatives must be a "
                          "mapping")  # fmt: skip
    return {str(k): model_from_document({"model": v}, f"{path}: structure_choice.alternatives."
                                        f"{k}") for k, v in found.items()}  # fmt: skip


def _error_band_record(doc: Mapping) -> tuple[dict | None, str, object]:
    """(the mapping that holds the band, its key path, the band's raw record): ``select``
    keeps it in its selection record, ``identify --error-band`` beside it."""
    ident = doc.get("identification") or {}
    if not isinstance(ident, Mapping):
        return None, "", None
    selection = ident.get("selection")
    if isinstance(selection, Mapping) and selection.get("error_band"):
        return selection, "identification.selection.error_band", selection["error_band"]
    return ident, "identification.error_band", ident.get("error_band")


def error_band_from_document(doc: Mapping, path: str | Path):
    """The cross-validated error band of a model file (``shipid select``, ``shipid identify
    --error-band``), or None. It describes the file's model: a refined model has not been
    cross-validated, so it has none."""
    _, where, data = _error_band_record(doc)
    if not data or has_refinement(doc):
        return None
    from shipid.evaluation.error_band import ErrorBand

    if not isinstance(data, Mapping):
        raise ShipidError(f"{path}: {where} must be a mapping")
    return ErrorBand.from_dict(data, f"{path}: {where}")


def _lengthened_texts(obj) -> set[str]:
    """The keys and strings of a model file's data that name a term with a length in it (the
    cross-flow drag's, the rudder's normal force's)."""
    if isinstance(obj, Mapping):
        return set().union(*(_lengthened_texts(k) | _lengthened_texts(v) for k, v in obj.items()))
    if isinstance(obj, list):
        return set().union(*(_lengthened_texts(v) for v in obj))
    if not (isinstance(obj, str) and any(name in obj for name in (*CROSSFLOW, RUDDER))):
        return set()
    try:
        term = parse_term(obj)
    except ShipidError:  # a note that names one
        return set()
    return {obj} if term.crossflow or term.rudder else set()


def rescaled_document(doc: Mapping, factor: float, to_rho: float | None = None,
                      path: str | Path = "model file") -> dict:  # fmt: skip
    """The model file of a geometrically similar ship ``factor`` times as long (Froude scaling,
    ``shipid.dynamics.prime``): coefficients (the refinement's and every bootstrap replicate's
    too), particulars, approach speed and rps, rudder rate, Δk and the training envelope, so
    that manoeuvres and criteria run at the new scale. The fit's own records (discrete
    coefficients, diagnostics) stay those of the original scale; ``scaling`` says what was done."""
    import copy

    import numpy as np

    from shipid.data.particulars import Particulars
    from shipid.dynamics.model import DOFS
    from shipid.dynamics.prime import (
        RHO,
        froude_ratios,
        lengthened_terms,
        renamed_terms,
        scaled,
        signal_scale,
    )

    particulars = Particulars.from_mapping(doc["particulars"]) if doc.get("particulars") else None
    rho = particulars.rho if particulars is not None else RHO
    to_rho = rho if to_rho is None else to_rho
    model = model_from_document(dict(doc), path)
    ratios = froude_ratios(model.structure, factor, rho, to_rho)
    k = math.sqrt(factor)
    out = copy.deepcopy(dict(doc))

    def scale_model(data: dict) -> dict:
        return scaled(model_from_document({"model": data}, path), ratios, 1 / k).to_dict()

    out["model"] = scale_model(doc["model"])
    ident = out.get("identification") or {}
    refinement = ident.get("refinement")
    if refinement:
        for key in ("initial_model", "refined_model"):
            if refinement.get(key):
                refinement[key] = scale_model(refinement[key])
        if refinement.get("statistics"):
            _scale_statistics(refinement["statistics"], ratios, factor, rho, to_rho)
    band = error_band_from_document(doc, path)
    if band is not None:  # in m/s and rad/s: a Froude-similar ship's speeds are k times these
        holder, _, _ = _error_band_record(out)
        holder["error_band"] = band.scaled(k).to_dict()
    chosen = ((ident.get("selection") or {}) if isinstance(ident, Mapping) else {}).get(
        "chosen_model")
    if chosen:  # select --average keeps the chosen candidate beside the averaged model
        sparse = model_from_document({"model": chosen}, path)
        out["identification"]["selection"]["chosen_model"] = scaled(
            sparse, froude_ratios(sparse.structure, factor, rho, to_rho), 1 / k).to_dict()
    for key, alt in alternatives_from_document(doc, path).items():  # the tied structures' fits
        out["identification"]["structure_choice"]["alternatives"][key] = scaled(
            alt, froude_ratios(alt.structure, factor, rho, to_rho), 1 / k).to_dict()
    if out.get("uncertainty"):
        unc = out["uncertainty"]
        # The members' structure: the model's, or a superset of it (select --bootstrap).
        members = ensemble_from_document(doc, path, model).structure
        member_ratios = froude_ratios(members, factor, rho, to_rho)
        thetas = np.asarray(unc["thetas"], dtype=float)
        for dof, terms in members.terms.items():
            for t in terms:
                thetas[:, DOFS.index(dof), unc["terms"].index(t)] *= member_ratios[dof][t]
        unc["thetas"] = thetas.tolist()
    if particulars is not None:
        p = dict(out["particulars"])
        for key, power in (("length", 1), ("beam", 1), ("draught", 1), ("propeller_diameter", 1),
                           ("xg", 1), ("rudder_area", 2), ("rudder_height", 1),
                           ("design_speed", 0.5)):  # fmt: skip
            if p.get(key) is not None:
                p[key] = p[key] * factor**power
        if p.get("mass") is not None:
            p["mass"] = p["mass"] * factor**3 * to_rho / rho
        if p.get("scale") is not None:
            p["scale"] = p["scale"] / factor
        p["rho"] = to_rho
        out["particulars"] = p
    prep = ident.get("preprocessing") or {}
    for key, scale in (("approach_speed", k), ("approach_rps", 1 / k), ("rudder_rate", 1 / k),
                       ("dt", k), ("log_scale", 1 / factor)):  # fmt: skip
        if isinstance(prep.get(key), int | float):
            prep[key] = prep[key] * scale
    if isinstance(ident.get("dt"), int | float):
        ident["dt"] = ident["dt"] * k
    if isinstance((ident.get("rps_similarity") or {}).get("rps"), int | float):
        ident["rps_similarity"]["rps"] = ident["rps_similarity"]["rps"] / k
    # The LS-SVM fit's standard errors are printed beside the coefficients: they scale with
    # them (a rescaled model's report printed ṙ's u·v as 0.0054 ± 0.0009, the error of 0.54).
    from shipid.dynamics.prime import prime_factor

    for dof, diag in (ident.get("diagnostics") or {}).items():
        errors = diag.get("std_errors") if isinstance(diag, Mapping) else None
        for t, se in (errors or {}).items():
            if isinstance(se, int | float):
                errors[t] = se * abs(prime_factor(dof, t, 1.0, 1.0, rho)
                                     / prime_factor(dof, t, factor, k, to_rho))  # fmt: skip
    envelope = ident.get("envelope") or {}
    for signal, bounds in envelope.items():
        scale = signal_scale(signal, factor, rho, to_rho)
        envelope[signal] = [b * scale for b in bounds]
    # The cross-flow terms' argument is the hull's length, the rudder's normal force's inflow has
    # the propeller's and the rudder's: every record of them takes the new.
    renamed = lengthened_terms(_lengthened_texts(out), factor)
    if renamed:
        out = renamed_terms(out, renamed)
    model_out = model_from_document(out, path)
    out["prime"] = prime_record(model_out, out.get("particulars"), prep.get("approach_speed"))
    out.setdefault("scaling", []).append({
        "method": "Froude: equal prime coefficients at equal Froude number",
        "factor": factor, "rho": [rho, to_rho],
        "note": "viscous (Reynolds) effects are not scaled; identification.discrete and "
                "diagnostics (but their standard errors) are those of the fit at the original "
                "scale"})  # fmt: skip
    return _fingerprinted(out)


def rps_similar_document(doc: Mapping, rps: float, path: str | Path = "model file") -> dict:
    """The model file of a fit to logs at the one propeller speed ``rps`` with its model carried
    to every other by advance-ratio similarity (``shipid.dynamics.similarity``): the model, the
    refinement's, the tied structures' and the chosen candidate's, every bootstrap replicate,
    the standard errors, covariances, priors and bounds, their terms renamed and coefficients
    scaled as one. The LS-SVM's own record (``identification.discrete``) stays the fit's;
    ``identification.rps_similarity`` says what was done. None where no term gains a factor of
    n, or the bootstrap replicates' terms would merge."""
    from shipid.dynamics.similarity import rps_similar, similar_term, similarity_map

    found = similarity_map(model_from_document(dict(doc), path).structure, rps)

    def alone(dof: str, term: str) -> tuple[str, float]:
        new, k = similar_term(term)
        return new, rps**-k

    return _renamed_document(doc, path, found, alone, lambda m: rps_similar(m, rps), (
        "rps_similarity", {
            "rps": float(rps), "terms": found.describe(),
            "note": "logs at one propeller speed cannot show how a force depends on it; each "
                    "term is written to scale with it as advance-ratio similarity has it, so "
                    "the model is the fit at this rps and scales to others; "
                    "identification.discrete is the fit's"}))  # fmt: skip


def ahead_forms_document(doc: Mapping, path: str | Path = "model file", forms=None
                         ) -> dict | None:  # fmt: skip
    """The model file of a fit to logs that never go astern with its terms written in the form
    that carries them astern (``shipid.dynamics.astern``: u·v → |u|·v in v̇, ...; ``forms``, an
    ``AsternForms``, by default those alone), renamed throughout as ``rps_similar_document``
    renames; ``identification.ahead_forms`` says what was done. None where no term changes, or
    the bootstrap replicates' terms would merge."""
    from shipid.dynamics.astern import AsternForms

    model = model_from_document(dict(doc), path)
    forms = AsternForms(hull=True) if forms is None else forms.for_model(model)
    found = forms.renaming(model.structure)
    hull, thrust = forms.parts(model.structure)
    notes = []
    if hull:
        notes.append("the logs never go astern, where these forms and the fitted ones agree; "
                     "written in the forms whose astern extension is the physics (damping "
                     "damps, the rudder's lift reverses with the flow)")  # fmt: skip
    if thrust:
        notes.append("the logs never reverse the propeller: its thrust is written "
                     "propeller(k), n² ahead and −k·n² astern, k a prior "
                     "(shipid.dynamics.propeller.ASTERN_THRUST_RATIO, or --astern-thrust)")
    record = {"terms": found.describe(), "note": "; ".join(notes) + ": the same fit ahead"}
    if thrust:
        record["astern_thrust_ratio"] = float(forms.thrust_ratio)
    return _renamed_document(doc, path, found, lambda dof, term: (forms.form(dof, term), 1.0),
                             forms.written, ("ahead_forms", record))


def _renamed_document(doc: Mapping, path, found, alone, carried, record: tuple[str, dict]
                      ) -> dict | None:  # fmt: skip
    """``doc`` with every model and statistic of it renamed by ``found`` (its ``renamed``
    {dof: {term: (new term, ratio)}} and ``changes``; ``alone(dof, term)`` for terms of other
    structures, ``carried(model)`` the model so renamed), ``record`` = (key, value) added to
    its identification; None where nothing changes or replicates' terms would merge."""
    import copy

    import numpy as np

    from shipid.dynamics.model import DOFS
    from shipid.dynamics.terms import parse_term

    if not found.changes:
        return None
    out = copy.deepcopy(dict(doc))

    def convert(data: Mapping) -> dict:
        return carried(model_from_document({"model": data}, path)).to_dict()

    def rename(dof: str, term: str) -> tuple[str, float]:
        """(new term, ratio) of a term of the model's ``dof`` equation (of another
        structure's: as it is renamed alone)."""
        given = found.renamed.get(dof, {}).get(parse_term(term).text)
        return given if given is not None else alone(dof, term)

    def mapped(values: Mapping, dof: str) -> dict:
        """{term: value} of equation ``dof`` renamed, each value (or pair) times its ratio;
        None (a bound's open side) stays None."""

        def times(x, ratio):
            return None if x is None else x * ratio

        res = {}
        for t, v in values.items():
            new, ratio = rename(dof, t)
            res[new] = [times(b, ratio) for b in v] if isinstance(v, list) else times(v, ratio)
        return res

    out["model"] = convert(doc["model"])
    unc = out.get("uncertainty")
    if unc:
        # Each replicate's row of each equation, renamed as that equation's terms are.
        thetas = np.asarray(unc["thetas"], dtype=float)
        names = [[rename(dof, t) for t in unc["terms"]] for dof in DOFS]
        columns = list(dict.fromkeys(n for row in names for n, _ in row))
        moved = np.zeros((thetas.shape[0], 3, len(columns)))
        for i, row in enumerate(names):
            targets = [columns.index(n) for n, _ in row]
            live = [j for j in range(len(row)) if np.any(thetas[:, i, j] != 0)]
            if len({targets[j] for j in live}) < len(live):
                return None  # two of a replicate's terms would become one
            for j in live:
                moved[:, i, targets[j]] = thetas[:, i, j] * row[j][1]
        if unc.get("structure"):
            unc["structure"] = {d: [rename(d, t)[0] for t in ts]
                                for d, ts in unc["structure"].items()}  # fmt: skip
        # In the order the ensemble's structure (else the model's) lists its terms, as a model
        # file has it.
        owner = unc.get("structure") or out["model"]["structure"]["terms"]
        order = list(ModelStructure("ensemble", {d: tuple(ts) for d, ts in owner.items()}
                                    ).all_terms)  # fmt: skip
        # (A term renamed in one equation is still named as it was in the others, where it
        # is 0 in every replicate: such a column goes.)
        spare = [c for c in columns if c not in order and not np.any(moved[:, :, columns.index(c)])]
        if set(order) != set(columns) - set(spare):
            return None  # the replicates would not fit the structure: the file as fitted
        unc["thetas"] = moved[:, :, [columns.index(t) for t in order]].tolist()
        unc["terms"] = order
    ident = out.get("identification") or {}
    refinement = ident.get("refinement")
    if refinement:
        for key in ("initial_model", "refined_model"):
            if refinement.get(key):
                refinement[key] = convert(refinement[key])
        stats = refinement.get("statistics") or {}
        for key in ("standard_errors", "bounds"):
            if stats.get(key):
                stats[key] = {d: mapped(v, d) for d, v in stats[key].items()}
        cov = stats.get("covariance")
        if cov:
            pairs = [rename(d, t) for d, t in cov["terms"]]
            cov["matrix"] = [[c * pairs[i][1] * pairs[j][1] for j, c in enumerate(row)]
                             for i, row in enumerate(cov["matrix"])]  # fmt: skip
            cov["terms"] = [[d, p[0]] for (d, _), p in zip(cov["terms"], pairs, strict=True)]
        if stats.get("at_bound"):
            stats["at_bound"] = [[d, rename(d, t)[0]] for d, t in stats["at_bound"]]
    chosen = (ident.get("selection") or {}).get("chosen_model")
    if chosen:
        ident["selection"]["chosen_model"] = convert(chosen)
    for key, alt in ((ident.get("structure_choice") or {}).get("alternatives") or {}).items():
        ident["structure_choice"]["alternatives"][key] = convert(alt)
    for dof, diag in (ident.get("diagnostics") or {}).items():
        if not isinstance(diag, dict):
            continue
        if diag.get("std_errors"):
            diag["std_errors"] = mapped(diag["std_errors"], dof)
        for pair in diag.get("most_collinear") or []:
            pair["terms"] = [rename(dof, t)[0] for t in pair["terms"]]
        for key in ("constant_terms", "at_bound"):
            if diag.get(key):
                diag[key] = [rename(dof, t)[0] for t in diag[key]]
    physics = ident.get("physics")
    if physics:
        for key in ("prior", "bounds"):
            if physics.get(key):
                physics[key] = {d: mapped(v, d) for d, v in physics[key].items()}
    model_out = model_from_document(out, path)
    out["prime"] = prime_record(model_out, out.get("particulars"),
                                (ident.get("preprocessing") or {}).get("approach_speed"))
    if out.get("identification") is None:
        out["identification"] = ident
    ident[record[0]] = record[1]
    return _fingerprinted(out)


def _scale_statistics(stats: dict, ratios: Mapping, factor: float, rho: float, to_rho: float
                      ) -> None:  # fmt: skip
    """An output-error fit's statistics at the new scale: standard errors and covariance scale
    with their coefficients, the noise and initial states with their signals."""
    from shipid.dynamics.prime import signal_scale

    for dof, terms in stats.get("standard_errors", {}).items():
        for t in terms:
            terms[t] = terms[t] * abs(ratios[dof][t])
    cov = stats.get("covariance")
    if cov:
        r = [ratios[d][t] for d, t in cov["terms"]]
        cov["matrix"] = [[c * r[i] * r[j] for j, c in enumerate(row)]
                         for i, row in enumerate(cov["matrix"])]  # fmt: skip
    for s in list(stats.get("noise", {})):
        stats["noise"][s] *= signal_scale(s, factor, rho, to_rho)
    for x0 in stats.get("initial_states", []):
        for s in ("u", "v", "r"):
            if s in x0:
                x0[s] *= signal_scale(s, factor, rho, to_rho)


def time_scale(doc: Mapping) -> float:
    """How much slower the model file's ship lives than the one it was identified as: √λ for
    every Froude rescaling by λ it went through (``rescaled_document``), 1 for none. A model's
    judgements in seconds (is its approach steady over 10 s?) are made over so many times as
    long, so that the rescaled model runs the same manoeuvres as its original (the one-file Esso
    model carried to 300 m judged its approach over 10 s, a tenth of its original's window, and
    started its 35° turn from another speed: tactical diameter 960 m against the original's
    8.53 m × 100)."""
    out = 1.0
    for record in doc.get("scaling") or ():
        factor = record.get("factor") if isinstance(record, Mapping) else None
        if isinstance(factor, int | float) and math.isfinite(factor) and factor > 0:
            out *= math.sqrt(factor)
    return out


def training_conditions(doc: Mapping) -> dict:
    """Approach speed, propeller speed and envelope of a model file's training logs."""
    ident = doc.get("identification") or {}
    prep = ident.get("preprocessing") or {}
    out = {"speed": prep.get("approach_speed"), "rps": prep.get("approach_rps"),
           "envelope": ident.get("envelope") or {}, "particulars": None,
           "rudder_rate": prep.get("rudder_rate"),
           "rudder_unresolved": bool(prep.get("rudder_unresolved")),
           "log_scale": prep.get("log_scale"),
           "rudder_positive": prep.get("rudder_positive"),
           "yaw_rate_offset_deg_s": prep.get("yaw_rate_offset_deg_s"),
           "dt": ident.get("dt") if isinstance(ident.get("dt"), int | float) else None,
           "time_scale": time_scale(doc), "ship": prep.get("ship"),
           "manoeuvres": prep.get("manoeuvres")}  # fmt: skip
    if doc.get("particulars"):
        from shipid.data.particulars import Particulars

        out["particulars"] = Particulars.from_mapping(doc["particulars"])
    return out
