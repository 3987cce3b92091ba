"""Exports of an identified model: a python-control nonlinear I/O system (and its linearisation),
and a standalone NumPy module with no shipid dependency.

python-control: states [u, v, r, ψ, x, y], inputs ['delta', and the model's input columns n,
thrust, wind_speed, wind_angle], outputs the states. With ``dt=None`` a continuous-time system
(integrate it with ``control.input_output_response``); with ``dt`` a discrete-time system whose
update is one step of shipid's own Euler or RK4 scheme, so its response equals ``simulate``'s.

NumPy module: ``accelerations``, ``derivatives`` and ``simulate`` (Euler or RK4, inputs held over
each step as in shipid), the coefficients written out exactly (``repr`` of each float); a hybrid
model's kernel residual as a function ``residual`` and its arrays.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from shipid.dynamics.hybrid import HybridModel
from shipid.dynamics.model import DOFS, ManoeuvringModel
from shipid.dynamics.terms import OPS, parse_term
from shipid.errors import ShipidError

STATE_NAMES = ("u", "v", "r", "psi", "x", "y")
# What each input of an exported module is, in shipid's canonical units and conventions.
INPUT_MEANINGS = {
    "n": "n [rps], the propeller speed (negative astern)",
    "thrust": "thrust [N]",
    "wind_speed": "wind_speed [m/s], the relative wind an anemometer on the ship reads",
    "wind_angle": "wind_angle [rad], where that wind comes from, clockwise from the bow",
}


def _inputs(model: ManoeuvringModel) -> list[str]:
    return ["delta", *model.inputs]


def _check(model) -> ManoeuvringModel:
    if not isinstance(model, ManoeuvringModel):
        raise ShipidError(f"only identified models can be exported, got {type(model).__name__}")
    return model


def to_control(model: ManoeuvringModel, dt: float | None = None, method: str = "rk4",
               name: str = "ship"):  # fmt: skip
    """The model as a ``control.NonlinearIOSystem`` (see the module docstring)."""
    import control

    model = _check(model)
    inputs = _inputs(model)

    def rhs(x, u):
        given = dict(zip(inputs, (np.atleast_1d(ui) for ui in u), strict=True))
        acc = model.accelerations(np.atleast_1d(x[0]), x[1], x[2], given.pop("delta"),
                                  given.pop("thrust", None), given.pop("n", None),
                                  **given)[0]  # fmt: skip
        c, s = math.cos(x[3]), math.sin(x[3])
        return np.array([acc[0], acc[1], acc[2], x[2], x[0] * c - x[1] * s, x[0] * s + x[1] * c])

    if dt is None:
        def update(t, x, u, params):
            return rhs(x, u)
    else:
        if not (math.isfinite(dt) and dt > 0) or method not in ("euler", "rk4"):
            raise ShipidError("a discrete export needs dt > 0 and method 'euler' or 'rk4'")

        def update(t, x, u, params):
            k1 = rhs(x, u)
            if method == "euler":
                return x + dt * k1
            k2 = rhs(x + 0.5 * dt * k1, u)
            k3 = rhs(x + 0.5 * dt * k2, u)
            k4 = rhs(x + dt * k3, u)
            return x + (dt / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)

    return control.nlsys(update, None, states=list(STATE_NAMES), inputs=inputs,
                         outputs=list(STATE_NAMES), dt=0 if dt is None else dt,
                         name=name)  # fmt: skip


def linearised_control(model: ManoeuvringModel, speed: float, rps: float | None = None):
    """``control.StateSpace`` of the surge–sway–yaw dynamics linearised about the trimmed
    straight run (states u − u0, v − v0, r; input δ − δ0, the trim in
    ``shipid.control.linear.linearise(model, speed, rps)["trim"]``)."""
    import control

    from shipid.control.linear import linearise

    lin = linearise(model, speed, rps)
    return control.ss(lin["A"], lin["B"][:, None], np.eye(3), np.zeros((3, 1)),
                      states=list(lin["states"]), inputs=["delta"],
                      outputs=list(lin["states"]))  # fmt: skip


_SIGNAL_EXPR = {"U": "np.sqrt(u * u + v * v)", "beta": "np.arctan2(-v, u)"}


def _factor_expr(f) -> str:
    x = _SIGNAL_EXPR.get(f.name, f.name)
    op = OPS[f.op]
    if f.crossflow:  # the module's own copy of shipid.dynamics.terms.crossflow
        return f"crossflow(v, r, {f.k!r})[{0 if op == 'crossflow_sway' else 1}]"
    if f.rudder:  # and of shipid.dynamics.terms.rudder_normal
        return f"rudder_normal(u, v, r, delta, n, {', '.join(repr(p) for p in f.params)})"
    if op == "pow":
        base = x
    elif op == "abs":
        base = f"np.abs({x})"
    elif op == "pos":
        base = f"np.maximum({x}, 0.0)"
    elif op == "neg":
        base = f"np.maximum(-({x}), 0.0)"
    elif f.propeller:  # n² ahead, −k n² astern
        base = f"np.where({x} >= 0.0, 1.0, {-f.k!r}) * {x} * {x}"
    else:
        base = f"np.{op}({f.k} * {x})" if f.k != 1 else f"np.{op}({x})"
    return base if f.power == 1 else f"{base} ** {f.power}"


def _factor_sources(model: ManoeuvringModel) -> list[str]:
    """The cross-flow factors' and the rudder's normal force's functions, where the model has
    them (their source, as shipid runs it)."""
    import inspect

    from shipid.dynamics.terms import TINY, crossflow, rudder_normal

    terms = [parse_term(t) for coefs in model.coefficients.values() for t in coefs]
    out = []
    if any(t.crossflow for t in terms):
        out += [f"TINY = {TINY!r}", "", "", *inspect.getsource(crossflow).splitlines(), "", ""]
    if any(t.rudder for t in terms):
        out += [*inspect.getsource(rudder_normal).splitlines(), "", ""]
    return out


def _array_literal(a: np.ndarray) -> str:
    """``np.array([...])`` with every float written exactly (``repr``)."""
    return "np.array(" + repr(np.asarray(a, dtype=float).tolist()) + ")"


def _residual_source(model: HybridModel) -> list[str]:
    """The kernel residual of a hybrid as module-level arrays and a function ``residual``."""
    r = model.residual
    args = ", ".join(r.features)
    return [
        "",
        "",
        f"RESIDUAL_FEATURES = {r.features!r}",
        f"RESIDUAL_MEAN = {_array_literal(r.mean)}",
        f"RESIDUAL_SCALE = {_array_literal(r.scale)}",
        f"RESIDUAL_SIGMA = {r.sigma!r}",
        f"RESIDUAL_REACH = {r.reach!r}",
        f"RESIDUAL_INTERCEPT = {_array_literal(r.intercept)}",
        f"RESIDUAL_CENTRES = {_array_literal(r.centres)}",
        f"RESIDUAL_WEIGHTS = {_array_literal(r.weights)}",
        "",
        "",
        f"def residual({args}):",
        '    """The kernel residual\'s (u̇, v̇, ṙ) at arrays of its features, faded out where the',
        '    kernel reaches less far than RESIDUAL_REACH (beyond the training envelope)."""',
        f"    x = np.column_stack([np.atleast_1d(np.asarray(a, dtype=float)) for a in ({args},)])",
        "    z = (x - RESIDUAL_MEAN) / RESIDUAL_SCALE",
        "    d2 = ((z[:, None, :] - RESIDUAL_CENTRES[None, :, :]) ** 2).sum(axis=2)",
        "    k = np.exp(-d2 / (RESIDUAL_SIGMA * RESIDUAL_SIGMA))",
        "    fade = np.minimum(1.0, k.max(axis=1) / RESIDUAL_REACH)",
        "    out = (k @ RESIDUAL_WEIGHTS + RESIDUAL_INTERCEPT) * fade[:, None]",
        "    return out[:, 0], out[:, 1], out[:, 2]",
    ]


def _conventions(inputs: list[str], rudder_positive: str | None, dt: float | None,
                 meanings: dict[str, str] | None = None) -> list[str]:  # fmt: skip
    """The exported module's docstring lines on units and signs: a module used without shipid
    has no log metadata to say which way its rudder turns (the Esso Osaka's models turn to
    starboard with positive delta, the KVLCC2's to port)."""
    rudder = ("delta [rad], the rudder angle; positive delta turns the ship to "
              f"{rudder_positive}" if rudder_positive else
              "delta [rad], the rudder angle (which way positive delta turns the ship: as in "
              "the training logs)")  # fmt: skip
    lines = ["Inputs, in INPUTS order:", "", f"- {rudder}"]
    lines += [f"- {(meanings or INPUT_MEANINGS).get(s, INPUT_MEANINGS.get(s, s))}" for s in inputs]
    lines += ["", "States: u, v [m/s] surge and sway (body axes, v to starboard), r [rad/s] yaw",
              "rate (positive to starboard), psi [rad] heading (clockwise from north), x, y [m]",
              "position (x north, y east, as derivatives() integrates them)."]  # fmt: skip
    if dt:
        lines.append(f"Identified from logs sampled at {dt:g} s: simulate at that step, as "
                     "shipid validated it.")  # fmt: skip
    return lines


def numpy_source(model: ManoeuvringModel | HybridModel, rudder_positive: str | None = None,
                 dt: float | None = None) -> str:  # fmt: skip
    """Python source of a standalone module (NumPy only) that evaluates and simulates the model
    (a hybrid's kernel residual with it: its centres and weights written out). ``rudder_positive``
    ('port' or 'starboard', the model file's) is written into it as RUDDER_POSITIVE, and said in
    its docstring with the inputs' units; ``dt``, the training logs' sampling time, too."""
    from shipid import __version__

    hybrid = model if isinstance(model, HybridModel) else None
    model = _check(hybrid.physical if hybrid else model)
    inputs = list(hybrid.inputs if hybrid else model.inputs)
    equations = (hybrid or model).equations(precision=6)
    lines = [
        f'"""{model.name}: a manoeuvring model exported by shipid {__version__}.',
        "",
        "Standalone (NumPy only). Equations:",
        "",
        *("    " + ln for ln in equations.splitlines()),
        "",
        *_conventions(inputs, rudder_positive, dt),
        '"""',
        "",
        "import numpy as np",
        "",
        f"INPUTS = {('delta', *inputs)!r}",
        f"RUDDER_POSITIVE = {rudder_positive!r}  # which way positive delta turns the ship",
        "",
        "",
        *_factor_sources(model),
        f"def accelerations(u, v, r, delta{''.join(f', {s}=0.0' for s in inputs)}):",
        '    """(u̇, v̇, ṙ) at arrays of states and inputs."""',
        "    u, v, r, delta = (np.asarray(a, dtype=float) for a in (u, v, r, delta))",
    ]
    lines += _sum_lines(model)
    if hybrid:
        names = ", ".join(hybrid.residual.features)
        lines += [f"    ru, rv, rr = residual({names})",
                  "    shape = np.shape(udot)",
                  "    udot, vdot, rdot = (udot + ru.reshape(shape), vdot + rv.reshape(shape),",
                  "                        rdot + rr.reshape(shape))"]  # fmt: skip
    lines += ["    return udot, vdot, rdot", *_integrator_lines(),
              *(_residual_source(hybrid) if hybrid else ()), ""]
    return "\n".join(lines)


def _sum_lines(model: ManoeuvringModel, prefix: str = "") -> list[str]:
    """The lines of ``accelerations`` that sum the model's terms into {prefix}udot, vdot, rdot
    (arrays u, v, r, delta and the inputs in scope)."""
    lines = []
    for dof in DOFS:
        coefs = model.coefficients.get(dof)
        if not coefs:
            lines.append(f"    {prefix}{dof}dot = np.zeros_like(u)")
            continue
        parts = []
        for text, c in coefs.items():
            term = parse_term(text)
            factors = " * ".join(_factor_expr(f) for f in term.factors)
            parts.append(f"{c!r}" + (f" * {factors}" if factors else " * np.ones_like(u)"))
        lines.append(f"    {prefix}{dof}dot = (" + "\n             + ".join(parts) + ")")
    return lines


def _integrator_lines() -> list[str]:
    """``derivatives`` and ``simulate`` of an exported module, after its ``accelerations``."""
    return [
        "",
        "",
        "def derivatives(state, inputs):",
        '    """d/dt [u, v, r, psi, x, y] for one state and the inputs (in INPUTS order)."""',
        "    u, v, r, psi = state[0], state[1], state[2], state[3]",
        "    a = accelerations(u, v, r, *inputs)",
        "    c, s = np.cos(psi), np.sin(psi)",
        "    return np.array([float(a[0]), float(a[1]), float(a[2]), r, u * c - v * s, u * s + v * c])",
        "",
        "",
        'def simulate(t, inputs, state0, method="euler"):',
        '    """States (N, 6) on the grid t (N,) from state0 (6,: u, v, r, psi, x, y; or 3,: u, v, r',
        "    from psi = x = y = 0), inputs (N, len(INPUTS)) held over each step (sample k over",
        "    [t_k, t_k+1)), Euler or RK4 (method 'euler' or 'rk4') as shipid.simulate does.\"\"\"",
        '    if method not in ("euler", "rk4"):',
        "        raise ValueError(f\"method must be 'euler' or 'rk4', got {method!r}\")",
        "    t = np.asarray(t, dtype=float)",
        "    inputs = np.asarray(inputs, dtype=float)",
        "    if inputs.size != len(t) * len(INPUTS):",
        "        raise ValueError(f\"inputs: {inputs.shape} values for {len(t)} times and \"",
        "                         f\"{len(INPUTS)} input(s) {INPUTS}; give (N, {len(INPUTS)})\")",
        "    inputs = inputs.reshape(len(t), len(INPUTS))",
        "    x = np.asarray(state0, dtype=float).ravel()",
        "    if x.size == 3:",
        "        x = np.concatenate([x, np.zeros(3)])",
        "    if x.size != 6:",
        "        raise ValueError(f\"state0: {x.size} values; give u, v, r (3) \"",
        "                         \"or u, v, r, psi, x, y (6)\")",
        "    out = np.empty((len(t), 6))",
        "    out[0] = x",
        "    for k in range(len(t) - 1):",
        "        h, w = t[k + 1] - t[k], inputs[k]",
        "        k1 = derivatives(x, w)",
        '        if method == "euler":',
        "            x = x + h * k1",
        "        else:",
        "            k2 = derivatives(x + 0.5 * h * k1, w)",
        "            k3 = derivatives(x + 0.5 * h * k2, w)",
        "            k4 = derivatives(x + h * k3, w)",
        "            x = x + (h / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)",
        "        out[k + 1] = x",
        "    return out",
    ]


def export_numpy(model: ManoeuvringModel | HybridModel, path: str | Path,
                 rudder_positive: str | None = None, dt: float | None = None) -> Path:  # fmt: skip
    """Write ``numpy_source(model, rudder_positive, dt)`` atomically to ``path`` (a .py file)."""
    from shipid.outputs import atomic_write_text

    return atomic_write_text(path, numpy_source(model, rudder_positive, dt))


def _mmg_function_source() -> list[str]:
    """The MMG formula as shipid runs it (``shipid.vessels.mmg.accelerations``, its source
    without numba's decorator), named ``mmg_accelerations``."""
    import inspect

    from shipid.vessels import mmg

    source = inspect.getsource(mmg.accelerations.py_func).splitlines()
    start = next(i for i, line in enumerate(source) if line.startswith("def "))
    return [source[start].replace("def accelerations(", "def mmg_accelerations("),
            *source[start + 1:]]  # fmt: skip


def mmg_source(ship) -> str:
    """Python source of a standalone module (NumPy only) of an MMG ship (a ``Vessel`` whose
    dynamics are ``shipid.vessels.mmg.MMGDynamics``: the built-in KVLCC2, an MMG file) or of one
    corrected by ``shipid correct`` (its correction's terms added): the MMG formula shipid runs,
    its coefficients written out exactly, ``accelerations``, ``derivatives`` and ``simulate``."""
    from shipid import __version__
    from shipid.vessels.mmg import MMGDynamics

    dyn = ship.dynamics
    reference = getattr(dyn, "reference", dyn)
    correction = getattr(dyn, "correction", None) if reference is not dyn else None
    if not isinstance(reference, MMGDynamics):
        raise ShipidError(f"{ship.name}: only identified models and MMG ships (an MMG file, the "
                          "KVLCC2, one of them corrected) export")  # fmt: skip
    inputs = (["n"] if reference.follow_rps else []) + [
        c for c in (correction.inputs if correction is not None else ()) if c != "delta"]
    fields = ",\n".join(f"    {k}={v!r}" for k, v in reference.packed._asdict().items())
    rps = ("the rate the inputs give (N_PROP, the trim for the approach, by default)"
           if reference.follow_rps else "N_PROP")
    corrected = [] if correction is None else [
        "", "Its correction (shipid correct), added to the MMG model's accelerations:", "",
        *("    " + ln for ln in correction.equations(precision=6).splitlines())]
    defaults = "".join(f", {s}=" + ("N_PROP" if s == "n" else "0.0") for s in inputs)
    names = ", ".join(["u", "v", "r", "delta"] + (["n"] if reference.follow_rps else []))
    lines = [
        f'"""{ship.name}: an MMG standard-method ship (Yasukawa & Yoshimura 2015) exported by '
        f"shipid {__version__}.",
        "",
        "Standalone (NumPy only).",
        f"Its propeller turns at {rps}.",
        "The MMG standard method models it turning ahead only (n > 0), and the ship under way",
        "(u, v not both 0).",
        *corrected,
        "",
        *_conventions(inputs, ship.rudder_positive, None,
                      {"n": "n [rps], the propeller speed (ahead: n > 0)"}),
        '"""',
        "",
        "import math",
        "from types import SimpleNamespace",
        "",
        "import numpy as np",
        "",
        f"INPUTS = {('delta', *inputs)!r}",
        f"RUDDER_POSITIVE = {ship.rudder_positive!r}  # which way positive delta turns the ship",
        f"N_PROP = {reference.n_prop!r}  # [rps], trimmed for {ship.approach_speed!r} m/s",
        "# The MMG model's coefficients: masses, the sway–yaw mass matrix's inverse, prime "
        "hull,",
        "# propeller and rudder coefficients (shipid.vessels.mmg.Coefficients).",
        f"C = SimpleNamespace(\n{fields},\n)",
        "",
        "",
        *_mmg_function_source(),
        "",
        "",
        *([] if correction is None else _factor_sources(correction)),
        f"def accelerations(u, v, r, delta{defaults}):",
        '    """(u̇, v̇, ṙ) at arrays of states and inputs (v the sway velocity at midship)."""',
        f"    {names} = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in ({names})))",
        "    own = np.array([mmg_accelerations(C, *s) for s in zip(",
        "        u.ravel(), v.ravel(), r.ravel(), delta.ravel(), "
        + ("n.ravel()" if reference.follow_rps else "np.full(u.size, N_PROP)") + ")])",
        "    own = own.reshape(u.shape + (3,))",
        "    udot, vdot, rdot = own[..., 0], own[..., 1], own[..., 2]",
    ]
    if correction is not None:
        lines += _sum_lines(correction, "c")
        lines += ["    udot, vdot, rdot = udot + cudot, vdot + cvdot, rdot + crdot"]
    lines += ["    return udot, vdot, rdot", *_integrator_lines(), ""]
    return "\n".join(lines)


def export_ship(ship, path: str | Path) -> Path:
    """Write ``mmg_source(ship)`` atomically to ``path`` (a .py file)."""
    from shipid.outputs import atomic_write_text

    return atomic_write_text(path, mmg_source(ship))
