"""A propeller's thrust at a ratio astern (``propeller(k)``; ``shipid.dynamics.astern``): models
of logs that never reverse the propeller are written with it, the same fit wherever n ≥ 0, and
every path that runs a model (NumPy, the compiled kernel, the generated loop, the exported
module) computes it as its closed form, n² ahead and −k·n² astern."""

import contextlib
import importlib.util
import io
import json

import numpy as np
import pytest

from shipid.data.io import write_log
from shipid.dynamics import codegen
from shipid.dynamics.astern import AsternForms, logs_never_reverse
from shipid.dynamics.equilibrium import astern_braking
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.propeller import ASTERN_THRUST_RATIO
from shipid.dynamics.simulate import simulate
from shipid.dynamics.terms import parse_term
from shipid.trials.manoeuvres import astern_thrust_note, stopping, zigzag
from shipid.vessels import PAPER_IMU, scale_ship

N0 = 12.0  # rps, logged constant


def run(argv) -> tuple[int, str, str]:
    from shipid.cli import main

    with contextlib.redirect_stdout(io.StringIO()) as out, \
            contextlib.redirect_stderr(io.StringIO()) as err:  # fmt: skip
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def surge_model(ratio: float | None) -> ManoeuvringModel:
    """A surge of resistance and thrust (pos(n)², or propeller(ratio)); sway and yaw damped."""
    thrust = "pos(n)^2" if ratio is None else f"propeller({ratio:g})"
    return ManoeuvringModel(
        f"u: |u|u, {thrust}; v: u*v, u*r, delta; r: u*v, u*r, delta",
        {"u": {"|u|u": -0.05, thrust: 2e-3}, "v": {"u*v": -0.5, "u*r": -0.4, "delta": 0.05},
         "r": {"u*v": -0.6, "u*r": -1.1, "delta": -0.5}})  # fmt: skip


@pytest.mark.parametrize("ratio", [0.0, 0.5, 1.3])
def test_the_factor_is_its_closed_form(ratio):
    term = parse_term(f"propeller({ratio:g})")
    assert term.text == f"propeller({ratio:g})" and term.degree_in("n") == 2
    n = np.array([-3.0, -0.5, 0.0, 0.5, 3.0])
    want = np.where(n >= 0, n**2, -ratio * n**2)
    np.testing.assert_array_equal(term.factors[0].values(n), want)


@pytest.mark.parametrize("text", ["propeller(-0.5)", "propeller(0.5)^2", "propeller()",
                                  "propeller(0.5 1)"])  # fmt: skip
def test_a_bad_ratio_is_named(text):
    from shipid.errors import ShipidError

    with pytest.raises(ShipidError, match=r"propeller\(k\)"):
        parse_term(text)


def _reversing_run(model, engine: str):
    t = np.arange(0, 120, 0.1)
    n = 10 * np.cos(t / 15)  # ahead, astern, ahead
    delta = 0.2 * np.sign(np.sin(t / 10))
    with codegen.use(engine):
        log = simulate(model, t, delta, {"u": 1.0}, rps=n, method="rk4").log
    return log[["u", "v", "r", "psi"]].to_numpy()


def test_the_compiled_run_is_the_closed_form():
    """A free run through a reversal, in the compiled kernel, against the same model with the
    thrust written pos(n)² − k·neg(n)², two terms the kernel already had."""
    model = surge_model(0.6)
    split = ManoeuvringModel(
        "u: |u|u, pos(n)^2, neg(n)^2; v: u*v, u*r, delta; r: u*v, u*r, delta",
        {"u": {"|u|u": -0.05, "pos(n)^2": 2e-3, "neg(n)^2": -0.6 * 2e-3},
         "v": model.coefficients["v"], "r": model.coefficients["r"]})  # fmt: skip
    a, b = _reversing_run(model, "interpreted"), _reversing_run(split, "interpreted")
    assert a[:, 0].min() < 0 < a[:, 0].max()  # it went astern and ahead again
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)


def test_the_generated_loop_is_the_interpreters(tmp_path, monkeypatch):
    monkeypatch.setenv("SHIPID_CACHE_DIR", str(tmp_path))  # compiled here, not in the user's cache
    model = surge_model(0.6)
    np.testing.assert_allclose(_reversing_run(model, "generated"),
                               _reversing_run(model, "interpreted"), rtol=1e-12, atol=1e-12)
    _no_cached_kernel_took_a_compiled_function(codegen.load(model.code,
                                                            codegen.nonzero_pairs(model.code,
                                                                                  model.theta)))


def _no_cached_kernel_took_a_compiled_function(generated):
    """The generated module was compiled in this process (a new folder), and with it the shared
    loops it calls with its rhs. numba keys a cached entry by its arguments' types, and a compiled
    function's type by its dispatcher, new in every process: a cached loop taking one gained an
    index entry in every process that compiled a term set, and once the index held more than the
    128 dispatchers numba keeps alive, saving it failed ("underlying object has vanished")."""
    from numba.core import types
    from numba.core.caching import NullCache

    from shipid.dynamics import kernel

    compiled = 0
    for module in (kernel, generated):
        for name, obj in vars(module).items():
            if not hasattr(obj, "signatures") or isinstance(getattr(obj, "_cache", None), NullCache):
                continue
            for sig in obj.signatures:
                compiled += 1
                assert not any(isinstance(a, types.Dispatcher) for a in sig), name
    assert compiled  # the generated kernel's own entries were seen


def test_the_exported_module_runs_it(tmp_path):
    from shipid.control.export import export_numpy

    model = surge_model(0.4)
    t = np.arange(0, 60, 0.1)
    n, delta = 8 * np.cos(t / 8), 0.1 * np.sign(np.sin(t / 6))
    ref = simulate(model, t, delta, {"u": 1.0}, rps=n, method="rk4").log[
        ["u", "v", "r", "psi", "x", "y"]].to_numpy()  # fmt: skip
    path = export_numpy(model, tmp_path / "exported.py")
    spec = importlib.util.spec_from_file_location("exported", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    got = mod.simulate(t, np.column_stack([delta, n]), [1.0, 0, 0, 0, 0, 0], "rk4")
    np.testing.assert_allclose(got, ref, atol=1e-9, rtol=0)


@pytest.mark.parametrize("thrust", ["pos(n)^2", "|n|*n"])
def test_written_the_same_ahead_and_k_times_the_push_astern(thrust):
    fitted = ManoeuvringModel(f"u: |u|u, {thrust}, pos(n)^2*delta^2; v: u*v, pos(n)^2; r: u*r",
                              {"u": {"|u|u": -0.05, thrust: 2e-3, "pos(n)^2*delta^2": -1e-3},
                               "v": {"u*v": -0.5, "pos(n)^2": 1e-4},
                               "r": {"u*r": -1.0}})  # fmt: skip
    written = AsternForms(thrust_ratio=0.5).written(fitted)
    # Only the surge's thrust: the rudder's drag in the race and the sway's side force stay.
    assert written.structure.terms["u"] == ("|u|*u", "propeller(0.5)", "pos(n)^2*delta^2")
    assert written.structure.terms["v"] == fitted.structure.terms["v"]
    rng = np.random.default_rng(0)
    s = {"u": rng.uniform(0.1, 2, 200), "v": rng.normal(0, 0.2, 200),
         "r": rng.normal(0, 0.1, 200), "delta": rng.uniform(-0.6, 0.6, 200)}  # fmt: skip
    ahead = rng.uniform(0, 15, 200)
    np.testing.assert_allclose(written.accelerations(**s, rps=ahead),
                               fitted.accelerations(**s, rps=ahead), rtol=1e-13, atol=1e-17)
    found = astern_braking(written, 1.0, 10.0)
    assert found["braking"] == pytest.approx(-0.5 * found["ahead"], rel=1e-12)


def test_a_negative_thrust_is_left_as_fitted():
    """A fitted pos(n)² < 0 is no thrust (the fit carried it elsewhere): at a ratio astern it
    would push the ship ahead when reversed."""
    fitted = surge_model(None)
    negative = ManoeuvringModel(fitted.structure, {**fitted.coefficients,
                                                   "u": {"|u|u": -0.05, "pos(n)^2": -2e-4}})
    assert AsternForms(True, 0.5).written(negative).structure.terms["u"] == ("|u|*u", "pos(n)^2")
    assert AsternForms(True, 0.5).written(fitted).structure.terms["u"] == ("|u|*u",
                                                                           "propeller(0.5)")


def test_a_surge_with_both_thrust_forms_is_left_as_fitted():
    """pos(n)² and |n|·n side by side (a ``select --average`` of candidates with either) are
    one term ahead: the first written propeller(k) beside the second as fitted braked astern
    at k·a + b of a + b, neither the ratio nor the fit's. Both stay as fitted, and the model
    brakes astern as fitted (−b n²)."""
    both = ManoeuvringModel("u: |u|u, pos(n)^2, |n|*n; v: u*v; r: u*r",
                            {"u": {"|u|u": -0.05, "pos(n)^2": 1.5e-3, "|n|*n": 0.5e-3},
                             "v": {"u*v": -0.5}, "r": {"u*r": -1.0}})  # fmt: skip
    forms = AsternForms(True, 0.5)
    assert forms.for_model(both) == AsternForms(True, None)
    written = forms.written(both)
    assert written.structure.terms["u"] == ("|u|*u", "pos(n)^2", "|n|*n")
    assert astern_braking(written, 1.0, 10.0)["braking"] == pytest.approx(-0.5e-3 * 100)


def test_logs_that_reverse_the_propeller_are_left_as_fitted():
    import pandas as pd

    ahead = pd.DataFrame({"n": [0.0, 5.0, 10.0]})
    assert logs_never_reverse([ahead, ahead])
    assert not logs_never_reverse([ahead, pd.DataFrame({"n": [5.0, -1.0]})])
    assert not logs_never_reverse([pd.DataFrame({"u": [1.0]})])  # no rps: nothing to write
    assert not logs_never_reverse([])


def test_the_crash_stop_note_names_the_ratio():
    note = astern_thrust_note(surge_model(0.5), 1.0, 10.0)
    assert note.kind == "ratio" and "brakes astern at 50 % of its ahead push" in note.note
    coasting = astern_thrust_note(surge_model(None), 1.0, 10.0)
    assert coasting.kind == "coasting" and "none of its propeller terms acts with n < 0" in \
        coasting.note  # fmt: skip
    # A crash stop stops, later than with the thrust mirrored astern whole.
    kw = {"speed": 1.0, "duration": 600, "dt": 0.5}
    half, whole = (stopping(surge_model(k), 10.0, **kw).indices["time_to_stop"] for k in (0.5, 1))
    assert np.isfinite(half) and half > whole > 0


@pytest.fixture(scope="module")
def one_rps_files(tmp_path_factory):
    """The paper's ship's noisy 20/20 zig-zag at a constant 12 rps, identified as the default
    writes it, at another ratio, and as fitted."""
    folder = tmp_path_factory.mktemp("astern_thrust")
    log = PAPER_IMU.apply(zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=90, dt=0.2,
                                 method="euler", approach=2.0).log, seed=5).assign(n=N0)  # fmt: skip
    path = write_log(log, folder / "zz.csv")
    out = {"log": path}
    for key, extra in (("default", []), ("0.7", ["--astern-thrust", "0.7"]),
                       ("fitted", ["--astern-thrust", "none"])):  # fmt: skip
        out[key] = folder / f"{key}.json"
        code, said, err = run(["identify", path, "--model", "blanke", "--no-output-error",
                               *extra, "-o", out[key]])  # fmt: skip
        assert code == 0, err
        out[f"{key}_said"] = said
    return out


def test_identify_writes_the_thrust_at_the_ratio_and_says_so(one_rps_files):
    docs = {k: json.loads(one_rps_files[k].read_text()) for k in ("default", "0.7", "fitted")}
    thrust = docs["fitted"]["model"]["coefficients"]["u"]["|n|*n"]  # the similarity's "1"
    for key, ratio in (("default", ASTERN_THRUST_RATIO), ("0.7", 0.7)):
        coefs = docs[key]["model"]["coefficients"]["u"]
        assert coefs[f"propeller({ratio:g})"] == thrust and "|n|*n" not in coefs
        record = docs[key]["identification"]["ahead_forms"]
        assert record["astern_thrust_ratio"] == ratio and "n²(astern" in record["terms"]
        said = one_rps_files[f"{key}_said"]
        assert f"its propeller pushes astern {ratio:g} times what it pushes ahead" in said
    assert "ahead_forms" in docs["fitted"]["identification"]  # the hull's forms still
    assert "astern_thrust_ratio" not in docs["fitted"]["identification"]["ahead_forms"]
    # The crash stop identify ran was of the model as written: it brakes at the ratio.
    astern = docs["default"]["identification"]["plausibility"]["astern"]
    assert not astern["diverged"]


def test_a_bad_ratio_on_the_command_line_is_a_usage_error(one_rps_files, tmp_path):
    from shipid.cli import main

    out = tmp_path / "m.json"
    # argparse's usage error, as for every option's value: exit 2 and a line naming it.
    with contextlib.redirect_stderr(io.StringIO()) as err, pytest.raises(SystemExit) as exc:
        main(["identify", str(one_rps_files["log"]), "--astern-thrust", "-1", "-o", str(out)])
    assert exc.value.code == 2 and not out.exists()
    assert "argument --astern-thrust: expected a ratio ≥ 0 or 'none', got '-1'" in err.getvalue()


def test_the_forms_say_which_part_they_change():
    from shipid.dynamics.model import ModelStructure

    both = ModelStructure("s", {"u": ("|u|u", "pos(n)^2"), "v": ("u*v",)})
    assert AsternForms(True, 0.5).parts(both) == (True, True)
    assert AsternForms(True, None).parts(both) == (True, False)
    assert AsternForms(False, 0.5).parts(both) == (False, True)
    assert AsternForms(True, 0.5).parts(ModelStructure("s", {"u": ("|u|u",)})) == (False, False)


def test_a_model_file_prior_in_the_other_thrust_form_holds_the_fit(one_rps_files):
    """A model file written with its thrust as propeller(k) as the prior of a fit whose surge
    holds pos(n)², or, at one rps, the constant that similarity writes |n|·n: the thrust takes
    the file's value, not 0."""
    from shipid.dynamics.model import ModelStructure
    from shipid.identification.priors import prior_at_rps, prior_from_model, prior_in_forms
    from shipid.reporting.modelfile import load_model

    written = prior_from_model(load_model(one_rps_files["default"]))
    value = written["u"]["propeller(0.5)"]
    pos = ModelStructure("s", {"u": ("|u|*u", "pos(n)^2")})
    assert prior_in_forms(written, pos)["u"]["pos(n)^2"] == value
    constant = ModelStructure("s", {"u": ("|u|*u", "1")})
    at_rps = prior_at_rps(prior_in_forms(written, constant), constant, N0)
    assert at_rps["u"]["1"] == pytest.approx(value * N0**2, rel=1e-12)
    # And the other way: a file's pos(n)² for a structure written with propeller(k).
    back = ModelStructure("s", {"u": ("|u|*u", "propeller(0.7)")})
    assert prior_in_forms({"u": {"pos(n)^2": 2.0}}, back)["u"]["propeller(0.7)"] == 2.0


def test_a_crash_stop_that_coasts_on_a_thrust_riding_on_the_advance_says_why():
    """u·|n| is even in n: a surge whose thrust rides on it (against a negative n⁺², as five of
    the nine sets of eight Esso zig-zag files take) pushes ahead whichever way the propeller
    turns. The crash stop's note said none of its terms acted with n < 0, which u·|n| does."""
    from shipid.dynamics.model import ManoeuvringModel

    model = ManoeuvringModel("u: |u|u, pos(n)^2, u*|n|; v: v; r: r",
                             {"u": {"|u|u": -0.324, "pos(n)^2": -8.05e-5, "u*|n|": 0.0139},
                              "v": {"v": -1.0}, "r": {"r": -1.0}})  # fmt: skip
    note = astern_thrust_note(model, 0.5, 16.67)
    braking = astern_braking(model, 0.5, 16.67)
    assert note.kind == "coasting" and braking["braking"] > 0  # reversed, it pushes ahead
    assert ("its thrust rides on the advance, u |n| at +0.0139 against pos(n)² at -8.05e-05, a "
            "term even in n that pushes ahead whichever way the propeller turns") in note.note
    assert note.note.endswith("--bound 'u: u*|n| <= 0' (or --constraints signs) holds it to the "
                              "thrust's fall with the advance")  # fmt: skip
