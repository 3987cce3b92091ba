"""Simulation speed of the compiled term interpreter against honest baselines in the same process.

Baselines (the strongest simple alternatives, not a strawman):
* a plain Python loop of the same Blanke model, scalar ``math`` arithmetic (no NumPy per step);
* a hand-written numba loop of the same Blanke model, its six terms typed in: the practical
  limit of a compiled loop, which a general interpreter of any term set can only approach.

Cases: the paper's Blanke model (6 terms per equation) and a 20-term user library (the #9 target:
≥ 1e6 steps/s for one trajectory of an arbitrary 20-term library), one trajectory of 2e6 steps
(the free-run kernel alone, ``run_kernel``, and the whole ``simulate`` with its log), and a batch
of 1000 × 2000. Run: .venv/bin/python benchmarks/bench_simulate.py
"""

from __future__ import annotations

import math
import os

import numba
import numpy as np
import pandas as pd
from timing import best_of

from shipid.dynamics import codegen, kernel
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.dynamics.simulate import input_array, run_kernel, simulate, simulate_batch
from shipid.vessels import scale_ship_model
from shipid.vessels.mmg import accelerations as mmg_accelerations
from shipid.vessels.tanker import accelerations as tanker_accelerations

TERMS_20 = ("|u|u", "v*r", "r^2", "delta^2", "1", "u*r", "u*v", "|v|v", "|v|r", "delta",
            "u^2*delta", "v^3", "v^2*r", "v*r^2", "r^3", "u*delta", "delta^3", "v*delta^2",
            "|r|r", "U^2*sin(2*beta)")  # fmt: skip


def user_model() -> ManoeuvringModel:
    rng = np.random.default_rng(0)
    base = scale_ship_model().coefficients
    coefs = {}
    for d in "uvr":
        c = {t: 1e-3 * rng.normal() for t in TERMS_20}
        c.update({t: v for t, v in base[d].items() if t in c})  # keep it stable: eq. 16 inside
        coefs[d] = c
    return ManoeuvringModel(ModelStructure("user-20", {d: TERMS_20 for d in "uvr"}), coefs)


def python_rhs(a, b, c):
    """The Blanke model's state derivative in plain Python (coefficients as Python floats)."""
    a, b, c = ([float(x) for x in coefs] for coefs in (a, b, c))

    def rhs(u, v, r, psi, d):
        av = abs(v)
        return (a[0] * abs(u) * u + a[1] * v * r + a[2] * r * r + a[3] * d * d + a[4],
                b[0] * u * r + b[1] * u * v + b[2] * av * v + b[3] * av * r + b[4] * d + b[5],
                c[0] * u * r + c[1] * u * v + c[2] * av * v + c[3] * av * r + c[4] * d + c[5],
                r, u * math.cos(psi) - v * math.sin(psi), u * math.sin(psi) + v * math.cos(psi))

    return rhs


def python_step(rhs, s, d, h, rk4):
    """One Euler or RK4 step of the state list ``s`` with the rudder ``d`` held."""
    k1 = rhs(s[0], s[1], s[2], s[3], d)
    if not rk4:
        return [x + h * y for x, y in zip(s, k1, strict=True)]
    k2 = rhs(*[x + 0.5 * h * y for x, y in zip(s[:4], k1[:4], strict=True)], d)
    k3 = rhs(*[x + 0.5 * h * y for x, y in zip(s[:4], k2[:4], strict=True)], d)
    k4 = rhs(*[x + h * y for x, y in zip(s[:4], k3[:4], strict=True)], d)
    return [x + h / 6 * (p + 2 * q + 2 * w + z)
            for x, p, q, w, z in zip(s, k1, k2, k3, k4, strict=True)]  # fmt: skip


def blanke_arrays(model):
    """The Blanke model's coefficients in the hand-written loops' order."""
    cu, cv, cr = (model.coefficients[d] for d in "uvr")
    return (np.array([cu["|u|*u"], cu["v*r"], cu["r^2"], cu["delta^2"], cu["1"]]),
            np.array([cv[k] for k in ("u*r", "u*v", "|v|*v", "|v|*r", "delta", "1")]),
            np.array([cr[k] for k in ("u*r", "u*v", "|v|*v", "|v|*r", "delta", "1")]))


def python_loop(model, t, delta, u0, method):
    """Plain Python, scalar math: the Blanke model's terms written out."""
    rhs = python_rhs(*blanke_arrays(model))
    t, delta = [float(x) for x in t], [float(x) for x in delta]
    s = [u0, 0.0, 0.0, 0.0, 0.0, 0.0]
    for k in range(len(t) - 1):
        s = python_step(rhs, s, delta[k], t[k + 1] - t[k], method == "rk4")
    return s


@numba.njit(cache=True)
def _blanke_rhs(a, b, c, u, v, r, psi, d):
    av = abs(v)
    return (a[0] * abs(u) * u + a[1] * v * r + a[2] * r * r + a[3] * d * d + a[4],
            b[0] * u * r + b[1] * u * v + b[2] * av * v + b[3] * av * r + b[4] * d + b[5],
            c[0] * u * r + c[1] * u * v + c[2] * av * v + c[3] * av * r + c[4] * d + c[5],
            r, u * math.cos(psi) - v * math.sin(psi), u * math.sin(psi) + v * math.cos(psi))


@numba.njit(cache=True, inline="always")
def _blanke_step(a, b, c, u, v, r, psi, x, y, d, h, rk4):
    """One Euler or RK4 step of the typed-in Blanke model with the rudder d held."""
    k1 = _blanke_rhs(a, b, c, u, v, r, psi, d)
    if not rk4:
        return (u + h * k1[0], v + h * k1[1], r + h * k1[2], psi + h * k1[3], x + h * k1[4],
                y + h * k1[5])
    g = 0.5 * h
    k2 = _blanke_rhs(a, b, c, u + g * k1[0], v + g * k1[1], r + g * k1[2], psi + g * k1[3], d)
    k3 = _blanke_rhs(a, b, c, u + g * k2[0], v + g * k2[1], r + g * k2[2], psi + g * k2[3], d)
    k4 = _blanke_rhs(a, b, c, u + h * k3[0], v + h * k3[1], r + h * k3[2], psi + h * k3[3], d)
    w = h / 6.0
    return (u + w * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
            v + w * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]),
            r + w * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]),
            psi + w * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]),
            x + w * (k1[4] + 2 * k2[4] + 2 * k3[4] + k4[4]),
            y + w * (k1[5] + 2 * k2[5] + 2 * k3[5] + k4[5]))


@numba.njit(cache=True)
def numba_loop(a, b, c, t, delta, u0, rk4, out):
    """Hand-written numba loop of the Blanke model (terms typed in): the practical limit."""
    u, v, r, psi, x, y = u0, 0.0, 0.0, 0.0, 0.0, 0.0
    for k in range(t.size - 1):
        u, v, r, psi, x, y = _blanke_step(a, b, c, u, v, r, psi, x, y, delta[k], t[k + 1] - t[k],
                                          rk4)  # fmt: skip
        out[k + 1, 0], out[k + 1, 1], out[k + 1, 2] = u, v, r
        out[k + 1, 3], out[k + 1, 4], out[k + 1, 5] = psi, x, y


def main() -> None:
    blanke, user = scale_ship_model(), user_model()
    zig = lambda t: 0.35 * np.sign(np.sin(2 * np.pi * t / 30) + 1e-9)  # noqa: E731
    a, b, c = blanke_arrays(blanke)
    s0 = np.array([[1.9, 0, 0, 0, 0, 0]])
    for m in (blanke, user):  # compile or load the caches (the generated kernels too)
        for engine in ("interpreted", "generated"):
            with codegen.use(engine):
                simulate(m, np.arange(0, 1, 0.2), np.zeros(5), {"u": 1.9})
                simulate_batch(m, np.arange(0, 1, 0.2), np.zeros((2, 5)), {"u": 1.9})
    numba_loop(a, b, c, np.arange(5) * 0.2, np.zeros(5), 1.9, True, np.zeros((5, 6)))
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| case | method | steps | time (s) | steps/s | vs plain Python loop | "
          "vs hand-written numba | target |")
    print("|---|---|---|---|---|---|---|---|")
    for method in ("euler", "rk4"):
        rk4 = method == "rk4"
        n_py = 200_000
        t = np.arange(n_py) * 0.2
        py_rate = (n_py - 1) / best_of(lambda: python_loop(blanke, t, zig(t), 1.9, method), 1)  # noqa: B023
        n = 2_000_000
        t = np.arange(n) * 0.2
        d = zig(t)
        out = np.zeros((n, 6))
        nb_rate = (n - 1) / best_of(lambda: numba_loop(a, b, c, t, d, 1.9, rk4, out))  # noqa: B023
        inp = input_array({"delta": d}, 1, n)
        print(f"| Blanke, plain Python loop | {method} | {n_py:.0e} | – | {py_rate:.3g} | 1× | "
              f"{py_rate / nb_rate:.3f}× | baseline |")
        print(f"| Blanke, hand-written numba loop | {method} | {n:.0e} | – | {nb_rate:.3g} | "
              f"{nb_rate / py_rate:.0f}× | 1× | baseline |")
        for model, label in ((blanke, "Blanke (6 terms)"), (user, "user library (20 terms)")):
            for engine in ("interpreted", "generated"):
                kt = best_of(lambda m=model, t=t, inp=inp, method=method, e=engine: run_kernel(
                    m.code, m.theta, t, inp, s0, method, 20.0, 5.0, engine=e))
                rate = (n - 1) / kt
                target = ("≥ 0.8× numba" if engine == "generated" and "6" in label
                          else "≥ 1e6 steps/s" if "20" in label else "≥ 50× Python")
                print(f"| {label}, free-run kernel, {engine} | {method} | {n:.0e} | {kt:.3f} | "
                      f"{rate:.3g} | {rate / py_rate:.0f}× | {rate / nb_rate:.2f}× | {target} |")
            st = best_of(lambda m=model: simulate(m, t, d, {"u": 1.9}, method=method))  # noqa: B023
            print(f"| {label}, simulate() with its log | {method} | {n:.0e} | {st:.3f} | "
                  f"{(n - 1) / st:.3g} | {(n - 1) / st / py_rate:.0f}× | "
                  f"{(n - 1) / st / nb_rate:.2f}× | – |")
        B, nb = 1000, 2000
        t = np.arange(nb) * 0.2
        deltas = np.tile(zig(t), (B, 1)) * np.linspace(0.5, 1.0, B)[:, None]
        init = np.column_stack([np.linspace(1.5, 2.0, B), np.zeros((B, 5))])
        for model, label in ((blanke, "Blanke"), (user, "user library")):
            for engine in ("interpreted", "generated"):
                with codegen.use(engine):
                    bt = best_of(lambda m=model: simulate_batch(m, t, deltas, init, method=method))  # noqa: B023
                rate = B * (nb - 1) / bt
                target = "≥ 1e7 state-steps/s" if label == "Blanke" else "–"
                print(f"| {label}, batch of {B}, {engine} | {method} | {B}×{nb} | {bt:.3f} | "
                      f"{rate:.3g} | {rate / py_rate:.0f}× | {rate / nb_rate:.2f}× | {target} |")


def python_zigzag(a, b, c, n, dt, u0, rk4, rudder, switch, rate, stbd):
    """Plain Python closed-loop zig-zag of the Blanke model: the rudder reversed at ±switch of
    heading, a rate-limited steering machine, states and rudder recorded every step; ``stbd``
    the sign of a starboard rudder angle."""
    rhs = python_rhs(a, b, c)
    s = [u0, 0.0, 0.0, 0.0, 0.0, 0.0]
    delta, side, lim = 0.0, 1.0, rate * dt
    states, rudders = [], []
    for _ in range(n):
        if side > 0 and s[3] >= switch:
            side = -1.0
        elif side < 0 and s[3] <= -switch:
            side = 1.0
        delta += min(max(side * stbd * rudder - delta, -lim), lim)
        states.append(tuple(s))
        rudders.append(delta)
        s = python_step(rhs, s, delta, dt, rk4)
    return states, rudders


@numba.njit(cache=True)
def numba_zigzag(a, b, c, n, dt, u0, rk4, rudder, switch, rate, stbd, states, rudders):
    """The same zig-zag hand-written in numba (terms typed in): the practical limit."""
    u, v, r, psi, x, y = u0, 0.0, 0.0, 0.0, 0.0, 0.0
    delta, side, lim = 0.0, 1.0, rate * dt
    for k in range(n):
        if side > 0 and psi >= switch:
            side = -1.0
        elif side < 0 and psi <= -switch:
            side = 1.0
        delta += min(max(side * stbd * rudder - delta, -lim), lim)
        states[k, 0], states[k, 1], states[k, 2] = u, v, r
        states[k, 3], states[k, 4], states[k, 5] = psi, x, y
        rudders[k] = delta
        u, v, r, psi, x, y = _blanke_step(a, b, c, u, v, r, psi, x, y, delta, dt, rk4)


def _closed_loop_table(title: str, model, n: int, dt: float):
    """Print a closed-loop table's title and header; returns the model's generated kernel."""
    print(f"\n{title}, {n:.0e} steps at {dt} s (load average {os.getloadavg()[0]:.2f})\n")
    print("| method | engine | time (s) | steps/s | vs plain Python loop | vs hand-written numba "
          "| target |")
    print("|---|---|---|---|---|---|---|")
    return codegen.load(model.code, codegen.nonzero_pairs(model.code, model.theta))


def _engine_rows(method, model, gen, params, s0, dt, n, py_rate, nb_rate, target: str):
    """The closed loop of ``params`` on the interpreted and generated kernels (kernel entries,
    no log), printed as rows against the baselines' rates; returns the run (engine → states)."""
    rk4 = method == "rk4"
    # Written into the same arrays every run, as the hand-written loop is: allocating and
    # first touching 112 MB per run would time the page faults, not the loop.
    out, rud, nv = np.zeros((1, n, 6)), np.zeros((1, n)), np.zeros(1, dtype=np.int64)

    def run(engine):
        args = (dt, n, s0, params[None].copy(), rk4, np.array([20.0]), np.array([5.0]), out,
                rud, nv)  # fmt: skip
        if engine == "generated":
            gen.integrate_closed(model.theta[None].copy(), *args)
        else:
            kernel.integrate_closed(model.theta[None].copy(), *model.code.arrays(),
                                    model.code.uses_derived, *args)  # fmt: skip
        return out

    for engine in ("interpreted", "generated"):
        run(engine)
        rate_e = n / best_of(lambda e=engine: run(e))
        print(f"| {method} | {engine} | {n / rate_e:.3f} | {rate_e:.3g} | "
              f"{rate_e / py_rate:.0f}× | {rate_e / nb_rate:.2f}× | "
              f"{target if engine == 'generated' else '–'} |")
    return run


def closed_loop() -> None:
    """Closed-loop 20/20 zig-zags of the Blanke model (scale ship, 9.6 °/s rudder): the term
    interpreter and the generated kernel (``kernel``-level entries, no log built) against a
    plain Python loop and a hand-written numba loop of the same manoeuvre."""
    from shipid.trials.manoeuvres import as_vessel, manoeuvre_params, run_closed_loop
    from shipid.vessels import scale_ship

    ship = scale_ship(rudder_rate_deg=9.6)
    model = ship.dynamics
    a, b, c = blanke_arrays(model)
    rudder, switch, rate = math.radians(20), math.radians(20), math.radians(9.6)
    vessel = as_vessel(ship)
    params = manoeuvre_params(vessel, kernel.MODE_ZIGZAG, rudder, 0.0, 0.0, switch=switch,
                              side=1.0)
    stbd = params[kernel.P_STBD]  # positive rudder turns this ship to port: −1
    dt, n = 0.05, 2_000_000
    u0 = vessel.approach_speed
    s0 = np.array([[u0, 0, 0, 0, 0, 0]])
    gen = _closed_loop_table("Closed-loop 20/20 zig-zag", model, n, dt)
    for method in ("euler", "rk4"):
        rk4 = method == "rk4"
        n_py = 200_000
        py_rate = n_py / best_of(lambda: python_zigzag(a, b, c, n_py, dt, u0, rk4, rudder,  # noqa: B023
                                                       switch, rate, stbd), 1)
        states, rudders = np.zeros((n, 6)), np.zeros(n)
        numba_zigzag(a, b, c, 10, dt, u0, rk4, rudder, switch, rate, stbd, states, rudders)
        nb_rate = n / best_of(lambda: numba_zigzag(a, b, c, n, dt, u0, rk4, rudder, switch,  # noqa: B023
                                                   rate, stbd, states, rudders))  # noqa: B023
        print(f"| {method} | plain Python loop | – | {py_rate:.3g} | 1× | "
              f"{py_rate / nb_rate:.3f}× | baseline |")
        print(f"| {method} | hand-written numba | – | {nb_rate:.3g} | {nb_rate / py_rate:.0f}× | "
              f"1× | baseline |")

        run = _engine_rows(method, model, gen, params, s0, dt, n, py_rate, nb_rate,
                           "≥ 50× Python, ≥ 0.8× numba")  # fmt: skip
        check = np.zeros((n, 6))
        numba_zigzag(a, b, c, n, dt, u0, rk4, rudder, switch, rate, stbd, check, rudders)
        ours = run("generated")[0]
        print(f"| {method} | (generated − hand-written numba, largest state difference) | "
              f"{np.abs(ours[:, :3] - check[:, :3]).max():.1e} | | | | |")
        with codegen.use("generated"):
            whole = best_of(lambda m=method: run_closed_loop(vessel, params, (n - 1) * dt, dt, m))
        print(f"| {method} | generated, run_closed_loop() with its log | {whole:.3f} | "
              f"{n / whole:.3g} | {n / whole / py_rate:.0f}× | {n / whole / nb_rate:.2f}× | – |")


class NumpyPath:
    """A reference ship seen through its NumPy ``derivatives`` only: the simulator's generic
    path, which is how the reference ships ran before their physics was compiled."""

    uses_thrust = False

    def __init__(self, dynamics):
        self.dynamics = dynamics

    def derivatives(self, nu, delta, thrust=None):
        return self.dynamics.derivatives(nu, delta)


def reference_ships() -> None:
    """Closed-loop turning circles of the reference ships: compiled physics against the NumPy
    path they ran on before (one ``derivatives`` call per RK4 stage), same steps."""
    import dataclasses

    from shipid.trials.manoeuvres import turning_circle
    from shipid.vessels import kvlcc2, mariner

    print("\nReference ships, closed-loop 35° turning circle (RK4)\n")
    print("| ship | steps | compiled (s) | steps/s | NumPy path (s) | speed-up |")
    print("|---|---|---|---|---|---|")
    for ship, duration, dt in ((kvlcc2(), 200.0, 0.05), (mariner(), 1000.0, 0.25)):
        slow_ship = dataclasses.replace(ship, dynamics=NumpyPath(ship.dynamics))
        turning_circle(ship, 35, duration=10 * dt, dt=dt)  # compile or load the caches
        n = int(duration / dt)
        fast = best_of(lambda s=ship, d=duration, h=dt: turning_circle(s, 35, duration=d, dt=h))
        slow = best_of(lambda s=slow_ship, d=duration, h=dt: turning_circle(
            s, 35, duration=d, dt=h), 1)
        print(f"| {ship.name} | {n} | {fast:.3f} | {n / fast:.3g} | {slow:.2f} | "
              f"{slow / fast:.0f}× |")


_TURN_SHIP = None  # the hand-written loop's coefficients: a global, frozen into its code


@numba.njit(cache=False)
def _mmg_turning_ship(u, v, r, d):
    """The MMG formula with the ship's coefficients frozen in as constants (``_TURN_SHIP``)."""
    c, rps = _TURN_SHIP
    return mmg_accelerations(c, u, v, r, d, rps)


_TANKER_RPS = 80.0 / 60.0  # the tanker's nominal propeller speed, frozen in


@numba.njit(cache=False)
def _tanker_turning_ship(u, v, r, d):
    """The tanker's formula (its coefficients are its module's constants) at its nominal rps."""
    return tanker_accelerations(u, v, r, d, _TANKER_RPS)


@numba.njit(cache=False)
def _typed_in_turn(ship_acc, n, dt, u0, rate, target, k_uv, k_ur, k_uud, states):
    """A turn hand-written in numba: the ship's formula (``ship_acc(u, v, r, δ)``, its
    coefficients frozen in as constants), a correction's three terms typed in, RK4, the rudder
    moving at its rate to ``target`` (the practical limit of the compiled closed loop)."""
    u, v, r, psi, x, y, d = u0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for k in range(n):
        states[k, 0], states[k, 1], states[k, 2] = u, v, r
        states[k, 3], states[k, 4], states[k, 5] = psi, x, y
        d = min(d + rate * dt, target)
        ks = np.empty((4, 6))
        su, sv, sr, sp = u, v, r, psi
        for i in range(4):
            a0, a1, a2 = ship_acc(su, sv, sr, d)
            ks[i, 0] = a0
            ks[i, 1] = a1 + k_uv * su * sv
            ks[i, 2] = a2 + k_ur * su * sr + k_uud * su * su * d
            ks[i, 3] = sr
            ks[i, 4] = su * math.cos(sp) - sv * math.sin(sp)
            ks[i, 5] = su * math.sin(sp) + sv * math.cos(sp)
            h = dt if i == 2 else 0.5 * dt
            su, sv, sr, sp = u + h * ks[i, 0], v + h * ks[i, 1], r + h * ks[i, 2], psi + h * ks[i, 3]
        w = dt / 6.0
        u += w * (ks[0, 0] + 2 * ks[1, 0] + 2 * ks[2, 0] + ks[3, 0])
        v += w * (ks[0, 1] + 2 * ks[1, 1] + 2 * ks[2, 1] + ks[3, 1])
        r += w * (ks[0, 2] + 2 * ks[1, 2] + 2 * ks[2, 2] + ks[3, 2])
        psi += w * (ks[0, 3] + 2 * ks[1, 3] + 2 * ks[2, 3] + ks[3, 3])
        x += w * (ks[0, 4] + 2 * ks[1, 4] + 2 * ks[2, 4] + ks[3, 4])
        y += w * (ks[0, 5] + 2 * ks[1, 5] + 2 * ks[2, 5] + ks[3, 5])
    return n


def _three_term_correction(k: tuple[float, float, float]) -> ManoeuvringModel:
    """blanke-race's 21 terms as a correction, three of them non-zero: v: u v; r: u r, u² δ."""
    from shipid.dynamics.model import get_structure

    structure = get_structure("blanke-race")
    coefficients = {d: dict.fromkeys(t, 0.0) for d, t in structure.terms.items()}
    coefficients["v"]["u*v"], coefficients["r"]["u*r"], coefficients["r"]["u^2*delta"] = k
    return ManoeuvringModel(structure, coefficients)


def _held_turn_rows(ship, rows, ship_acc, speed_lim: float, duration: float = 2000.0,
                    dt: float = 0.05) -> None:  # fmt: skip
    """Print a table row per (label, dynamics, the correction's three terms typed in) of
    ``ship``'s held turn at its largest rudder, the closed loop's kernel entry without the log:
    compiled, the generic Python loop (a tenth of the turn, scaled) and the hand-written loop
    of ``ship_acc`` with the terms typed in."""
    from shipid.identification.correction import CorrectedDynamics
    from shipid.trials.manoeuvres import _generic_closed_loop, manoeuvre_params

    n = int(duration / dt) + 1
    params = manoeuvre_params(ship, kernel.MODE_HOLD, ship.steering.max_angle, 0.0, 0.0)
    s0 = np.zeros((1, 6))
    s0[0, 0] = ship.approach_speed
    lim = (np.array([speed_lim]), np.array([10.0]))
    states, rudder, valid = np.zeros((1, n, 6)), np.zeros((1, n)), np.zeros(1, dtype=np.int64)
    mine = np.zeros((n, 6))
    m = n // 10  # the generic loop runs a tenth of the turn: 20 s of it otherwise

    def ours(dyn):
        dyn.integrate_closed(dt, n, s0, params[None].copy(), True, *lim, states, rudder, valid)
        return states[0].copy()

    def hand(k):
        return _typed_in_turn(ship_acc, n, dt, ship.approach_speed, ship.steering.max_rate,
                              ship.steering.max_angle, *k, mine)  # fmt: skip

    print("| ship | compiled (ms) | steps/s | generic Python loop (s) | speed-up | "
          "hand-written numba (ms) | vs hand-written | largest state difference |")
    print("|---|---|---|---|---|---|---|---|")
    for label, dyn, k in rows:
        ours(dyn)
        hand(k)
        fast = best_of(lambda d=dyn: ours(d), 5)
        typed = best_of(lambda k=k: hand(k), 5)
        generic = CorrectedDynamics(dyn.reference, dyn.correction) if k[0] else NumpyPath(dyn)
        slow = best_of(lambda g=generic: _generic_closed_loop(g, params, m, dt, s0, "rk4",
                                                              speed_lim, 10.0, None), 1) * n / m
        diff = float(np.max(np.abs(ours(dyn)[:, :3] - mine[:, :3])))
        print(f"| {label} | {1e3 * fast:.1f} | {n / fast:.3g} | {slow:.1f} | {slow / fast:.0f}× | "
              f"{1e3 * typed:.1f} | {typed / fast:.2f}× | {diff:.1e} |")


def mmg_ships() -> None:
    """The MMG model compiled once for any coefficients (``shipid.vessels.mmg``): the built-in
    KVLCC2, the same ship from an MMG file and the KVLCC2 with a correction (``shipid
    correct``), a 35° turning circle's closed loop (the kernel entry, no log), against the
    generic Python loop they ran on before (``derivatives`` per RK4 stage; the NumPy-free MMG
    file's, the correction through its compiled term kernel) and a hand-written numba loop with
    the coefficients frozen in as constants and the correction's terms typed in."""
    import dataclasses

    from shipid.identification.correction import CorrectedDynamics, corrected_dynamics
    from shipid.vessels import kvlcc2
    from shipid.vessels.mmg import MMGDynamics
    from shipid.vessels.mmg_file import mmg_vessel

    global _TURN_SHIP

    ship = kvlcc2()
    _TURN_SHIP = (ship.dynamics.packed, ship.dynamics.n_prop)
    doc = {"format": "shipid-mmg", "name": "kvlcc2-file", **{
        k: v for k, v in ship.dynamics.c.items() if "." not in k and k not in ("name", "rps")}}
    for key, value in ship.dynamics.c.items():
        if "." in key:
            group, name = key.split(".")
            doc.setdefault(group, {})[name] = value
    from_file = mmg_vessel(doc)
    correction = _three_term_correction((0.01, -0.02, 0.003))
    corrected = dataclasses.replace(ship, dynamics=corrected_dynamics(ship.dynamics, correction))
    rows = (("built-in KVLCC2", ship.dynamics, (0.0, 0.0, 0.0)),
            ("KVLCC2 from an MMG file", from_file.dynamics, (0.0, 0.0, 0.0)),
            ("KVLCC2 + correction", corrected.dynamics, (0.01, -0.02, 0.003)))
    assert all(isinstance(getattr(d, "reference", d), MMGDynamics) for _, d, _ in rows)
    print("\nMMG ships, a 2000 s 35° turning circle's closed loop (RK4, Δt 0.05 s, 40001 steps): "
          "the compiled kernel entry against the generic Python loop and a hand-written numba "
          "loop (coefficients as constants, the correction typed in)\n")
    _held_turn_rows(ship, rows, _mmg_turning_ship, 10.0)
    # What a user waits for: a 200 s 35° turn with its log and indices (turning_circle), the
    # ship compiled against the same ship stepped by the generic loop (the way an MMG file and
    # a corrected ship ran before).
    from shipid.trials.manoeuvres import turning_circle

    print("\n| ship | 35° turning circle, 200 s, log and indices: compiled (ms) | generic loop "
          "(ms) |")
    print("|---|---|---|")
    for label, dyn, k in rows:
        compiled = dataclasses.replace(ship, dynamics=dyn)
        generic = dataclasses.replace(ship, dynamics=CorrectedDynamics(dyn.reference,
                                                                       dyn.correction)
                                      if k[0] else NumpyPath(dyn))  # fmt: skip
        fast = best_of(lambda s=compiled: turning_circle(s, 35, duration=200.0), 5)
        slow = best_of(lambda s=generic: turning_circle(s, 35, duration=200.0), 1)
        print(f"| {label} | {1e3 * fast:.1f} | {1e3 * slow:.0f} |")


def corrected_tanker() -> None:
    """The tanker corrected (``shipid correct tanker``), compiled since 2026-11-29: a 2000 s
    10° turn's closed loop (the kernel entry, no log; its gear's lag left out, as the
    hand-written loop has none) against the generic Python loop it ran on before and a
    hand-written numba loop of the tanker's formula with the correction's terms typed in."""
    import dataclasses

    from shipid.dynamics.steering import SteeringMachine
    from shipid.identification.correction import CorrectedDynamics, corrected_dynamics
    from shipid.trials.manoeuvres import turning_circle
    from shipid.vessels import tanker

    ship = tanker()
    ship = dataclasses.replace(ship, steering=SteeringMachine(ship.steering.max_angle,
                                                              ship.steering.max_rate))
    k = (1e-4, -2e-4, 3e-6)  # v: u v; r: u r, u² δ (a tenth of the tanker's own, about)
    correction = _three_term_correction(k)
    corrected = dataclasses.replace(ship, dynamics=corrected_dynamics(ship.dynamics, correction))
    print("\nThe tanker corrected, a 2000 s 10° turn's closed loop (RK4, Δt 0.05 s, 40001 steps): "
          "the compiled kernel entry against the generic Python loop it ran on before and a "
          "hand-written numba loop (the tanker's formula, the correction typed in)\n")
    _held_turn_rows(ship, (("tanker", ship.dynamics, (0.0, 0.0, 0.0)),
                           ("tanker + correction", corrected.dynamics, k)),
                    _tanker_turning_ship, 50.0)
    generic = dataclasses.replace(ship, dynamics=CorrectedDynamics(ship.dynamics, correction))
    fast = best_of(lambda: turning_circle(corrected, 10, duration=2000.0), 3)
    slow = best_of(lambda: turning_circle(generic, 10, duration=200.0), 1) * 10
    print(f"\nA 2000 s 10° turning circle of the corrected tanker with its log and indices: "
          f"{1e3 * fast:.0f} ms compiled, {slow:.1f} s on the generic loop (a tenth of it run, "
          "times ten)")


def python_heading(a, b, c, n, dt, u0, rk4, target, gains, max_angle, rate):
    """Plain Python heading autopilot on the Blanke model: PID on the wrapped heading error
    (integral frozen while the command exceeds the rudder limit), a rate-limited steering
    machine, states and rudder recorded every step."""
    rhs = python_rhs(a, b, c)
    kp, ki, kd = gains
    s = [u0, 0.0, 0.0, 0.0, 0.0, 0.0]
    delta, integral, lim = 0.0, 0.0, rate * dt
    states, rudders = [], []
    for _ in range(n):
        err = (s[3] - target + math.pi) % (2 * math.pi) - math.pi
        cmd = -(kp * err + ki * integral + kd * s[2])
        if -max_angle <= cmd <= max_angle:
            integral += err * dt
        cmd = min(max(cmd, -max_angle), max_angle)
        delta += min(max(cmd - delta, -lim), lim)
        states.append(tuple(s))
        rudders.append(delta)
        s = python_step(rhs, s, delta, dt, rk4)
    return states, rudders


@numba.njit(cache=True)
def numba_heading(a, b, c, n, dt, u0, rk4, target, kp, ki, kd, max_angle, rate, states, rudders):
    """The same autopilot hand-written in numba (terms typed in): the practical limit."""
    u, v, r, psi, x, y = u0, 0.0, 0.0, 0.0, 0.0, 0.0
    delta, integral, lim = 0.0, 0.0, rate * dt
    for k in range(n):
        err = (psi - target + math.pi) % (2 * math.pi) - math.pi
        cmd = -(kp * err + ki * integral + kd * r)
        if -max_angle <= cmd <= max_angle:
            integral += err * dt
        cmd = min(max(cmd, -max_angle), max_angle)
        delta += min(max(cmd - delta, -lim), lim)
        states[k, 0], states[k, 1], states[k, 2] = u, v, r
        states[k, 3], states[k, 4], states[k, 5] = psi, x, y
        rudders[k] = delta
        u, v, r, psi, x, y = _blanke_step(a, b, c, u, v, r, psi, x, y, delta, dt, rk4)


def heading_autopilot() -> None:
    """The PID heading step (``shipid autopilot``) in the compiled closed loop
    (``kernel.MODE_HEADING``), kernel entries without a log, against a plain Python loop and a
    hand-written numba loop of the same autopilot on the same Blanke model; and
    ``heading_step`` with its log against the NumPy-per-step loop it ran in before
    (``heading_loop``, which ``follow_path`` still runs)."""
    from shipid.control.autopilot import heading_loop, heading_step, pid_from_nomoto
    from shipid.control.linear import nomoto
    from shipid.trials.manoeuvres import as_vessel, manoeuvre_params
    from shipid.vessels import scale_ship

    ship = scale_ship(rudder_rate_deg=9.6)
    model = ship.dynamics
    a, b, c = blanke_arrays(model)
    nm = nomoto(ship, ship.approach_speed)
    pid = pid_from_nomoto(nm["K"], nm["T"])
    target, dt, n = math.radians(20.0), 0.05, 2_000_000
    vessel = as_vessel(ship)
    params = manoeuvre_params(vessel, kernel.MODE_HEADING, target, 0.0, 0.0)
    params[kernel.P_KP], params[kernel.P_KI], params[kernel.P_KD] = pid.kp, pid.ki, pid.kd
    max_angle, rate = ship.steering.max_angle, ship.steering.max_rate
    u0 = vessel.approach_speed
    s0 = np.array([[u0, 0, 0, 0, 0, 0]])
    gen = _closed_loop_table("Heading autopilot, a 20° step", model, n, dt)
    for method in ("euler", "rk4"):
        rk4 = method == "rk4"
        n_py = 200_000
        py_rate = n_py / best_of(lambda: python_heading(a, b, c, n_py, dt, u0, rk4, target,  # noqa: B023
                                                        (pid.kp, pid.ki, pid.kd), max_angle,
                                                        rate), 1)  # fmt: skip
        states, rudders = np.zeros((n, 6)), np.zeros(n)
        args_nb = (a, b, c, n, dt, u0, rk4, target, pid.kp, pid.ki, pid.kd, max_angle, rate,
                   states, rudders)  # fmt: skip
        numba_heading(*args_nb)
        nb_rate = n / best_of(lambda: numba_heading(*args_nb))  # noqa: B023
        print(f"| {method} | plain Python loop | – | {py_rate:.3g} | 1× | "
              f"{py_rate / nb_rate:.3f}× | baseline |")
        print(f"| {method} | hand-written numba | – | {nb_rate:.3g} | {nb_rate / py_rate:.0f}× | "
              f"1× | baseline |")
        run = _engine_rows(method, model, gen, params, s0, dt, n, py_rate, nb_rate, "–")
        ours = run("generated")[0]
        print(f"| {method} | (generated − hand-written numba, largest state difference) | "
              f"{np.abs(ours[:, :3] - states[:, :3]).max():.1e} | | | | |")
    # With its log, against the loop it ran in before (NumPy per step, the same model).
    steps = 6000
    heading_step(ship, pid, 20.0, duration=1.0, dt=0.1)
    fast = best_of(lambda: heading_step(ship, pid, 20.0, steps * 0.1, dt=0.1))
    slow = best_of(lambda: heading_loop(ship, pid, 20.0, steps * 0.1, dt=0.1), 1)
    print(f"\nheading_step() with its log, {steps} RK4 steps: {1e3 * fast:.1f} ms; the "
          f"NumPy-per-step loop it ran in before: {1e3 * slow:.0f} ms ({slow / fast:.0f}×)")
    from shipid.control.autopilot import follow_loop, follow_path

    path = [(0.0, 0.0), (200.0, 0.0), (200.0, 200.0), (0.0, 200.0)]
    follow_path(ship, pid, path, 15.0, duration=10.0)
    fast = best_of(lambda: follow_path(ship, pid, path, 15.0, duration=600.0))
    slow = best_of(lambda: follow_loop(ship, pid, path, 15.0, 600.0), 1)
    n_run = len(follow_path(ship, pid, path, 15.0, duration=600.0).log)
    print(f"follow_path() along a 600 m path ({n_run} RK4 steps at 0.1 s, cut at its end): "
          f"{1e3 * fast:.1f} ms; the same loop in Python: {1e3 * slow:.0f} ms "
          f"({slow / fast:.0f}×)")


def kvlcc2_against_solve_ivp() -> None:
    """The KVLCC2's 35° turning circle the way shipmmg runs it (issue #13 names it as the
    baseline): scipy's ``solve_ivp`` (RK45, its default tolerances, as shipmmg calls it) on the
    MMG formulas evaluated in Python, the rudder a function of time. shipmmg itself does not
    install beside shipid (it pins Pillow < 11, matplotlib here needs newer), so its method is
    re-run on our formulas: ``accelerations.py_func``, the same MMG code before numba compiles it.
    A tight-tolerance ``solve_ivp`` run is the accuracy reference of both."""
    from scipy.integrate import solve_ivp

    from shipid.trials.indices import turning_indices
    from shipid.trials.manoeuvres import turning_circle
    from shipid.vessels import kvlcc2, mmg

    ship = kvlcc2()
    n, u0, duration, dt = ship.dynamics.n_prop, ship.approach_speed, 200.0, 0.05
    c = ship.dynamics.packed

    def python_formulas(u, v, r, delta, n):
        return mmg.accelerations.py_func(c, u, v, r, delta, n)

    def compiled_formulas(u, v, r, delta, n):
        return mmg.accelerations(c, u, v, r, delta, n)

    rate, target = ship.steering.max_rate, ship.steering.max_angle  # starboard: δ > 0

    def rhs_of(acc):
        def rhs(t, y):
            u, v, r, psi = y[0], y[1], y[2], y[3]
            a = acc(u, v, r, min(rate * t, target), n)
            return [a[0], a[1], a[2], r, u * math.cos(psi) - v * math.sin(psi),
                    u * math.sin(psi) + v * math.cos(psi)]  # fmt: skip

        return rhs

    t = np.arange(int(duration / dt) + 1) * dt

    def run_ivp(acc=python_formulas, **tol):
        sol = solve_ivp(rhs_of(acc), (0.0, t[-1]), [u0, 0, 0, 0, 0, 0], method="RK45",
                        t_eval=t, **tol)  # fmt: skip
        log = pd.DataFrame({"t": t, "u": sol.y[0], "v": sol.y[1], "r": sol.y[2],
                            "psi": sol.y[3], "x": sol.y[4], "y": sol.y[5],
                            "delta": np.minimum(rate * t, target)})  # fmt: skip
        return log, sol.nfev

    def baseline(**kw):
        log, nfev = run_ivp(**kw)
        return turning_indices(log, t_order=0.0)["tactical_diameter"], nfev

    ref, _ = baseline(rtol=1e-10, atol=1e-12)
    baseline()
    t_ivp = best_of(baseline)
    td_ivp, nfev = baseline()
    # The stronger simple alternative: the same solve_ivp calling our compiled formulas.
    baseline(acc=compiled_formulas)
    t_fast = best_of(lambda: baseline(acc=compiled_formulas))
    print(f"\nKVLCC2 35° turning circle, {duration:g} s, run, logged and its indices computed: "
          "our compiled RK4 against scipy solve_ivp RK45 on the Python MMG formulas (shipmmg's "
          "method); the tactical diameter against a tight-tolerance solve_ivp run "
          f"({ref:.4f} m)\n")  # fmt: skip
    print("| run | time (ms) | rhs evaluations | tactical diameter error | speed-up | vs solve_ivp "
          "on compiled formulas | target |")
    print("|---|---|---|---|---|---|---|")
    print(f"| solve_ivp RK45, default tolerances, Python formulas | {1e3 * t_ivp:.2f} | {nfev} | "
          f"{td_ivp / ref - 1:+.1e} | 1× | {t_fast / t_ivp:.2f}× | baseline |")
    print(f"| solve_ivp RK45, default tolerances, compiled formulas | {1e3 * t_fast:.2f} | {nfev} | "
          f"{td_ivp / ref - 1:+.1e} | {t_ivp / t_fast:.1f}× | 1× | baseline |")
    for step in (0.05, 0.5):
        turning_circle(ship, 35, duration=10 * step, dt=step)  # compile or load the caches
        ours = best_of(lambda h=step: turning_circle(ship, 35, duration=duration, dt=h))
        td = turning_circle(ship, 35, duration=duration, dt=step).indices["tactical_diameter"]
        print(f"| shipid compiled RK4, Δt {step} s | {1e3 * ours:.2f} | "
              f"{4 * round(duration / step)} | {td / ref - 1:+.1e} | {t_ivp / ours:.1f}× | "
              f"{t_fast / ours:.1f}× | ≥ 3× |")


if __name__ == "__main__":
    main()
    closed_loop()
    reference_ships()
    mmg_ships()
    corrected_tanker()
    heading_autopilot()
    kvlcc2_against_solve_ivp()
