"""The public API: what ``shipid`` exports, docstrings on every public item, round trips."""

import importlib
import inspect
import pkgutil

import numpy as np
import pytest

import shipid


def test_the_documented_names_import_from_shipid():
    from shipid import (  # noqa: F401
        LSSVR,
        identify,
        load_model,
        pull_out,
        read_log,
        save_model,
        turning_circle,
        validate,
        zigzag,
    )

    assert set(shipid.__all__) >= {"read_log", "identify", "validate", "load_model", "save_model",
                                   "zigzag", "turning_circle", "pull_out", "LSSVR", "select",
                                   "imo_criteria"}  # fmt: skip
    with pytest.raises(AttributeError):
        shipid.no_such_thing  # noqa: B018


def _public_items():
    for m in pkgutil.walk_packages(shipid.__path__, "shipid."):
        mod = importlib.import_module(m.name)
        yield m.name, mod
        for name, obj in vars(mod).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != mod.__name__:
                continue
            if inspect.isfunction(obj) or inspect.isclass(obj):
                yield f"{m.name}.{name}", obj
                if inspect.isclass(obj):
                    for attr, member in vars(obj).items():
                        f = member.fget if isinstance(member, property) else member
                        if not attr.startswith("_") and inspect.isfunction(f):
                            yield f"{m.name}.{name}.{attr}", f


def test_every_public_item_has_a_docstring():
    missing = [name for name, obj in _public_items()
               if not (obj.__doc__ or "").strip()]  # fmt: skip
    assert missing == []


def test_model_save_load_and_validation_frame(tmp_path):
    from shipid import load_model, validate, zigzag
    from shipid.vessels import scale_ship, scale_ship_model

    m = scale_ship_model()
    path = m.save(tmp_path / "m.json", particulars={"length": 4.389})
    back = load_model(path)
    assert back.coefficients == m.coefficients
    log = zigzag(scale_ship(), 20, 20, duration=30, dt=0.2, method="euler").log
    frame = validate(back, log)[0].to_frame()
    assert list(frame.index) == ["u", "v", "r"]
    assert {"rmse", "fit_percent", "mean", "std"} <= set(frame.columns)
    assert np.allclose(frame["rmse"], 0.0, atol=1e-6)  # the truth predicts itself


def test_the_cli_knows_every_reader():
    from shipid.cli import FORMATS as CLI_FORMATS
    from shipid.data.formats import FORMATS

    assert CLI_FORMATS == FORMATS


def test_the_cli_knows_every_linear_estimator():
    from shipid.cli.parser import LINEAR_ESTIMATORS as CLI_ESTIMATORS
    from shipid.identification.estimators import LINEAR_ESTIMATORS

    assert CLI_ESTIMATORS == LINEAR_ESTIMATORS


@pytest.fixture(scope="module")
def short_trial():
    from shipid.trials.manoeuvres import zigzag
    from shipid.vessels import scale_ship

    log = zigzag(scale_ship(), 20, 20, duration=40, dt=0.2, method="euler").log
    log.attrs["name"] = "zz.csv"
    return log


@pytest.mark.parametrize(("call", "column"), [
    ("identify", "v"), ("identify", "delta"), ("select", "r"), ("simulate_log", "delta"),
    ("manoeuvre_indices", "r"), ("validate", "u"), ("refine", "delta"), ("output_error", "t"),
])  # fmt: skip
def test_a_dataframe_without_a_column_is_named(short_trial, call, column):
    """The command line's reader checks its files; a DataFrame handed to these functions
    without a column raised a KeyError from deep inside. Now one line names the log and it."""
    from shipid.dynamics.simulate import simulate_log
    from shipid.errors import ShipidError
    from shipid.identification.output_error import output_error
    from shipid.trials.indices import manoeuvre_indices
    from shipid.vessels.scale_ship import scale_ship_model

    log = short_trial.drop(columns=[column])
    model = scale_ship_model()
    calls = {"identify": lambda: shipid.identify(log),
             "select": lambda: shipid.select([short_trial, log]),
             "simulate_log": lambda: simulate_log(model, log),
             "manoeuvre_indices": lambda: manoeuvre_indices(log),
             "refine": lambda: shipid.refine(model, log),
             "output_error": lambda: output_error(model, log)}  # fmt: skip
    if call == "validate":  # a log that cannot be validated gets its error, the others go on
        (res,) = shipid.validate(model, log)
        assert res.error.startswith(f"zz.csv: missing column(s) {column} (")
        return
    with pytest.raises(ShipidError, match=rf"^zz\.csv: missing column\(s\) {column} \("):
        calls[call]()


@pytest.mark.parametrize("call", ["identify", "select", "validate", "simulate_log", "lowpass",
                                  "resample", "manoeuvre_indices", "trim", "output_error",
                                  "choose_prefilter", "auto_structure", "refine"])  # fmt: skip
def test_a_path_where_a_log_belongs_is_named(short_trial, call):
    """A file's path handed where a log (a DataFrame) belongs raised AttributeError ('str'
    object has no attribute 'columns' or 'attrs') or TypeError ('string indices must be
    integers') from deep inside."""
    from shipid.errors import ShipidError
    from shipid.vessels.scale_ship import scale_ship_model

    model = scale_ship_model()
    calls = {"identify": lambda p: shipid.identify(p), "select": lambda p: shipid.select(p),
             "validate": lambda p: shipid.validate(model, p),
             "simulate_log": lambda p: shipid.simulate_log(model, p),
             "lowpass": lambda p: shipid.lowpass(p, 0.5), "resample": lambda p: shipid.resample(p, 0.5),
             "manoeuvre_indices": lambda p: shipid.manoeuvre_indices(p),
             "trim": lambda p: shipid.trim(p, start="auto"),
             "output_error": lambda p: shipid.output_error(model, p),
             "choose_prefilter": lambda p: shipid.choose_prefilter(p, lambda logs: model),
             "auto_structure": lambda p: shipid.auto_structure(p),
             "refine": lambda p: shipid.refine(model, p)}  # fmt: skip
    one = call in ("simulate_log", "lowpass", "resample", "manoeuvre_indices", "trim")
    for given in ("zz.csv",) if one else ("zz.csv", ["zz.csv"]):
        said = r"is a pandas DataFrame \(shipid\.read_log reads a file into one\), got the path"
        with pytest.raises(ShipidError, match=said + r" 'zz\.csv'$"):
            calls[call](given)
    if one:  # a list of logs where one log belongs
        with pytest.raises(ShipidError, match=r"^a log is a pandas DataFrame .*, got a list$"):
            calls[call]([short_trial])


@pytest.mark.parametrize("call", ["validate", "simulate_log", "simulate", "output_error",
                                  "refine", "turning_circle", "zigzag"])  # fmt: skip
def test_a_path_or_a_name_where_a_model_belongs_is_named(short_trial, call):
    """validate('m.json', logs) raised "'str' object has no attribute 'uses_thrust'",
    output_error and refine the same of 'structure', the manoeuvres a TypeError: which function
    reads a model file or a reference ship by name was left to guess."""
    from shipid.errors import ShipidError

    calls = {"validate": lambda m: shipid.validate(m, short_trial),
             "simulate_log": lambda m: shipid.simulate_log(m, short_trial),
             "simulate": lambda m: shipid.simulate(m, [0.0, 0.1], [0.0, 0.0], {"u": 1.0}),
             "output_error": lambda m: shipid.output_error(m, short_trial),
             "refine": lambda m: shipid.refine(m, short_trial),
             "turning_circle": lambda m: shipid.turning_circle(m, 35),
             "zigzag": lambda m: shipid.zigzag(m, 20, 20)}  # fmt: skip
    for given in ("m.json", "kvlcc2"):
        with pytest.raises(ShipidError, match=r"is a ManoeuvringModel, a HybridModel or a "
                                              r"reference ship \(shipid\.load_model reads a model "
                                              rf"file, shipid\.get_vessel a reference ship by "
                                              rf"name\), got '{given}'$"):  # fmt: skip
            calls[call](given)


def test_a_function_is_asked_for_where_one_is_given_something_else(short_trial):
    """A structure or a model given where the fit function is asked for failed with "'X' object
    is not callable" from inside; trim's 'auto' without the rudder with a KeyError."""
    from shipid.dynamics.model import get_structure
    from shipid.errors import ShipidError

    for call in (lambda: shipid.choose_prefilter([short_trial], get_structure("blanke")),
                 lambda: shipid.bootstrap([short_trial], get_structure("blanke")),
                 lambda: shipid.choose_residual(shipid.identify(short_trial).model,
                                                [short_trial])):  # fmt: skip
        with pytest.raises(ShipidError, match=r"^\w+: fit must be a function, e\.g\. "):
            call()
    with pytest.raises(ShipidError, match=r"missing column\(s\) delta \('auto' finds"):
        shipid.trim(short_trial.drop(columns=["delta"]), start="auto")
    cutoff, table = shipid.choose_prefilter(short_trial, lambda logs: shipid.identify(logs).model,
                                            cutoffs=[0.5])  # a single log, as identify takes
    assert len(table) == 2 and cutoff in (None, 0.5)


def test_save_model_says_what_it_writes(short_trial, tmp_path):
    """save_model(model, path), in write_log's order, failed inside on a 'str'; a bare model
    given for the identification likewise."""
    from shipid.errors import ShipidError

    fit = shipid.identify(short_trial)
    with pytest.raises(ShipidError, match=r"got \w*Path \(the path comes first"):
        shipid.save_model(fit.model, tmp_path / "a.json")
    with pytest.raises(ShipidError, match="ident must be what identify returns, got Manoeuvring"):
        shipid.save_model(tmp_path / "b.json", fit.model)
    assert shipid.save_model(tmp_path / "c.json", fit).exists()
    assert not (tmp_path / "a.json").exists() and not (tmp_path / "b.json").exists()
