"""Regressor terms as an open algebra: a term is a product of factors of the log's signals.

Every model of this package is linear in its parameters: each acceleration is Σ θⱼ·φⱼ over terms
φⱼ (paper eq. 12 for the Blanke terms). A term is written as text and parsed once::

    "|u|u"   "v*r"   "u^2*delta"   "|n|*n*delta"   "delta^3"   "U^2*sin(2*wind_angle)"   "1"

Signals (``SIGNALS``): the states u, v [m/s], r [rad/s]; derived U = √(u² + v²) [m/s] and the
drift angle beta = atan2(−v, u) [rad]; the inputs delta [rad], n [rps], thrust [N] (alias T); the
relative wind wind_speed [m/s] (alias U_A) and wind_angle [rad] (alias gamma_A).

Factors: ``x`` or ``x^p`` (integer p ≥ 1), ``|x|`` or ``|x|^p``, ``pos(x)`` = max(x, 0) and
``neg(x)`` = max(−x, 0) (four-quadrant propeller and rudder terms), and ``sin(k*a)``, ``cos(k*a)``
of an angle signal a (beta, delta, wind_angle) with an integer k ≥ 1, each with an optional power.
The hull's cross-flow drag (``crossflow_sway(L)``, ``crossflow_yaw(L)``, L the hull's length in
metres) is a factor of v and r together: the sway force and yaw moment of a drag on each section
that goes as |w|w, w = v + x r its lateral velocity at x along the hull (Hooft 1994; Fossen 2011,
sec. 6.7), one coefficient for what ``|v|v``, ``|v|r`` and ``|r|r`` split among them::

    crossflow_sway(L) = 1/L ∫ |w| w dx,     crossflow_yaw(L) = 1/L² ∫ x |w| w dx,   x ∈ [−L/2, L/2]

in closed form (``crossflow``). Where a zig-zag's small drift leaves the split of |v|v and |v|r
free, the integral carries the drag to a turn's drift and yaw rate by the hull's geometry.
A propeller's thrust at a ratio astern (``propeller(k)``, k the ratio) is a factor of n: n² ahead
(n ≥ 0), −k·n² astern, the thrust of a fixed-pitch propeller at bollard in the four quadrants
reduced to one number, which a fit to logs that never reverse the propeller cannot give
(``shipid.dynamics.astern``)::

    propeller(k) = n²  (n ≥ 0),   −k n²  (n < 0)

The rudder's normal force (``rudder_normal(a c g x)``, four numbers) is a factor of u, v, r, n and δ
together: one inflow to the rudder, shared by the three equations (the MMG standard method's,
Yasukawa & Yoshimura 2015, with a quadratic race), whose coefficients the fit leaves free::

    rudder_normal = U_R² sin α_R,   U_R² = u_R² + v_R²,   α_R = δ − atan2(v_R, u_R),
    u_R² = a u² + c n⁺²,   v_R = −g (v + x r)

a = (1 − w_R)² the wake's, c [m²] the propeller race's share (n⁺ = max(n, 0): an ahead
propeller's), g the hull's flow straightening γ_R, signed as positive rudder turns (+ to
starboard, − to port), x [m] the rudder's effective position (aft: < 0). The terms
``rudder_normal(...)*sin(delta)`` (surge: its drag) and ``rudder_normal(...)*cos(delta)`` (sway,
yaw) are the MMG rudder forces (``rudder_normal``).
Factors are joined by ``*`` or written side by side (``vr``, ``|u|u``: the names of the original
Blanke terms parse unchanged). Like factors merge (``u*u`` is ``u^2``), factors are put in one
order, so each term has one canonical text (``Term.text``), which model files store.

Evaluation is one vectorised NumPy path (``term_matrix``) and one compiled path (``TermCode``, the
factor table the simulator's kernel interprets), for any set of terms.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np

from shipid.errors import ShipidError

# Signal order is the compiled kernel's signal vector: append only.
SIGNALS: tuple[str, ...] = ("u", "v", "r", "U", "beta", "delta", "n", "thrust", "wind_speed",
                            "wind_angle")  # fmt: skip
SIGNAL_INDEX = {s: i for i, s in enumerate(SIGNALS)}
STATE_SIGNALS = ("u", "v", "r")
DERIVED_SIGNALS = ("U", "beta")
# Inputs: log columns that drive a model (the rudder and the rest).
INPUT_SIGNALS = ("delta", "n", "thrust", "wind_speed", "wind_angle")
ANGLE_SIGNALS = ("beta", "delta", "wind_angle")
ALIASES = {"T": "thrust", "U_A": "wind_speed", "gamma_A": "wind_angle"}
DISPLAY = {"delta": "δ", "beta": "β", "thrust": "T", "wind_speed": "U_A", "wind_angle": "γ_A"}
# Op codes are the compiled kernel's (``kernel._factor``): append only.
OPS = ("pow", "abs", "pos", "neg", "sin", "cos", "crossflow_sway", "crossflow_yaw",
       "rudder_normal", "propeller")  # fmt: skip
OP_CODE = {op: i for i, op in enumerate(OPS)}
FUNCTIONS = ("abs", "pos", "neg", "sin", "cos")
# Factors of v and r together, with the hull's length [m] as their argument. The compiled kernel
# evaluates them once per state into the signal buffer's slots after ``SIGNALS`` (sway, yaw): in
# its factor table they are plain signals there, k the length.
CROSSFLOW = ("crossflow_sway", "crossflow_yaw")
CROSSFLOW_SLOTS = (len(SIGNALS), len(SIGNALS) + 1)
# The rudder's normal force, a factor of u, v, r, n and δ with its inflow's four parameters
# (``Factor.params``); the kernel evaluates it once per state into the slot after the cross-flow's.
RUDDER = "rudder_normal"
RUDDER_SLOT = len(SIGNALS) + 2
RUDDER_SIGNALS = ("u", "v", "r", "delta", "n")
RUDDER_PARAMS = ("a", "c", "g", "x")
# A propeller's thrust, n² ahead and −k·n² astern (k its astern ratio): a factor of n.
PROPELLER = "propeller"
# Order of factors in a term's text: states, derived, propulsion, wind, the rudder last (u² δ).
FACTOR_ORDER = {s: i for i, s in enumerate(("u", "v", "r", "U", "beta", "n", "thrust",
                                            "wind_speed", "wind_angle", "delta"))}  # fmt: skip
SUPERSCRIPT = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")
MAX_POWER = 9

_NAMES = sorted([*SIGNALS, *ALIASES], key=len, reverse=True)


# Factors and terms are immutable and asked for their names and signals in every fit and
# simulation of a search (1.3 million times in five test files): computed once each
# (``cached_property`` writes the instance's __dict__, which a frozen dataclass allows).
@dataclass(frozen=True, order=True)
class Factor:
    """op(k·signal)^power, op one of ``OPS`` (k only for sin/cos); for a cross-flow factor
    (signal v, r read beside it) k is the hull's length [m]; the rudder's normal force (signal
    δ, u, v, r, n read beside it) has its inflow's parameters (a, c, g, x) in ``params``."""

    signal: int  # index into SIGNALS
    op: int  # index into OPS
    k: float = 1
    power: int = 1
    params: tuple[float, ...] = ()

    @cached_property
    def rudder(self) -> bool:
        """Whether this is the rudder's normal force (of u, v, r, n and δ, with ``params``)."""
        return OPS[self.op] == RUDDER

    @cached_property
    def crossflow(self) -> bool:
        """Whether this is a cross-flow factor (of v and r, k the hull's length)."""
        return OPS[self.op] in CROSSFLOW

    @cached_property
    def propeller(self) -> bool:
        """Whether this is a propeller's thrust at a ratio astern (of n, k the ratio)."""
        return OPS[self.op] == PROPELLER

    @cached_property
    def name(self) -> str:
        """The signal's name."""
        return SIGNALS[self.signal]

    @cached_property
    def text(self) -> str:
        """The factor's canonical text (``|u|``, ``delta^2``, ``sin(2*beta)``)."""
        op, name = OPS[self.op], self.name
        if op in CROSSFLOW:
            return f"{op}({self.k:.12g})"
        if op == RUDDER:
            return f"{op}({' '.join(f'{p:.12g}' for p in self.params)})"
        if op == PROPELLER:
            return f"{op}({self.k:.12g})"
        if op == "pow":
            base = name
        elif op == "abs":
            base = f"|{name}|"
        elif op in ("pos", "neg"):
            base = f"{op}({name})"
        else:
            base = f"{op}({self.k}*{name})" if self.k != 1 else f"{op}({name})"
        return base if self.power == 1 else f"{base}^{self.power}"

    def display(self) -> str:
        """The factor as printed in equations (``|u|``, ``δ²``, ``sin(2β)``)."""
        op, name = OPS[self.op], DISPLAY.get(self.name, self.name)
        if op in CROSSFLOW:
            return f"{'Y' if op == 'crossflow_sway' else 'N'}_cf(v, r; {self.k:.12g} m)"
        if op == RUDDER:
            a, c, g, x = self.params
            return f"F_R(a {a:.4g}, c {c:.4g} m², γ {g:.4g}, x {x:.4g} m)"
        if op == PROPELLER:
            return f"n²(astern ×{self.k:.4g})"
        sup = str(self.power).translate(SUPERSCRIPT) if self.power != 1 else ""
        if op == "pow":
            return f"{name}{sup}"
        if op == "abs":
            return f"|{name}|{sup}"
        if op in ("pos", "neg"):
            return f"{op}({name}){sup}"
        arg = f"{self.k}{name}" if self.k != 1 else name
        return f"{op}{sup}({arg})" if sup else f"{op}({arg})"

    def values(self, x: np.ndarray, r: np.ndarray | None = None,
               signals: Mapping[str, np.ndarray] | None = None) -> np.ndarray:  # fmt: skip
        """The factor's values for the signal's values ``x`` (and the yaw rate ``r``, which a
        cross-flow factor reads beside v; the rudder's normal force reads u, v, r, δ and n
        from ``signals``)."""
        op = OPS[self.op]
        if op in CROSSFLOW:
            sway, yaw = crossflow(x, r, self.k)
            return sway if op == "crossflow_sway" else yaw
        if op == RUDDER:
            return rudder_normal(*(signals[s] for s in RUDDER_SIGNALS), *self.params)
        if op == PROPELLER:
            return np.where(x >= 0.0, 1.0, -self.k) * x * x
        if op == "pow":
            base = x
        elif op == "abs":
            base = np.abs(x)
        elif op == "pos":
            base = np.maximum(x, 0.0)
        elif op == "neg":
            base = np.maximum(-x, 0.0)
        elif op == "sin":
            base = np.sin(self.k * x)
        else:
            base = np.cos(self.k * x)
        return base if self.power == 1 else base**self.power


@dataclass(frozen=True)
class Term:
    """A product of factors; no factors is the constant term "1"."""

    factors: tuple[Factor, ...] = ()

    @cached_property
    def text(self) -> str:
        """The term's canonical text (what model files store)."""
        return "*".join(f.text for f in self.factors) if self.factors else "1"

    @cached_property
    def signals(self) -> tuple[str, ...]:
        """The signals the term uses, in signal order."""
        names = {f.name for f in self.factors} | ({"v", "r"} if self.crossflow else set())
        if self.rudder:
            names |= set(RUDDER_SIGNALS)
        return tuple(sorted(names, key=SIGNAL_INDEX.get))

    @cached_property
    def crossflow(self) -> bool:
        """Whether the term has a cross-flow factor (of v and r, with the hull's length)."""
        return any(f.crossflow for f in self.factors)

    @cached_property
    def rudder(self) -> bool:
        """Whether the term has the rudder's normal force (``rudder_normal``)."""
        return any(f.rudder for f in self.factors)

    @cached_property
    def inputs(self) -> tuple[str, ...]:
        """Log columns besides u, v, r that the term needs (e.g. 'n', 'wind_speed')."""
        return tuple(s for s in self.signals if s in INPUT_SIGNALS and s != "delta")

    def display(self) -> str:
        """As printed in equations, in the paper's style: ``|u|u``, ``v r``, ``u² δ``."""
        parts: list[str] = []
        for i, f in enumerate(self.factors):
            glue = ""
            if i:
                prev = self.factors[i - 1]
                # |u|u, |v|v, |n|n: an absolute value followed by its own signal reads as one.
                glue = "" if (OPS[prev.op] == "abs" and OPS[f.op] == "pow" and prev.power == 1
                              and prev.signal == f.signal) else " "  # fmt: skip
            parts.append(glue + f.display())
        return "".join(parts)

    def degree_in(self, signal: str) -> int:
        """Total power of ``signal`` in the term (abs/pos/neg count; sin/cos do not). A
        cross-flow factor counts 2 in v: |w|w, w = v + x r, is a speed squared (its r comes with
        a length), which is how it scales (prime form, Froude, advance-ratio similarity). The
        rudder's normal force, the square of its inflow speed, counts 2 in u."""
        i = SIGNAL_INDEX[signal]
        rudder = 2 * sum(f.power for f in self.factors if f.rudder) if signal == "u" else 0
        return rudder + sum(2 * f.power if f.crossflow or f.propeller else f.power
                            for f in self.factors
                            if f.signal == i and OPS[f.op] not in ("sin", "cos", RUDDER))

    def __str__(self) -> str:
        return self.text


# ---------------------------------------------------------------------------- parsing
_TOKEN = re.compile(r"\s*(?:(?P<num>\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)|(?P<name>[A-Za-z_][A-Za-z_0-9]*)"
                    r"|(?P<sym>[|*^()-]))")


def _tokens(text: str) -> list[tuple[str, str]]:
    out, pos = [], 0
    text = text.strip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            hint = (f" ({RUDDER}(a c g x) takes its numbers apart by spaces: a structure's text "
                    "lists terms apart by commas)" if text[pos] == "," and RUDDER in text else "")
            raise ShipidError(f"term {text!r}: unexpected {text[pos:pos + 1]!r} at position "
                              f"{pos + 1}{hint}")  # fmt: skip
        pos = m.end()
        kind = m.lastgroup
        value = m.group(kind)
        if kind == "name" and value not in (*FUNCTIONS, *CROSSFLOW, RUDDER, PROPELLER):
            out.extend(("name", n) for n in _split_names(value, text))
        else:
            out.append((kind, value))
    return out


def _split_names(word: str, text: str) -> list[str]:
    """'vr' → ['v', 'r'], 'un' → ['u', 'n'], 'delta' → ['delta']: longest known names first."""
    names, i = [], 0
    while i < len(word):
        for n in _NAMES:
            if word.startswith(n, i):
                names.append(n)
                i += len(n)
                break
        else:
            known = ", ".join(SIGNALS) + "; aliases " + ", ".join(ALIASES)
            # The word too where its start read as signals ('nothing': 'othing' after n).
            where = f" in {word!r}" if i else ""
            raise ShipidError(f"term {text!r}: unknown signal {word[i:]!r}{where} (signals: "
                              f"{known})")  # fmt: skip
    return names


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.toks = _tokens(text)
        self.i = 0

    def error(self, what: str) -> ShipidError:
        return ShipidError(f"term {self.text!r}: {what}")

    def peek(self) -> tuple[str, str] | None:
        return self.toks[self.i] if self.i < len(self.toks) else None

    def take(self, kind: str, value: str | None = None) -> str:
        tok = self.peek()
        if tok is None or tok[0] != kind or (value is not None and tok[1] != value):
            got = "the end" if tok is None else repr(tok[1])
            raise self.error(f"expected {value or kind}, got {got}")
        self.i += 1
        return tok[1]

    def signal(self) -> int:
        name = self.take("name")
        return SIGNAL_INDEX[ALIASES.get(name, name)]

    def integer(self) -> int:
        text = self.take("num")
        if not text.isdigit():
            raise self.error(f"expected a whole number, got {text!r}")
        return int(text)

    def power(self) -> int:
        tok = self.peek()
        if tok == ("sym", "^"):
            self.i += 1
            p = self.integer()
            if not 1 <= p <= MAX_POWER:
                raise self.error(f"power {p} out of range 1–{MAX_POWER}")
            return p
        return 1

    def number(self) -> float:
        """A real number, signed."""
        sign = 1.0
        if self.peek() == ("sym", "-"):
            self.i += 1
            sign = -1.0
        tok = self.peek()
        if tok is None or tok[0] != "num":
            raise self.error(f"expected a number, got {'the end' if tok is None else repr(tok[1])}")
        self.i += 1
        return sign * float(tok[1])

    def rudder(self) -> Factor:
        usage = (f"{RUDDER}(a c g x) takes the inflow's four numbers apart by spaces: a = "
                 f"(1 − w_R)², c [m²] the race's share, g the flow straightening γ_R, x [m] the "
                 f"rudder's position")  # fmt: skip
        self.take("name", RUDDER)
        self.take("sym", "(")
        params = []
        for _ in RUDDER_PARAMS:  # apart by spaces: structures' texts list terms apart by commas
            try:
                params.append(self.number())
            except ShipidError:
                raise self.error(usage) from None
        if self.peek() != ("sym", ")"):
            raise self.error(usage)
        self.i += 1
        problem = inflow_problem(*params)
        if problem:
            raise self.error(f"{RUDDER}'s {problem}")
        if self.peek() == ("sym", "^"):
            raise self.error(f"{RUDDER}(a c g x) takes no power")
        return Factor(SIGNAL_INDEX["delta"], OP_CODE[RUDDER], 1, 1, tuple(params))

    def propeller(self) -> Factor:
        usage = (f"{PROPELLER}(k) takes the ratio k ≥ 0 of its thrust astern to ahead at the "
                 f"same |n|, e.g. {PROPELLER}(0.5)")  # fmt: skip
        self.take("name", PROPELLER)
        self.take("sym", "(")
        try:
            ratio = self.number()
        except ShipidError:
            raise self.error(usage) from None
        if self.peek() != ("sym", ")") or not (math.isfinite(ratio) and ratio >= 0):
            raise self.error(usage)
        self.i += 1
        if self.peek() == ("sym", "^"):
            raise self.error(f"{PROPELLER}(k) takes no power")
        return Factor(SIGNAL_INDEX["n"], OP_CODE[PROPELLER], ratio, 1)

    def factor(self) -> Factor:
        tok = self.peek()
        if tok is not None and tok == ("name", RUDDER):
            return self.rudder()
        if tok is not None and tok == ("name", PROPELLER):
            return self.propeller()
        if tok is not None and tok[0] == "name" and tok[1] in CROSSFLOW:
            fn = self.take("name")
            self.take("sym", "(")
            text = self.take("num") if self.peek() and self.peek()[0] == "num" else None
            if text is None or self.peek() != ("sym", ")"):
                raise self.error(f"{fn}(L) takes the hull's length L in metres, e.g. {fn}(3)")
            self.take("sym", ")")
            length = float(text)
            if not (math.isfinite(length) and length > 0):
                raise self.error(f"{fn}'s hull length must be > 0 m, got {text}")
            if self.peek() == ("sym", "^"):
                raise self.error(f"{fn}(L) takes no power")
            return Factor(SIGNAL_INDEX["v"], OP_CODE[fn], length, 1)
        if tok == ("sym", "|"):
            self.i += 1
            sig = self.signal()
            self.take("sym", "|")
            return Factor(sig, OP_CODE["abs"], 1, self.power())
        if tok is not None and tok[0] == "name" and tok[1] in FUNCTIONS:
            fn = self.take("name")
            self.take("sym", "(")
            k = 1
            if self.peek() is not None and self.peek()[0] == "num":
                k = self.integer()
                self.take("sym", "*")
                if fn not in ("sin", "cos") or not 1 <= k <= MAX_POWER:
                    raise self.error(f"a multiple k*x is allowed in sin/cos only, k in 1–{MAX_POWER}")
            sig = self.signal()
            self.take("sym", ")")
            if fn in ("sin", "cos") and SIGNALS[sig] not in ANGLE_SIGNALS:
                raise self.error(f"{fn}() takes an angle signal ({', '.join(ANGLE_SIGNALS)}), "
                                 f"not {SIGNALS[sig]!r}")  # fmt: skip
            return Factor(sig, OP_CODE[fn], k, self.power())
        if tok is not None and tok[0] == "name":
            return Factor(self.signal(), OP_CODE["pow"], 1, self.power())
        got = "the end" if tok is None else repr(tok[1])
        raise self.error(f"expected a signal, |signal| or a function, got {got}")

    def term(self) -> Term:
        if self.toks == [("num", "1")]:
            return Term(())
        if not self.toks:
            raise self.error("empty term")
        factors = [self.factor()]
        while self.peek() is not None:
            if self.peek() == ("sym", "*"):
                self.i += 1
            factors.append(self.factor())
        return _canonical(factors, self)


def _canonical(factors: list[Factor], parser: _Parser) -> Term:
    merged: dict[tuple[int, int, float, tuple[float, ...]], int] = {}
    for f in factors:
        key = (f.signal, f.op, f.k, f.params)
        merged[key] = merged.get(key, 0) + f.power
    if sum(1 for key in merged if OPS[key[1]] == RUDDER) > 1:
        raise parser.error(f"{RUDDER} appears twice: a term has it once")
    out = []
    for (sig, op, k, params), p in sorted(merged.items()):
        if OPS[op] in (*CROSSFLOW, RUDDER, PROPELLER) and p > 1:
            raise parser.error(f"{OPS[op]} appears twice: a term has it once")
        if p > MAX_POWER:
            raise parser.error(f"power {p} of {SIGNALS[sig]} out of range 1–{MAX_POWER}")
        out.append(Factor(sig, op, k, p, params))
    # |x| before x: reads as |u|u; otherwise signal order.
    out.sort(key=lambda f: (FACTOR_ORDER[f.name],
                            0 if OPS[f.op] == "abs" else 1 if OPS[f.op] == "pow" else 2, f.op, f.k))
    return Term(tuple(out))


@lru_cache(maxsize=4096)
def parse_term(text: str) -> Term:
    """The term of ``text`` (see the module docstring), or a one-line error naming the problem."""
    if not isinstance(text, str):
        raise ShipidError(f"a term must be text, got {type(text).__name__} {text!r}")
    return _Parser(text).term()


def canonical(text: str) -> str:
    """The canonical text of a term: ``canonical("vr") == "v*r"``."""
    return parse_term(text).text


def parse_terms(texts: Iterable[str], where: str = "") -> tuple[Term, ...]:
    """Parse several terms; duplicates (after canonicalisation) are an error."""
    texts = list(texts)
    terms = tuple(parse_term(t) for t in texts)
    seen: dict[str, str] = {}
    for raw, term in zip(texts, terms, strict=True):
        if term.text in seen:
            at = f" in {where}" if where else ""
            raise ShipidError(f"terms {seen[term.text]!r} and {raw!r} are the same term{at}")
        seen[term.text] = raw
    return terms


def required_inputs(terms: Iterable[str | Term]) -> tuple[str, ...]:
    """Log columns besides t, u, v, r, delta that the terms need, in signal order."""
    need = set()
    for t in terms:
        need.update((parse_term(t) if isinstance(t, str) else t).inputs)
    return tuple(s for s in INPUT_SIGNALS if s in need)


# ---------------------------------------------------------------------------- evaluation
def signal_values(u, v, r, inputs: Mapping[str, np.ndarray] | None = None,
                  needed: Iterable[str] = SIGNALS) -> dict[str, np.ndarray]:  # fmt: skip
    """Arrays of the signals a term set needs, from states and input columns (absent: error)."""
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    r = np.asarray(r, dtype=float)
    inputs = inputs or {}
    out: dict[str, np.ndarray] = {"u": u, "v": v, "r": r}
    needed = set(needed)
    if "U" in needed:
        out["U"] = np.hypot(u, v)
    if "beta" in needed:
        out["beta"] = np.arctan2(-v, u)
    for s in INPUT_SIGNALS:
        if s in needed:
            if s not in inputs or inputs[s] is None:
                raise ShipidError(f"the model needs the input {s!r}, which was not given")
            out[s] = np.broadcast_to(np.asarray(inputs[s], dtype=float), u.shape)
    return out


def term_matrix(terms: Sequence[str | Term], u, v, r, inputs: Mapping[str, np.ndarray] | None = None
                ) -> np.ndarray:  # fmt: skip
    """(n, len(terms)) matrix of regressor values."""
    parsed = [parse_term(t) if isinstance(t, str) else t for t in terms]
    needed = {s for t in parsed for s in t.signals}
    sig = {k: np.atleast_1d(x) for k, x in signal_values(u, v, r, inputs, needed).items()}
    n = sig["u"].shape[0]
    out = np.empty((n, len(parsed)))
    for j, term in enumerate(parsed):
        col = np.ones(n)
        for f in term.factors:
            col = col * f.values(sig[f.name], sig["r"], sig)
        out[:, j] = col
    return out


TINY = 1e-150  # [m/s] the flow at the hull's ends below which the cross-flow drag is 0


def crossflow(v, r, length: float) -> tuple[np.ndarray, np.ndarray]:
    """The cross-flow factors (1/L ∫ |w|w dx, 1/L² ∫ x |w|w dx over x ∈ [−L/2, L/2], w = v + x r)
    at arrays of v [m/s], r [rad/s], in closed form: where w keeps its sign along the hull
    (|v| ≥ |r| L/2), |w|w = ±w² integrates to ±L (v² + r²L²/12) and ±r v L³/6; where it
    changes sign, ∫|w|w dx = [|w|³/3r] and ∫x|w|w dx = [(w|w|³/4 − v|w|³/3)/r²] between the ends
    (r ≠ 0 there). The compiled kernel's ``shipid.dynamics.kernel.crossflow`` is the same."""
    v, r = np.broadcast_arrays(np.asarray(v, dtype=float), np.asarray(r, dtype=float))
    h = 0.5 * length
    # Below TINY the sign-changing form's 1/r² would underflow to 0/0; the drag there is
    # smaller than any double anyway, and the same-sign form gives it (as 0).
    same = (np.abs(v) >= np.abs(r) * h) | (np.abs(r) * h < TINY)
    sign = np.sign(v)
    sway = np.where(same, sign * (v * v + r * r * h * h / 3.0), 0.0)
    yaw = np.where(same, sign * r * v * h / 3.0, 0.0)
    if not same.all():
        a, b = v[~same], r[~same]
        s2, s1 = a + b * h, a - b * h
        c2, c1 = np.abs(s2) ** 3, np.abs(s1) ** 3
        sway[~same] = (c2 - c1) / (3.0 * b) / length
        yaw[~same] = ((s2 * c2 - s1 * c1) / 4.0 - a * (c2 - c1) / 3.0) / (b * b) / length**2
    return sway, yaw


def inflow_problem(a: float, c: float, g: float, x: float) -> str | None:
    """What is wrong with a rudder inflow (a, c, g, x) (``rudder_normal``), or None: the one
    check of a term's text and of ``shipid.dynamics.rudder.RudderInflow``."""
    for name, value in zip(RUDDER_PARAMS, (a, c, g, x), strict=True):
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            return f"{name} must be a finite number, got {value!r}"
    if not a > 0:
        return f"a = (1 − w_R)² must be > 0, got {a:g}"
    if not c >= 0:
        return f"race share c must be ≥ 0 m², got {c:g}"
    return None


def rudder_normal_angle(term: str | Term) -> str | None:
    """'sin' for the rudder's drag F_N sin δ, 'cos' for its side force F_N cos δ (the terms
    ``--rudder-normal`` writes, of any inflow), None for any other term."""
    factors = (parse_term(term) if isinstance(term, str) else term).factors
    if len(factors) != 2 or not any(f.rudder for f in factors):
        return None
    angle = next(f for f in factors if not f.rudder)
    if angle.name != "delta" or angle.k != 1 or angle.power != 1:
        return None
    return OPS[angle.op] if OPS[angle.op] in ("sin", "cos") else None


def rudder_normal(u, v, r, delta, n, a: float, c: float, g: float, x: float) -> np.ndarray:
    """The rudder's normal force factor U_R² sin α_R (see the module docstring) at arrays of u,
    v [m/s], r [rad/s], δ [rad], n [rps]: u_R = √(a u² + c n⁺²), v_R = −g (v + x r),
    α_R = δ − atan2(v_R, u_R). The compiled kernel's ``shipid.dynamics.kernel.rudder_normal`` is
    the same."""
    u, v, r, delta, n = np.broadcast_arrays(*(np.asarray(s, dtype=float)
                                              for s in (u, v, r, delta, n)))  # fmt: skip
    ahead = np.maximum(n, 0.0)
    u_r = np.sqrt(a * u * u + c * ahead * ahead)
    v_r = -g * (v + x * r)
    return (u_r * u_r + v_r * v_r) * np.sin(delta - np.arctan2(v_r, u_r))


@dataclass(frozen=True)
class TermCode:
    """A term set as the factor table the compiled kernel interprets.

    Term j is the product of factors ``start[j]:start[j+1]``; factor i is
    op[i](k[i]·s[signal[i]])^power[i] with s the signal vector in ``SIGNALS`` order.
    """

    texts: tuple[str, ...]
    start: np.ndarray  # (n_terms + 1,) int64
    signal: np.ndarray  # (n_factors,) int64
    op: np.ndarray  # (n_factors,) int64
    k: np.ndarray  # (n_factors,) float64
    power: np.ndarray  # (n_factors,) int64
    uses_derived: bool  # U or beta appear (computed only when needed)
    # The rudder's normal force's inflow (a, c, g, x); a = 0: the term set has none.
    rudder: np.ndarray = field(default_factory=lambda: np.zeros(len(RUDDER_PARAMS)))

    @property
    def n_terms(self) -> int:
        """Number of terms in the table."""
        return len(self.texts)

    @cached_property
    def _kernel_table(self) -> tuple:
        # Each distinct factor once, and each term as the indices of its factors among them,
        # padded to the longest term with the index of a factor that reads 1 (the kernel's
        # last): the interpreter evaluates every factor once per evaluation and multiplies
        # rows of equal length, which ran its closed loops 1.4 times as fast as reading each
        # term's own factors in a loop of its own length (the same products, in the same
        # order, so the same numbers to the bit).
        keys = list(zip(self.signal.tolist(), self.op.tolist(), self.k.tolist(),
                        self.power.tolist(), strict=True))  # fmt: skip
        index: dict[tuple, int] = {}
        for key in keys:
            index.setdefault(key, len(index))
        lengths = np.diff(self.start)
        rows = np.full((self.n_terms, int(lengths.max(initial=0))), len(index), dtype=np.int64)
        for j in range(self.n_terms):
            for q, f in enumerate(range(int(self.start[j]), int(self.start[j + 1]))):
                rows[j, q] = index[keys[f]]
        unique = list(index)
        columns = [np.array([u[c] for u in unique], dtype=dtype)
                   for c, dtype in enumerate((np.int64, np.int64, np.float64, np.int64))]  # fmt: skip
        return (rows, *columns)

    def arrays(self) -> tuple:
        """(term factors (n_terms, longest term), and the distinct factors' signal, op, k and
        power, rudder): the arrays the compiled kernel takes. Row j holds term j's factors as
        indices into the distinct ones, padded with their number (a factor that reads 1)."""
        return (*self._kernel_table, self.rudder)


def term_code(terms: Sequence[str | Term]) -> TermCode:
    """The factor table (``TermCode``) of a term set, for the compiled kernel."""
    parsed = [parse_term(t) if isinstance(t, str) else t for t in terms]
    start, sig, op, k, power = [0], [], [], [], []
    lengths, inflows = set(), set()
    for t in parsed:
        for f in t.factors:
            if f.crossflow:  # its value's slot, read as it is (the kernel fills it per state)
                sig.append(CROSSFLOW_SLOTS[CROSSFLOW.index(OPS[f.op])])
                op.append(OP_CODE["pow"])
                lengths.add(f.k)
            elif f.rudder:  # likewise
                sig.append(RUDDER_SLOT)
                op.append(OP_CODE["pow"])
                inflows.add(f.params)
            else:
                sig.append(f.signal)
                op.append(f.op)
            k.append(float(f.k))
            power.append(f.power)
        start.append(len(sig))
    if len(lengths) > 1:
        raise ShipidError(f"the cross-flow terms of one model take one hull length, got "
                          f"{', '.join(f'{x:g}' for x in sorted(lengths))} m")  # fmt: skip
    if len(inflows) > 1:
        raise ShipidError(f"the rudder terms of one model take one inflow, got "
                          f"{', '.join(RUDDER + str(p) for p in sorted(inflows))}")  # fmt: skip
    derived = any(s < len(SIGNALS) and SIGNALS[s] in DERIVED_SIGNALS for s in sig)
    rudder = np.array(next(iter(inflows)) if inflows else [0.0] * len(RUDDER_PARAMS))
    return TermCode(tuple(t.text for t in parsed), np.array(start, dtype=np.int64),
                    np.array(sig, dtype=np.int64), np.array(op, dtype=np.int64),
                    np.array(k, dtype=np.float64), np.array(power, dtype=np.int64), derived,
                    rudder)
