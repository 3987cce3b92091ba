"""KVLCC2 tanker at model scale (L7, 1/45.7), MMG standard method (Yasukawa & Yoshimura 2015).

reference-ships.md §2 with x′P = −0.48, the wake formula of pitfall 1, midship sway velocity
throughout (pitfall 3) and dimensional lever arms (pitfall 4). Propeller revolutions are trimmed
numerically for the SIMMAN approach speed 1.179 m/s (≈ 11.85 rps). Positive δ turns to starboard.
The formula is ``shipid.vessels.mmg``'s, which a ship's own MMG file runs too.
"""

from __future__ import annotations

import math
from functools import lru_cache

from shipid.dynamics.steering import SteeringMachine

from .mmg import MMGDynamics, pack, trimmed_rps
from .mmg import accelerations as mmg_accelerations
from .vessel import Vessel

RHO = 1025.0
L, B, D_DRAUGHT, VOLUME, XG = 7.00, 1.27, 0.46, 3.27, 0.25
DP, HR, AR = 0.216, 0.345, 0.0539
APPROACH_SPEED = 1.179
RUDDER_RATE_DEG = 15.8
SCALE = 45.7

MX, MY, JZ = 0.022, 0.223, 0.011
R0 = 0.022
XVV, XVR, XRR, XVVVV = -0.040, 0.002, 0.011, 0.771
YV, YR, YVVV, YVVR, YVRR, YRRR = -0.315, 0.083, -1.607, 0.379, -0.391, 0.008
NV, NR, NVVV, NVVR, NVRR, NRRR = -0.137, -0.049, -0.030, -0.294, 0.055, -0.013
TP, WP0, K0, K1, K2, XP_PRIME, C1 = 0.220, 0.40, 0.2931, -0.2753, -0.1385, -0.48, 2.0
TR, AH, XH_PRIME, XR_PRIME, LR_PRIME, EPS, KAPPA, F_ALPHA = (
    0.387, 0.312, -0.464, -0.5, -0.710, 1.09, 0.50, 2.747)  # fmt: skip
# The MMG file's fields (``shipid.vessels.mmg_file``): the built-in ship is one such file's.
COEFFICIENTS = {
    "name": "kvlcc2", "length": L, "beam": B, "draught": D_DRAUGHT, "volume": VOLUME, "x_g": XG,
    "k_zz": 0.25, "rho": RHO, "approach_speed": APPROACH_SPEED, "rudder_rate": RUDDER_RATE_DEG,
    "rudder_limit": 35.0, "scale": SCALE, "rps": None,
    "hull.m_x": MX, "hull.m_y": MY, "hull.j_z": JZ, "hull.r0": R0, "hull.x_vv": XVV,
    "hull.x_vr": XVR, "hull.x_rr": XRR, "hull.x_vvvv": XVVVV, "hull.y_v": YV, "hull.y_r": YR,
    "hull.y_vvv": YVVV, "hull.y_vvr": YVVR, "hull.y_vrr": YVRR, "hull.y_rrr": YRRR,
    "hull.n_v": NV, "hull.n_r": NR, "hull.n_vvv": NVVV, "hull.n_vvr": NVVR, "hull.n_vrr": NVRR,
    "hull.n_rrr": NRRR,
    "propeller.diameter": DP, "propeller.t_p": TP, "propeller.w_p0": WP0, "propeller.k0": K0,
    "propeller.k1": K1, "propeller.k2": K2, "propeller.x_p": XP_PRIME, "propeller.c1": C1,
    "propeller.c2_pos": 1.6, "propeller.c2_neg": 1.1,
    "rudder.area": AR, "rudder.height": HR, "rudder.t_r": TR, "rudder.a_h": AH,
    "rudder.x_h": XH_PRIME, "rudder.x_r": XR_PRIME, "rudder.l_r": LR_PRIME, "rudder.epsilon": EPS,
    "rudder.kappa": KAPPA, "rudder.f_alpha": F_ALPHA, "rudder.gamma_r_pos": 0.640,
    "rudder.gamma_r_neg": 0.395}  # fmt: skip


PACKED = pack(COEFFICIENTS)


def accelerations(u: float, vm: float, r: float, delta: float, n: float
                  ) -> tuple[float, float, float]:  # fmt: skip
    """(u̇, v̇m, ṙ) of the KVLCC2 at midship sway vm, rudder δ and propeller speed n [rps]
    (``shipid.vessels.mmg.accelerations`` with its coefficients)."""
    return mmg_accelerations(PACKED, u, vm, r, delta, n)


class KVLCC2Dynamics(MMGDynamics):
    """MMG accelerations at constant propeller revolutions ``n_prop`` [rps]."""

    def __init__(self, n_prop: float) -> None:
        super().__init__(COEFFICIENTS, n_prop)


@lru_cache(maxsize=8)
def trimmed_revolutions(speed: float = APPROACH_SPEED) -> float:
    """Propeller rps for u̇ = 0 at ``speed`` in straight running (≈ 11.85 rps at 1.179 m/s):
    ``shipid.vessels.mmg.trimmed_rps`` of its coefficients."""
    return trimmed_rps(COEFFICIENTS, speed)


def kvlcc2(speed: float = APPROACH_SPEED) -> Vessel:
    """The KVLCC2 L7 model as a vessel, trimmed for ``speed`` [m/s]."""
    return Vessel(
        name="kvlcc2",
        dynamics=KVLCC2Dynamics(trimmed_revolutions(speed)),
        length=L,
        approach_speed=speed,
        # Model scale: the rudder moves at the constant rate until the ordered angle (pure rate).
        steering=SteeringMachine(math.radians(35.0), math.radians(RUDDER_RATE_DEG)),
        rudder_positive="starboard",
        scale=SCALE,
        source="KVLCC2 L7, MMG standard method (Yasukawa & Yoshimura 2015)",
    )
