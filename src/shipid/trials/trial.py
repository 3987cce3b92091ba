"""What a log is, decided once: the kind of manoeuvre and the facts its indices and replicas need.

``describe_trial`` reads the rudder execute, the approach heading ψ0, the rudder neutral and
amplitude, and classifies the log:

* **turning**: the rudder goes to one side and is held until the heading has changed by 180°;
* **zigzag**: the rudder swings from side to side at least twice, every swing to a similar angle
  (within ±40 % of the median), each reversal ordered with the heading on the side the ship was
  turning to at a similar heading (within 0.3–3 × the median), the heading within ±90°, and the
  propeller not reversed;
* **other**: anything else (random rudder and propeller orders, a stopping run, a straight run).
  Such a log has no IMO indices; it is still validated by its free-run errors.

A kind can be forced (``kind=``); then the classification only supplies the facts.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shipid.data.log import column_values, require_columns
from shipid.data.preprocess import cumulative_integral, white_noise_variance
from shipid.data.rudder_signal import ramp_start, rise_rate, rudder_for_events, stand_samples
from shipid.data.trim import (
    DEFAULT_LEAD_S,
    EXECUTE_FRACTION,
    first_swing_index,
    held_peak,
    swing_start,
)
from shipid.errors import ShipidError

KINDS = ("zigzag", "turning", "pull-out", "other")
# Kinds whose log holds a turn from a straight approach (a pull-out's before its release).
TURN_KINDS = ("turning", "pull-out")
AMPLITUDE_SPREAD = 0.4  # zig-zag swings within ±40 % of the median swing
SWITCH_SPREAD = (0.3, 3.0)  # zig-zag switch headings within this factor of the median
MIN_SWITCH = math.radians(3.0)  # IMO zig-zags switch at 5°–20°; a 2° "switch" is helm noise
MAX_ZIGZAG_HEADING = math.radians(90.0)
# Heading change before the first order beyond which the log has no straight approach.
MAX_APPROACH_TURN = math.radians(90.0)
APPROACH_HEADING_S = DEFAULT_LEAD_S  # the approach heading: what --start auto keeps of it
HELD_TOLERANCE = math.radians(3.0)  # a held rudder stays within this of its plateau (or 15 %)
PLATEAU_TOLERANCE = math.radians(0.5)
# Heading noise above this is fused with the yaw rate (the Esso Osaka's logs show 0.06-0.1°,
# the paper's IMU 0.05°; a MEMS compass 1°), over this window.
HEADING_NOISE_FLOOR = math.radians(0.15)
HEADING_FUSION_S = 4.0


@dataclass(frozen=True)
class Trial:
    """Facts of one log (angles in radians, times in seconds).

    Attributes
    ----------
    kind : 'zigzag', 'turning', 'pull-out' or 'other'.
    reason : why the log is of this kind (for 'other': which test a zig-zag or turn failed).
    execute_index, execute_time : the rudder order (start of the first large swing).
    psi0 : mean heading over the approach's last ``APPROACH_HEADING_S`` (up to the order).
    neutral : the rudder's neutral (mid-range) angle.
    amplitude : median rudder deflection from neutral on the plateaus.
    plateau_angle : median |δ| where the rudder is within 80 % of its largest swing from the
        initial angle (midships where the log starts on its order): the commanded rudder angle
        of a zig-zag or turn.
    first_rudder : signed deflection of the first plateau from neutral.
    switch_heading_deg : zig-zag switch heading inferred at the rudder orders (None if none).
    rudder_rate : the rudder's rate over its swings [rad/s] (``shipid.data.rudder_signal``; None
        if it never swings, or if the sampling does not resolve the movement).
    held_end_index : last sample of the held rudder after the execute (turning; else the end).
    reversal_headings_deg : the signed heading change from ψ0 at each rudder order after the
        execute (a zig-zag's reversals), in order; ``switch_heading_deg`` is their median size.
    reversal_step_deg : the largest heading change over one sample at those orders: how finely
        the log resolves them.
    release_time : where the held rudder went back to the approach's angle (or midships) and
        stayed there to the log's end: the release of a pull-out (None where it did not).
    turning_at_order : where the ship turns at the order, already (a log cut inside its
        manoeuvre) or still (an approach that is not straight), its yaw rate there as a share
        of its largest after it (``turning_at_order``); else None.
    """

    kind: str
    reason: str
    execute_index: int
    execute_time: float
    psi0: float
    neutral: float
    amplitude: float
    plateau_angle: float
    first_rudder: float
    switch_heading_deg: float | None
    rudder_rate: float | None
    held_end_index: int
    reversal_headings_deg: tuple[float, ...] = ()
    reversal_step_deg: float = 0.0
    release_time: float | None = None
    turning_at_order: float | None = None


def heading_noise(psi: np.ndarray, integral: np.ndarray) -> float:
    """White noise [rad] on the heading, robustly: the spread of the steps of ψ − ∫r dt (the
    manoeuvre itself cancels; a gyro's bias is a slow drift)."""
    if psi.size < 3:
        return 0.0
    return _step_noise(np.diff(psi - integral))


def _step_noise(d: np.ndarray) -> float:
    """``heading_noise`` of the steps ``d`` of ψ − ∫r dt: their median absolute deviation."""
    return float(np.median(np.abs(d - np.median(d))) / 0.6745 / math.sqrt(2.0))


# A run's heading is read twice for its indices, and a validate with a model's ensemble reads
# 400 runs of a long log: np.unwrap's passes and heading_noise's two medians were a sixth of it
# (1.4 and 1.2 ms at 45 000 samples, against 0.03 and 0.04 ms for the checks below), for
# headings no step of which reaches π and whose steps' whole range lies within the floor.


def _unwrap(psi: np.ndarray) -> np.ndarray:
    """``np.unwrap(psi)``; where no step reaches π it corrects nothing, so a copy is it."""
    d = np.diff(psi)
    if d.size and np.abs(d).max() < np.pi:  # NaN: unwrap's own way
        return np.array(psi, dtype=float)
    return np.unwrap(psi)


def _heading_noise_within(psi: np.ndarray, integral: np.ndarray, level: float) -> bool:
    """``heading_noise(psi, integral) <= level``: the median absolute deviation of the steps
    never exceeds their range (rounding keeps the order), so a range within ``level`` settles
    it without the medians."""
    if psi.size < 3:
        return heading_noise(psi, integral) <= level
    d = np.diff(psi - integral)
    return bool(np.ptp(d) / 0.6745 / math.sqrt(2.0) <= level or _step_noise(d) <= level)


def unwrapped_heading(log: pd.DataFrame) -> np.ndarray:
    """ψ unwrapped, or integrated from r when the log has no heading.

    A noisy heading (more than ``HEADING_NOISE_FLOOR``, as a MEMS compass's 1°) is fused with
    the yaw rate: ∫r dt plus a ``HEADING_FUSION_S`` moving average of ψ − ∫r dt. On the raw
    heading the noise was counted as overshoot (a 20/20 zig-zag of the Mariner: first overshoot
    7.8° read as 11.4° with 1° of noise) and crossed the switch heading early."""
    t = column_values(log, "t")
    if "psi" not in log.columns:
        return cumulative_integral(column_values(log, "r"), t, initial=0.0)
    psi = _unwrap(column_values(log, "psi"))
    integral = cumulative_integral(column_values(log, "r"), t, initial=0.0)
    if _heading_noise_within(psi, integral, HEADING_NOISE_FLOOR):
        return psi
    n = max(1, int(round(HEADING_FUSION_S / float(np.median(np.diff(t))))))
    if n < 2 or n >= psi.size:
        return psi
    return integral + moving_average(psi - integral, n)


def moving_average(x: np.ndarray, n: int) -> np.ndarray:
    """Centred moving average over ``n`` samples, the ends padded with the end values
    (cumulative sums: linear time)."""
    pad = np.concatenate([np.full(n // 2, x[0]), x, np.full(n - 1 - n // 2, x[-1])])
    c = np.concatenate([[0.0], np.cumsum(pad)])
    return (c[n:] - c[:-n]) / n


def neutral_rudder(delta: np.ndarray) -> float:
    """Mid-range of the rudder: the neutral of a zig-zag whatever side the log starts on."""
    return 0.5 * (float(np.max(delta)) + float(np.min(delta)))


def runs_of(values: np.ndarray) -> list[tuple[int, int, float]]:
    """(first, last, value) of the runs of equal values, in one pass."""
    if values.size == 0:
        return []
    edges = np.flatnonzero(values[1:] != values[:-1]) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges - 1, [values.size - 1]])
    return [(int(a), int(b), float(values[a])) for a, b in zip(starts, ends, strict=True)]


def _plateau_orders(delta: np.ndarray, side: np.ndarray, i0: int, t: np.ndarray | None = None,
                    raw: np.ndarray | None = None) -> list[tuple[int, int, float | None]]:  # fmt: skip
    """(order index, new side, order time) of each rudder reversal after ``i0``: the last sample
    of the previous plateau (within 0.5° of its extreme angle) before the rudder swung over
    (time None: between it and the next). With the times ``t`` and the measured rudder ``raw``
    (``delta`` denoised: its dead band leaves the plateau late), the time the swing's ramp,
    extended back, leaves the plateau, and the last sample before it."""
    runs = [r for r in runs_of(side[i0:]) if r[2] != 0]
    orders = []
    for (a0, b0, s0), (a1, b1, s1) in zip(runs[:-1], runs[1:], strict=True):
        if s1 == s0:
            continue
        seg = delta[i0 + a0 : i0 + b0 + 1]
        extreme = seg[np.argmax(s0 * seg)]
        near = np.flatnonzero(np.abs(seg - extreme) <= PLATEAU_TOLERANCE)
        order, when = i0 + a0 + int(near[-1]), None
        if t is not None:
            end = i0 + a1 + int(np.argmax(s1 * delta[i0 + a1 : i0 + b1 + 1]))
            level = float(np.median(raw[i0 + a0 + near]))
            when = ramp_start(t, delta, order, end, level)
            order = _before(t, when, order)
        orders.append((order, int(s1), when))
    return orders


# An order before the first swing from the log's first angle: a plateau at this share of the
# trial's deflection from neutral, held this long.
EARLIER_LEVEL = 0.7
EARLIER_HOLD_S = 2.0


def earlier_order(t: np.ndarray, delta: np.ndarray, i0: int, max_stand: int = 0) -> int:
    """The first order where the log starts with the helm over: the first swing from the first
    angle that is at least half the largest (``first_swing_index``) misses a smaller first
    order. An Esso Osaka 15°/15° zig-zag starts at +7.7° (the helm holding the course), so its
    first order to +14.8° is a 7° swing against the reversals' 30°, and the first reversal was
    taken for the execute (the first overshoot read 18.5° from a heading averaged over the first
    leg). Where the rudder swings over from side to side at least twice after the swing at ``i0``
    (a zig-zag's reversals, by ``EARLIER_LEVEL`` of its deflection from their mid-range), the first
    swing before ``i0`` to a plateau at that level, and no more than ``AMPLITUDE_SPREAD`` beyond
    the trial's angle, held ``EARLIER_HOLD_S`` is the order; ``i0`` if there is none (or the
    trial is a turn: one swing, and back at the end of the run)."""
    if i0 <= 0:
        return i0
    dev = delta - neutral_rudder(delta[i0:])
    amplitude = float(np.max(np.abs(dev[i0:])))
    level = EARLIER_LEVEL * amplitude
    # At the trial's angle: a helm correction beyond it (16° before a 10° zig-zag) is none.
    side = np.where((np.abs(dev) >= level) & (np.abs(dev) <= (1 + AMPLITUDE_SPREAD) * amplitude),
                    np.sign(dev), 0.0)  # fmt: skip
    legs = [s for _, _, s in runs_of(side[_swing_end(t, delta, i0) :]) if s != 0]
    if sum(1 for a, b in zip(legs[:-1], legs[1:], strict=True) if a != b) < 2:
        return i0
    hold = max(1, int(round(EARLIER_HOLD_S / float(np.median(np.diff(t))))))
    smallest = max(math.radians(2.0), 0.2 * level)  # a swing, not a log that starts on the plateau
    for k in np.flatnonzero(side[:i0]):
        k = int(k)
        if k + hold < len(delta) and np.ptp(delta[k : k + hold + 1]) <= PLATEAU_TOLERANCE:
            start = swing_start(delta, k, float(side[k]), max_stand)
            if abs(delta[k] - delta[start]) >= smallest:
                return start
    return i0


# A ship turning at its order faster than this share of its largest yaw rate does not start
# from a straight approach (``turning_at_order``). A log starts on its order where the ship turns
# under the rudder of its first sample at least the second share as hard as after its first swing.
STRAIGHT_START = 0.1
TURNS_ON_FIRST_RUDDER = 0.5


def starts_on_order(log: pd.DataFrame, delta: np.ndarray, i0: int) -> int:
    """0 where the log starts on its first order, else ``i0``. A simulated manoeuvre with an
    instantaneous rudder (the scale ship's), or a log cut at the execute, has the rudder over
    from its first sample: the first swing (``i0``) is then the first reversal of a zig-zag or
    the release of a pull-out, and was taken for the execute (the scale ship's 20/20 zig-zag read
    reversals at −27.9° and +12.5° from a heading averaged over its first leg, and a first
    overshoot of 8.7° against 3.7°; its pull-out read as a turn with advance 0). The rudder held
    from the first sample to ``i0`` (or still swinging to where it is then held: a log cut
    during the order), and the ship turning under that rudder about as hard as it turns after
    ``i0``: the order came at the first sample, or before it where the ship already turns there
    (a log cut inside its manoeuvre: ``turning_at_order`` says so; its first reversal was taken
    for the execute, and MARIN's 20/20 zig-zag cut 3 s after its order read overshoots of 1.8°
    and 25.7° against 14.7° and 11.8°). A straight approach with the helm held over (the Esso
    Osaka's −6°) turns far less than the trial."""
    if i0 <= 0 or np.ptp(delta[_swing_end_from_start(delta, i0) : i0 + 1]) > PLATEAU_TOLERANCE:
        return i0
    r = np.abs(column_values(log, "r"))
    turning = float(np.max(r[: i0 + 1]))
    return 0 if turning >= TURNS_ON_FIRST_RUDDER * float(np.max(r[i0:])) else i0


def _swing_end_from_start(delta: np.ndarray, i0: int) -> int:
    """Where the rudder, moving one way from the first sample (a log cut during a swing),
    stops before ``i0`` (0 where it does not move at first)."""
    steps = np.diff(delta[: i0 + 1])
    moving = np.flatnonzero(np.abs(steps) > 0)
    if not moving.size or moving[0] != 0:
        return 0
    way = np.sign(steps[0])
    against = np.flatnonzero(way * steps <= 0)
    return int(against[0]) if against.size else i0


# An approach's yaw rate is read as its running median over this long (a gust's or a sensor's
# spike is not a turn), and counts beyond this many standard deviations of its noise.
ORDER_YAW_S = 1.0
ORDER_NOISE = 4.0


def turning_at_order(log: pd.DataFrame, i0: int) -> float | None:
    """How hard the ship turns at the order ``i0``, as a share of its largest yaw rate from
    there on, where that is more than ``STRAIGHT_START`` beyond what the yaw rate's white noise
    reaches (``ORDER_NOISE`` standard deviations of the statistic); else None (a straight
    approach). At the first sample (``i0`` 0): its yaw rate there; the log was cut after the
    execute, whose heading (a zig-zag's overshoots are measured from it) and track (a turn's
    advance, transfer and times to 90° and 180°) it lacks. After an approach: the largest of its
    yaw rate's running median over ``ORDER_YAW_S`` in the ``APPROACH_HEADING_S`` up to the
    order; the ship still turned from a manoeuvre before, and the trial counts from a ship
    turning (the scale ship's 35° turn after 4 s of −20° rudder read an advance 44 % long and a
    tactical diameter 14 % short, and ``validate``'s replica, run straight to the order, laid
    them on the true ship). No approach of the Esso Osaka's and the KVLCC2's logs reaches it
    (0.079 at most, ad hoc); without the noise's margin the paper's noisy 10°/10° zig-zag of the
    scale ship, whose approach turns at 5 % of its largest yaw rate, read as turning in 2 of 40
    seeds, at five times the noise in 36 of 40."""
    t, r = column_values(log, "t"), column_values(log, "r", float)
    largest = max(float(np.max(r[i0:])), -float(np.min(r[i0:])))  # no |r| array
    if not largest > 0:
        return None
    if i0 == 0:
        turning, width = abs(float(r[0])), 1
    else:
        first = int(np.searchsorted(t, t[i0] - APPROACH_HEADING_S))
        # The approach's own sampling: a median over the whole log cost every replica's read.
        sampling = float(np.median(np.diff(t[max(0, first - 1) : i0 + 1])))
        width = max(1, int(round(ORDER_YAW_S / sampling)))
        lead = r[max(0, first - width + 1) : i0 + 1]
        width = min(width, lead.size)
        turning = float(np.max(np.abs(np.median(
            np.lib.stride_tricks.sliding_window_view(lead, width), axis=1))))  # fmt: skip
    if turning <= STRAIGHT_START * largest:
        return None  # straight whatever the noise: its two medians over the log are spared
    # A median of ``width`` samples of white noise spreads 1.2533/√width as far (1 for one).
    spread = (1.2533 / math.sqrt(width) if width > 1 else 1.0) * \
        math.sqrt(white_noise_variance(r))  # fmt: skip
    return turning / largest if turning > STRAIGHT_START * largest + ORDER_NOISE * spread \
        else None  # fmt: skip


# A rudder order is held within this spread of its extreme [rad] (``rudder_execute_time``'s
# plateau) for ``HELD_ORDER_S``, or ``HOLD_SHARE`` of the trial's typical hold where shorter.
HELD_SPREAD = math.radians(1.0)
HELD_ORDER_S = 5.0
HOLD_SHARE = 0.5
LONG_HOLD = 0.25  # the trial's holds: those longer than this share of the longest


def _hold(t: np.ndarray, x: np.ndarray) -> float:
    """How long [s] ``x`` stays within ``HELD_SPREAD`` of its extreme (the angle an order holds;
    the samples counted, ``t`` uniform or not)."""
    k = int(np.argmax(np.abs(x)))
    near = np.abs(x - x[k]) <= HELD_SPREAD
    steps = np.diff(t, append=t[-1] + (t[-1] - t[-2] if t.size > 1 else 0.0))
    return float(np.sum(steps[near]))


def held_swing_index(t: np.ndarray, delta: np.ndarray, max_stand: int = 0) -> int:
    """``first_swing_index``, past swings the helm made before the trial. The trial's orders are
    the swings beyond half the largest deflection held longest (``LONG_HOLD``); a swing counts
    as the order where the rudder then stays within ``HELD_SPREAD`` of its extreme for
    ``HELD_ORDER_S`` or ``HOLD_SHARE`` of their median hold, whichever is shorter (a turn's
    order), or swings over into a long hold on the other side as fast as the trial's reversals
    do, within twice their median time (a zig-zag's first leg can be short: the scale ship's
    20/20 holds 2.2 s against 7.5–8.8 s after), at an angle within ``AMPLITUDE_SPREAD`` of
    theirs.

    Logs that start at rest carry the helm's corrections as the ship gathers speed: four of
    the Esso Osaka's nine zig-zags read whole swing to 13–19° in the first seconds (more than
    half their 15–30° orders; held 1.1–2.1 s against 15–55 s) and drift back, and the first
    correction was taken for the execute: two read as no zig-zag, one with reversals at −34°
    and +19° around a 30° switch heading. Where no swing passes, ``first_swing_index``'s."""
    first = first_swing_index(delta, max_stand)
    dev = delta - delta[0]
    if not np.max(np.abs(dev)) > 0:
        return first
    peak = held_peak(t, dev)
    if not peak > 0:
        return first
    side = np.where(np.abs(dev) >= EXECUTE_FRACTION * peak, np.sign(dev), 0.0)
    runs = [(a, b, v) for a, b, v in runs_of(side) if v != 0 and b >= first]
    if len(runs) < 2:
        return first
    holds = np.array([_hold(t[a : b + 1], dev[a : b + 1]) for a, b, _ in runs])
    angles = np.array([np.max(np.abs(dev[a : b + 1])) for a, b, _ in runs])
    long = holds >= LONG_HOLD * holds.max()
    needed = min(HELD_ORDER_S, HOLD_SHARE * float(np.median(holds[long])))
    angle = float(np.median(angles[long]))
    # The time the rudder takes over from one long hold to the other side's.
    over = [t[runs[i + 1][0]] - t[runs[i][1]] for i in range(len(runs) - 1)
            if long[i] and long[i + 1] and runs[i][2] != runs[i + 1][2]]  # fmt: skip
    reversal = 2.0 * float(np.median(over)) if over else -math.inf
    for i, ((a, b, v), hold, x) in enumerate(zip(runs, holds, angles, strict=True)):
        if abs(x - angle) > AMPLITUDE_SPREAD * angle:
            continue
        # Held, or reversed into the trial's next leg as its reversals are (in a beam wind the
        # scale ship's first leg held 1.0 s against 9–11 s after).
        reversed_ = i + 1 < len(runs) and long[i + 1] and runs[i + 1][2] != v and \
            t[runs[i + 1][0]] - t[b] <= reversal  # fmt: skip
        if hold >= needed or reversed_:
            return first if a <= first else swing_start(delta, a, v, max_stand)
    return first


def execute_index(log: pd.DataFrame, delta: np.ndarray, rudder_noise: float) -> int:
    """The sample of the first rudder order of ``log`` (``delta`` its rudder for events,
    ``rudder_for_events``): the first held swing from the first angle to at least half the
    largest deflection (``held_swing_index``), or an earlier, smaller one to the trial's plateau
    (``earlier_order``); on a noisy rudder the ramp extended back to where it left the approach;
    the first sample where the log starts on the order (``starts_on_order``)."""
    t, raw = column_values(log, "t"), column_values(log, "delta")
    stand = stand_samples(t) if rudder_noise else 0
    i0 = earlier_order(t, delta, held_swing_index(t, delta, stand), stand)
    if rudder_noise:  # the dead band left the approach late: extend the ramp back
        stood = np.flatnonzero(delta[: i0 + 1] != delta[i0])
        level = float(np.median(raw[stood[-1] + 1 if stood.size else 0 : i0 + 1]))
        i0 = _before(t, ramp_start(t, delta, i0, _swing_end(t, delta, i0), level), i0)
    return starts_on_order(log, delta, i0)


def _before(t: np.ndarray, when: float, latest: int) -> int:
    """The last sample at or before ``when``, no later than ``latest``."""
    return max(0, min(latest, int(np.searchsorted(t, when, side="right")) - 1))


def _swings_unresolved(delta: np.ndarray) -> bool:
    """Half the rudder's travel or more between two samples: the sampling does not resolve the
    movement, and step/Δt would only measure the sampling."""
    step = np.abs(np.diff(delta))
    return bool(step.size and step.max() >= 0.5 * np.ptp(delta))


def _rudder_rate(t: np.ndarray, delta: np.ndarray) -> float | None:
    rate = np.abs(np.diff(delta)) / np.diff(t)
    moving = rate > math.radians(0.5)
    if not moving.any() or _swings_unresolved(delta):
        return None
    # By the swings, not by the steps, which measure the quantisation too; movements all under
    # the 2° of a swing by their fastest steps.
    swings = rise_rate(t, delta)
    return swings if swings is not None else float(np.percentile(rate[moving], 90))


def logs_rudder_rate(logs: Sequence[pd.DataFrame], trials: Sequence[Trial] | None = None
                     ) -> float | None:  # fmt: skip
    """The rudder rate of a set of logs [rad/s]: the fastest of their ``Trial.rudder_rate`` (the
    steering gear's, which manoeuvres on a model of them run at); None where none swings.
    ``trials``: the logs' ``describe_trial``, where the caller has them."""
    trials = trials if trials is not None else [describe_trial(log) for log in logs]
    rates = [t.rudder_rate for t in trials if t.rudder_rate]
    return max(rates) if rates else None


def rudder_unresolved(log: pd.DataFrame) -> bool:
    """Whether the log's rudder swings faster than its sampling resolves: half its travel or more
    between two samples (``Trial.rudder_rate`` is None then, though the rudder moves)."""
    delta = column_values(log, "delta", float)
    return bool(np.ptp(delta) > math.radians(2.0) and _swings_unresolved(delta))


def describe_trial(
    log: pd.DataFrame,
    kind: str | None = None,
    heading_deg: float | None = None,
    t_order: float | None = None,
    indices_only: bool = False,
) -> Trial:
    """The trial facts of ``log``; ``kind`` forces the kind, ``heading_deg`` the zig-zag switch
    heading, ``t_order`` the execute time (a simulated manoeuvre knows it).

    ``indices_only`` with ``kind`` given: the facts the indices read, for a run read for its
    indices only (a replicate's replica in ``validate``): no rudder rate (None) and, unless a
    zig-zag's switch heading is to be inferred from them, no rudder reversals
    (``reversal_headings_deg`` empty, ``reversal_step_deg`` 0, and a turn's or pull-out's
    ``switch_heading_deg`` None). A long zig-zag's hundreds of swings cost a Python step each
    for both."""
    if kind is not None and kind not in KINDS:
        raise ShipidError(f"manoeuvre kind must be one of {', '.join(KINDS)}, got {kind!r}")
    # The heading, and the yaw rate it is read with (or from, without ψ), besides the rudder.
    require_columns(log, ("t", "delta", "r"), why="a trial's facts are read off its time, "
                    "rudder, yaw rate and heading")  # fmt: skip
    t = column_values(log, "t")
    raw = column_values(log, "delta")
    delta, rudder_noise = rudder_for_events(t, raw)
    i0 = (execute_index(log, delta, rudder_noise) if t_order is None
          else min(int(np.searchsorted(t, t_order - 1e-9)), len(t) - 1))  # fmt: skip
    psi = unwrapped_heading(log)
    # The heading the ship held at the order: over a log that gathers speed from rest the helm
    # wanders (the Esso Osaka's raw 13_04_24 zig-zag: its overshoots read 6.6° and 7.0° from
    # the mean over its 44 s, 4.8° and 8.9° from the last 5 s, as --start auto cuts it).
    approach = int(np.searchsorted(t, t[i0] - APPROACH_HEADING_S))
    yawing = turning_at_order(log, i0)
    # Turning on the approach, its mean lags the heading the order was given at.
    psi0 = _heading_at_order(t, psi, column_values(log, "r", float), i0) \
        if yawing is not None and i0 > 0 else \
        float(np.mean(psi[min(approach, i0) : i0 + 1]))  # fmt: skip
    dpsi = psi - psi0
    neutral = neutral_rudder(delta[i0:])
    if np.ptp(delta[i0:]) < math.radians(1.0):
        neutral = 0.0  # the rudder never swings: it is held where it is (a log cut after the order)
    dev = delta - neutral
    peak = float(np.max(np.abs(dev[i0:])))
    side = np.sign(dev)
    side[np.abs(dev) < max(EXECUTE_FRACTION * peak, math.radians(1.0))] = 0
    # A helm held over before the execute, by half the amplitude or more to the side the first
    # order leaves, read as a plateau of the trial's: an order at the execute and the first
    # rudder to the wrong side. Where the rudder later comes back over to that side (a zig-zag;
    # a turn's approach is the other side of its mid-range for good), it is no plateau.
    away = np.sign(delta[_swing_end(t, delta, i0)] - delta[i0])
    if away != 0 and side[i0] == -away:
        on_side = np.flatnonzero(side[i0:] == away)
        if on_side.size and np.any(side[i0 + int(on_side[0]) :] == -away):
            side[i0 : i0 + int(on_side[0])] = 0
    big = np.flatnonzero(side[i0:]) + i0
    # A noisy rudder's event signal creeps up to the highest noise on a plateau: the level is
    # the median of the measured rudder on it.
    amplitudes = _plateau_levels(side[i0:], dev[i0:], (raw - neutral)[i0:] if rudder_noise
                                 else None)  # fmt: skip
    amplitude = float(np.median(amplitudes)) if amplitudes else 0.0
    first_rudder = float(side[big[0]] * amplitudes[0]) if amplitudes else 0.0
    quick = indices_only and kind is not None
    skip = quick and (heading_deg is not None or kind != "zigzag")
    orders = [] if skip else _plateau_orders(delta, side, i0,
                                             *((t, raw) if rudder_noise else ()))  # fmt: skip
    switch, reversals, step = None, (), 0.0
    if orders:
        k = np.array([o for o, _, _ in orders])
        # The order fell between the last plateau sample and the next one: take their midpoint
        # (the ramp's start on a denoised rudder, at the same half sample after it).
        at_order = 0.5 * (dpsi[k] + dpsi[np.minimum(k + 1, len(dpsi) - 1)])
        if rudder_noise:
            half = 0.5 * float(np.median(np.diff(t)))
            at_order = np.interp([w + half for _, _, w in orders], t, dpsi)
        reversals = tuple(float(x) for x in np.degrees(at_order))
        step = float(np.degrees(np.max(np.abs(dpsi[np.minimum(k + 1, len(dpsi) - 1)] - dpsi[k]))))
        switch = float(np.degrees(np.median(np.abs(at_order))))
    if heading_deg is not None:
        switch = float(heading_deg)
    held_end = _held_end(t, delta, i0)
    release_time = _release_time(t, delta, i0, held_end)
    # The swing from the rudder before the order; a log that starts on its order (the rudder
    # over from the first sample) came from midships. From its first sample, a turn held from
    # there never swung (plateau 0) and a pull-out's largest swing was its release: validate's
    # replica of either stopped on "rudder angle must be > 0, got 0.0".
    swing = np.abs(delta - (delta[0] if i0 > 0 else 0.0))
    plateau_angle = float(np.median(np.abs(raw[swing > 0.8 * swing.max()]))) if swing.max() > 0 \
        else 0.0
    facts = dict(execute_index=i0, execute_time=float(t[i0]), psi0=psi0, neutral=neutral,
                 amplitude=amplitude, plateau_angle=plateau_angle, first_rudder=first_rudder,
                 switch_heading_deg=switch,
                 rudder_rate=None if quick else rise_rate(t, delta) if rudder_noise
                 else _rudder_rate(t, delta),
                 held_end_index=held_end, reversal_headings_deg=reversals,
                 reversal_step_deg=step,
                 release_time=release_time,
                 turning_at_order=yawing)  # fmt: skip
    if kind is not None:
        return Trial(kind=kind, reason="given", **facts)
    found, reason = _classify(log, dpsi, dev, side, i0, held_end, amplitudes, orders,
                              release_time, yawing if i0 == 0 else None)  # fmt: skip
    return Trial(kind=found, reason=reason, **facts)


def _heading_at_order(t: np.ndarray, psi: np.ndarray, r: np.ndarray, i0: int) -> float:
    """The heading at sample ``i0``: each heading of the last ``ORDER_YAW_S`` carried on to the
    order by the yaw rate's integral, averaged (one sample's compass noise is not the order's
    heading, and a straight line through a turning ship's headings falls behind it: 0.13° on the
    scale ship's turn after 4 s of −20° rudder)."""
    first = int(np.searchsorted(t, t[i0] - ORDER_YAW_S))
    turned = cumulative_integral(r[first : i0 + 1], t[first : i0 + 1])
    return float(np.mean(psi[first : i0 + 1] + turned[-1] - turned))


def turning_at_order_note(trial: Trial, replica: bool = False) -> str | None:
    """What a trial measures where the ship turns at its order (``turning_at_order``): cut
    inside its manoeuvre, or after an approach that is not straight; None where it runs
    straight there. ``replica``: said of a replica run from the same state, which ``validate``
    compares with it."""
    if trial.turning_at_order is None or trial.kind == "other":
        return None
    what = ("its overshoots" if trial.kind == "zigzag" else
            "its advance, transfer, tactical diameter and times to 90° and 180°")
    share = f"{100 * trial.turning_at_order:.0f} % of its largest yaw rate"
    where = (f"the log starts inside its manoeuvre, the ship turning at {share} at the first "
             "sample: the execute came before it, and " if trial.execute_index == 0 else
             f"its approach is not straight, the ship turning at up to {share} in the "
             f"{APPROACH_HEADING_S:g} s before the order (t = {trial.execute_time:.6g} s): ")
    start = "the first sample" if trial.execute_index == 0 else "the order"
    steady = "" if trial.kind == "zigzag" else " (its steady turn does not depend on it)"
    alike = "; the replica, run from the same state, counts alike" if replica else ""
    return (f"{where}{what} count from {start}, not from the straight approach of the IMO's "
            f"trial{steady}{alike}")


def _plateau_levels(side: np.ndarray, dev: np.ndarray, measured_dev: np.ndarray | None
                    ) -> list[float]:  # fmt: skip
    """The level of each rudder plateau (each run of ``side`` ≠ 0), in order: the largest
    deflection ``dev`` to its side, or with a noisy rudder (``measured_dev``, the measured
    rudder's deflection) the median of the measured rudder within ``PLATEAU_TOLERANCE`` of it.
    One reduction over all runs: a long zig-zag has hundreds of them."""
    if side.size == 0:
        return []
    starts = np.concatenate([[0], np.flatnonzero(side[1:] != side[:-1]) + 1])
    tops = np.maximum.reduceat(side * dev, starts)
    ends = np.append(starts[1:], side.size)
    levels = []
    for a, b, s, top in zip(starts, ends, side[starts], tops, strict=True):
        if s == 0:
            continue
        if measured_dev is not None:
            on_plateau = s * dev[a:b] >= top - PLATEAU_TOLERANCE
            top = np.median(s * measured_dev[a:b][on_plateau])
        levels.append(float(top))
    return levels


def _held_end(t: np.ndarray, delta: np.ndarray, i0: int, stand_s: float = 1.0) -> int:
    """Last sample of the rudder held where the execute swing took it: the swing is followed to
    where the rudder stops moving its way (a stand shorter than ``stand_s`` inside the swing, as
    a noisy rudder's dead band makes, does not stop it); held ends where the rudder leaves that
    angle by more than 3° (or 15 % of the swing)."""
    k = _swing_end(t, delta, i0, stand_s)
    held = float(delta[k])
    tol = max(HELD_TOLERANCE, 0.15 * abs(held - delta[i0]))
    away = np.flatnonzero(np.abs(delta[k:] - held) > tol)
    return int(k + away[0] - 1) if away.size else len(delta) - 1


def _swing_end(t: np.ndarray, delta: np.ndarray, i0: int, stand_s: float = 1.0) -> int:
    """Where the swing from ``i0`` stops moving its way (a stand shorter than ``stand_s`` does
    not stop it)."""
    moves = np.flatnonzero(np.diff(delta[i0:])) + i0
    side = np.sign(delta[moves[0] + 1] - delta[moves[0]]) if moves.size else 1.0
    k = i0
    while k + 1 < len(delta):
        step = side * (delta[k + 1] - delta[k])
        if step == 0:
            j = int(np.searchsorted(moves, k))  # the next move after the stand
            if j < moves.size and t[moves[j]] - t[k] < stand_s and \
                    side * (delta[moves[j] + 1] - delta[k]) > 0:
                k = int(moves[j])
                continue
        if step <= 0:
            break
        k += 1
    return k


def _release_time(t: np.ndarray, delta: np.ndarray, i0: int, held_end: int) -> float | None:
    """When the rudder held from ``i0`` to ``held_end`` was released: the first sample of its
    swing back (``held_end`` is where it has left the held angle by 3°, a few samples into a
    rate-limited swing: 0.3 s at 9.6 °/s). None unless it goes back to the approach's angle
    (midships for a log that starts on its order), within 3° (or 15 % of the held deflection),
    without going anywhere else first, and stays there to the log's end."""
    if held_end + 1 >= len(delta):
        return None
    approach = float(delta[i0 - 1]) if i0 > 0 else 0.0
    held = float(np.median(delta[i0 : held_end + 1]))
    tol = max(HELD_TOLERANCE, 0.15 * abs(held - approach))
    after = delta[held_end + 1 :]
    back = np.abs(after - approach) <= tol
    if not back[-1]:
        return None
    away = np.flatnonzero(~back)
    swing_back = after[: int(away[-1]) + 1 if away.size else 0]
    if np.any((swing_back < min(held, approach) - tol) | (swing_back > max(held, approach) + tol)):
        return None
    j = held_end + 1
    way = np.sign(delta[j] - delta[held_end])
    while j - 2 > i0 and way * (delta[j - 1] - delta[j - 2]) > 0:
        j -= 1
    return float(t[j])


# A pull-out: its held turn ≥ 90° of heading, and the rudder released for a quarter of the time
# it was held or more (the yaw rate's decay, or its residual, is what the test measures).
PULL_OUT_TURN = math.radians(90.0)
PULL_OUT_RELEASED_SHARE = 0.25


def _classify(log, dpsi, dev, side, i0, held_end, amplitudes, orders, release_time,
              turning_at_order=None) -> tuple[str, str]:  # fmt: skip
    if not amplitudes:
        return "other", "the rudder never swings"
    # A turn or zig-zag is measured from the heading of a straight approach. A spiral had turned
    # 3300° at the step its execute was found at, and read as a turning circle of advance 0.
    before = float(np.ptp(dpsi[: i0 + 1]))
    if before > MAX_APPROACH_TURN:
        return "other", (f"the heading turns {math.degrees(before):.0f}° before the first rudder "
                         "order: no straight approach (a spiral, or a log cut inside a "
                         "manoeuvre)")  # fmt: skip
    n = column_values(log, "n")[i0:] if "n" in log.columns else None
    reversed_prop = n is not None and np.min(n) < 0 < np.max(n)
    turned = np.abs(dpsi[i0 : held_end + 1])
    t = column_values(log, "t")
    if release_time is not None and not reversed_prop and np.max(turned) >= PULL_OUT_TURN and \
            t[-1] - release_time >= PULL_OUT_RELEASED_SHARE * (release_time - t[i0]):  # fmt: skip
        return "pull-out", (f"rudder held through {math.degrees(np.max(turned)):.0f}° of heading,"
                            f" then released for {t[-1] - release_time:.3g} s")  # fmt: skip
    if turned.size and np.max(turned) >= math.pi and not reversed_prop:
        return "turning", "rudder held to one side through 180° of heading"
    if len(orders) < 2:
        if np.max(np.abs(dpsi[i0:])) >= math.pi:
            return "other", "the heading turns 180° but the rudder is not held"
        if turned.size and np.max(turned) >= MIN_SWITCH:
            # A turn stopped short read "fewer than two rudder reversals", which says nothing of
            # what it lacks.
            return "other", (f"the rudder held to one side through "
                             f"{math.degrees(np.max(turned)):.0f}° of heading and not reversed: "
                             "short of a turning circle's 180°, without a zig-zag's reversals "
                             "(--kind turning reads the indices it reaches)")  # fmt: skip
        return "other", "fewer than two rudder reversals"
    if reversed_prop:
        return "other", "the propeller is reversed"
    if turning_at_order is not None:
        # Cut inside its manoeuvre: a zig-zag's overshoots are heading changes from its approach,
        # which the log does not hold; a turn's steady part and a pull-out's release do not need
        # it (above, with ``turning_at_order_note``).
        return "other", (
            f"it starts inside its manoeuvre, the ship turning at {100 * turning_at_order:.0f} % "
            "of its largest yaw rate at the first sample: the heading of its approach, which a "
            "zig-zag's overshoots are measured from, is not in the log (give the log from "
            "before the first order, or --kind zigzag to measure from its first sample)")
    amp = np.array(amplitudes)
    med = float(np.median(amp))
    if np.any(np.abs(amp - med) > AMPLITUDE_SPREAD * med):
        return "other", (f"rudder swings of {np.degrees(amp.min()):.3g}°–{np.degrees(amp.max()):.3g}°"
                         " are not one zig-zag angle")  # fmt: skip
    if np.max(np.abs(dpsi[i0:])) > MAX_ZIGZAG_HEADING:
        return "other", "the heading leaves ±90° (not a zig-zag)"
    k = np.array([o for o, _, _ in orders])
    new_side = np.array([s for _, s, _ in orders], dtype=float)
    at = dpsi[k]
    # Each reversal sends the ship back: the heading then lies on the side opposite to the new
    # rudder's turn; with either rudder convention sign(Δψ)·(new side) is the same at every order.
    agree = np.sign(at) * new_side
    consistent = max(np.mean(agree > 0), np.mean(agree < 0))
    mag = np.abs(at)
    med_sw = float(np.median(mag))
    lo, hi = SWITCH_SPREAD
    if consistent < 0.75 or med_sw <= 0 or np.any((mag < lo * med_sw) | (mag > hi * med_sw)):
        return "other", "the rudder reversals are not ordered at one switch heading"
    if med_sw < MIN_SWITCH:
        return "other", (f"the rudder reversals come at {np.degrees(med_sw):.2g}° of heading: "
                         "helm corrections, not a zig-zag")  # fmt: skip
    return "zigzag", f"{len(orders)} rudder reversals at ≈ {np.degrees(med_sw):.3g}° heading"
