"""What a propeller turned astern pushes, for models of logs that never turn it so.

A fixed-pitch propeller reversed pushes less than ahead at the same |n|: its sections meet the
water trailing edge first, and its race runs forward along the hull. Logs that never reverse the
propeller cannot measure how much less, so a model of them is given it as a prior
(``shipid.dynamics.astern``, the factor ``propeller(k)`` of ``shipid.dynamics.terms``); kept
apart from both so that the command line reads it without importing either.
"""

# The thrust astern over the thrust ahead at the same |n|. Measured on the Esso Osaka
# (``benchmarks/study_astern_thrust.py``): the ratio the free runs of three of its four random
# runs choose for the model of its nine zig-zags, judged on the fourth, is 0.5 or 0.6 in each
# fold.
ASTERN_THRUST_RATIO = 0.5


# The surge's thrust: its terms in n² (and ``propeller(k)``, pos(n)² written for going astern)
# and its fall with the advance (``shipid.identification.physics.SIGN_RULES``).
THRUST_TERMS = ("pos(n)^2", "|n|*n")
ADVANCE_TERMS = ("u*|n|", "u*pos(n)")


def thrust_on_the_advance(model) -> tuple[str, float, list[tuple[str, float]]] | None:
    """(advance term, its coefficient, the thrust terms in n² and theirs) where ``model``'s
    surge carries its thrust on an advance term of the wrong sign (u·|n| > 0, which the thrust's
    fall with the advance forbids) against no positive term in n²; else None. u·|n| is even in
    n: it pushes ahead whichever way the propeller turns, so such a model goes astern from rest
    and coasts in a crash stop. Five of the nine sets of eight Esso zig-zag files take such a
    surge (u·|n| +0.012 to +0.014 against n⁺² −7e-5 to −1e-4; ``benchmarks/README.md``, *Leave
    one zig-zag file out*). A hybrid model's are its physical model's terms."""
    physical = getattr(model, "physical", model)
    surge = getattr(physical, "coefficients", {}).get("u") or {}
    advance = [(t, surge[t]) for t in ADVANCE_TERMS if surge.get(t, 0.0) > 0]
    thrust = [(t, c) for t, c in surge.items()
              if c != 0 and (t in THRUST_TERMS or t.startswith("propeller("))]  # fmt: skip
    if not advance or any(c > 0 for _, c in thrust):
        return None
    return advance[0][0], advance[0][1], thrust


def thrust_on_the_advance_note(model) -> tuple[str, str] | None:
    """Where ``thrust_on_the_advance`` finds ``model``'s thrust riding on the advance: (why, in
    words: 'its thrust rides on the advance, u |n| at +0.0139 against pos(n)² at -8.05e-05, a
    term even in n ...', and the bound that holds it, as the command line takes it); else None.
    The from-rest warning and the crash stop's note give both."""
    found = thrust_on_the_advance(model)
    if found is None:
        return None
    from shipid.dynamics.terms import parse_term

    term, value, thrust = found
    against = (" against " + ", ".join(f"{parse_term(t).display()} at {c:.3g}" for t, c in thrust)
               if thrust else " with no thrust in n²")  # fmt: skip
    return (f"its thrust rides on the advance, {parse_term(term).display()} at {value:+.3g}"
            f"{against}, a term even in n that pushes ahead whichever way the propeller turns",
            f"--bound 'u: {term} <= 0' (or --constraints signs) holds it to the thrust's fall "
            "with the advance")
