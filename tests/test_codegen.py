"""Kernels generated per term set against the term interpreter (the independent reference):
the same states, open and closed loop, for a term set that uses every factor operation, power,
derived signal and the wind; the engine choice and the cache folder."""

import math

import numpy as np
import pytest

from shipid.dynamics import codegen
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.dynamics.simulate import input_array, run_kernel
from shipid.errors import ShipidError
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import scale_ship
from shipid.vessels.scale_ship import scale_ship_model

# Every factor operation (x, |x|, pos, neg, sin, cos, the hull's cross-flow), powers, U and β,
# the propeller, the wind.
RICH = ("|u|u", "v*r", "1", "u*r", "u*v", "|v|v", "|v|r", "delta", "v^3", "pos(n)^2*delta",
        "neg(v)*r", "U^2*sin(2*beta)", "wind_speed^2*cos(wind_angle)", "u^2*delta^2",
        "crossflow_sway(4)", "u*crossflow_yaw(4)")  # fmt: skip


def rich_model() -> ManoeuvringModel:
    base = scale_ship_model().coefficients
    rng = np.random.default_rng(1)
    coefs = {}
    for d in "uvr":
        c = {t: 1e-3 * rng.normal() for t in RICH}
        c.update({t: v for t, v in base[d].items() if t in c})
        coefs[d] = c
    return ManoeuvringModel(ModelStructure("rich", {d: RICH for d in "uvr"}), coefs)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    # The suite's own folder beside pytest's numbered runs, kept between runs and shared by the
    # xdist workers: the compilation is paid once per machine.
    base = tmp_path_factory.getbasetemp()
    if base.name.startswith("popen-gw"):
        base = base.parent
    folder = base.parent / "shipid-kernels"
    mp.setenv("SHIPID_CACHE_DIR", str(folder))
    yield folder
    mp.undo()


@pytest.mark.parametrize("method", ["euler", "rk4"])
def test_the_generated_open_loop_is_the_interpreters(cache, method):
    model = rich_model()
    n, B = 600, 3
    t = np.arange(n) * 0.2
    rng = np.random.default_rng(0)
    series = {"delta": 0.3 * np.sign(np.sin(2 * np.pi * t / 30))[None] * np.ones((B, 1)),
              "n": 10 + rng.normal(size=(B, n)), "wind_speed": 3 + 0 * t,
              "wind_angle": np.linspace(-3, 3, n)}  # fmt: skip
    inputs = input_array(series, B, n)
    s0 = np.column_stack([np.linspace(1.5, 2.0, B), np.zeros((B, 5))])
    thetas = model.theta[None] * np.array([1.0, 1.01, 0.99])[:, None, None]
    a, na = run_kernel(model.code, thetas, t, inputs, s0, method, 20.0, 5.0, engine="generated")
    b, nb = run_kernel(model.code, thetas, t, inputs, s0, method, 20.0, 5.0, engine="interpreted")
    assert (na == n).all() and (na == nb).all()
    np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-13)
    assert np.ptp(a[:, :, 2]) > 0.05  # it turned: the comparison is not of two straight lines


def test_the_generated_closed_loop_is_the_interpreters(cache):
    model = rich_model()
    ship = scale_ship(rudder_rate_deg=9.6)
    ship = type(ship)(**{**ship.__dict__, "dynamics": model})
    kw = {"duration": 120, "dt": 0.1, "method": "rk4", "rps": 12.0, "wind": (3.0, 1.0)}
    with codegen.use("generated"):
        a = zigzag(ship, 20, 20, **kw)
    with codegen.use("interpreted"):
        b = zigzag(ship, 20, 20, **kw)
    assert not a.diverged and len(a.log) == 1201
    np.testing.assert_allclose(a.log[["u", "v", "r", "psi", "x", "y", "delta"]].to_numpy(),
                               b.log[["u", "v", "r", "psi", "x", "y", "delta"]].to_numpy(),
                               rtol=1e-12, atol=1e-12)  # fmt: skip
    assert a.indices["first_overshoot_deg"] == pytest.approx(b.indices["first_overshoot_deg"],
                                                             abs=1e-9)


def test_the_module_is_written_once_and_reused(cache):
    code = rich_model().code
    module = codegen.load(code)
    before = sorted(cache.glob("shipid_terms_*.py"))
    assert codegen.load(code) is module
    assert sorted(cache.glob("shipid_terms_*.py")) == before  # nothing written again
    path = cache / f"{module.__name__}.py"
    assert path in before
    text = path.read_text()
    assert "Do not edit" in text and "math.atan2(-v, u)" in text  # β is used, so computed
    # A term set without U, β or wind computes none of them.
    assert "atan2" not in codegen.source(scale_ship_model().code)



def test_only_the_non_zero_coefficients_are_compiled_in(cache):
    """The paper's model: surge, sway and yaw have different terms (and r² a zero coefficient),
    so 14 of the 30 (equation, term) products are left out of the generated sums, which is what
    brings it to a loop with the terms typed in. The states still equal the interpreter's, open
    and closed loop; a batch compiles in the pairs non-zero in any of its members."""
    model = scale_ship_model()
    pairs = codegen.nonzero_pairs(model.code, model.theta)
    assert model.code.n_terms == 10 and pairs.sum() == 16  # surge 4 (r² is 0.0), sway and yaw 6
    text = codegen.source(model.code, pairs)
    for i in range(3):
        line = next(ln for ln in text.splitlines() if ln.strip().startswith(f"a{i} = "))
        assert line.count("th[") == pairs[i].sum()
    other = model.theta.copy()
    j = model.code.texts.index("r^2")
    other[0, j] = 0.01
    assert codegen.nonzero_pairs(model.code, np.stack([model.theta, other]))[0, j]
    t = np.arange(600) * 0.2
    inputs = input_array({"delta": 0.35 * np.sign(np.sin(2 * np.pi * t / 40))}, 2, 600)
    s0 = np.array([[1.9, 0, 0, 0, 0, 0], [2.0, 0.01, 0, 0, 0, 0]])
    thetas = np.stack([model.theta, 1.01 * model.theta])  # the same pairs: one module compiled
    a, na = run_kernel(model.code, thetas, t, inputs, s0, "rk4", 20.0, 5.0, engine="generated")
    b, nb = run_kernel(model.code, thetas, t, inputs, s0, "rk4", 20.0, 5.0, engine="interpreted")
    assert (na == 600).all() and (nb == 600).all()
    np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-13)
    ship = scale_ship(rudder_rate_deg=9.6)
    kw = {"duration": 90, "dt": 0.05, "method": "euler"}
    with codegen.use("generated"):
        g = zigzag(ship, 20, 20, **kw).log
    with codegen.use("interpreted"):
        i = zigzag(ship, 20, 20, **kw).log
    np.testing.assert_allclose(g[["u", "v", "r", "psi"]].to_numpy(),
                               i[["u", "v", "r", "psi"]].to_numpy(), rtol=1e-12, atol=1e-12)

def test_auto_interprets_short_runs_of_new_term_sets(monkeypatch):
    code = ModelStructure("tiny", {"u": ("1",), "v": ("delta",), "r": ("delta",)})
    model = ManoeuvringModel(code, {"u": {"1": 0.0}, "v": {"delta": 0.01}, "r": {"delta": -0.1}})
    loaded = []
    monkeypatch.setattr(codegen, "load", lambda c, pairs=None: loaded.append(c))
    assert codegen.choose(model.code, 1000) is None and not loaded
    codegen.choose(model.code, codegen.GENERATED_MIN_STEPS)
    assert loaded == [model.code]
    with pytest.raises(ShipidError, match="engine must be one of"):
        codegen.choose(model.code, 10, "fast")
    with codegen.use("interpreted"):
        assert codegen.choose(model.code, 10**9) is None
    assert codegen.choose(model.code, 10) is None  # the context is gone


def test_an_unwritable_cache_folder_falls_back_to_the_interpreter(monkeypatch, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("SHIPID_CACHE_DIR", str(blocker / "kernels"))  # below a file: cannot exist
    monkeypatch.setattr(codegen, "_loaded", {})
    monkeypatch.setattr(codegen, "_unwritable", False)
    model = scale_ship_model()
    assert codegen.load(model.code) is None
    t = np.arange(50) * 0.2
    out, n_valid = run_kernel(model.code, model.theta, t, input_array({"delta": 0.1 + 0 * t}, 1, 50),
                              np.array([[1.9, 0, 0, 0, 0, 0]]), "euler", 20.0, 5.0,
                              engine="generated")  # fmt: skip
    assert n_valid[0] == 50 and math.isfinite(out[0, -1, 2])
