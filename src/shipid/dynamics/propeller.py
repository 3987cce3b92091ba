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
