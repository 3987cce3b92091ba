"""A trial file read as a model is fitted to it, or judged on it: the trial it holds.

Trial files often hold more than their manoeuvre. The Esso Osaka's zig-zag and turn files start
at rest, the ship gathering speed under the helm's corrections for 20–120 s, and end with the
propeller stopped; one random run ends in a minute whose logged propeller speed and rudder read
0 while the ship speeds up (a propulsion dropout, ``shipid.data.checks.propulsion_dropouts``).
Fitted as they are, the default model's 35° turns came 35–131 % long; cut as the README's
``shipid import --start auto --end auto`` and ``--end dropout`` cut them, −13 to +10 %
(``benchmarks/study_esso_whole_logs.py``). ``read_trial_log`` cuts them so; ``identify``,
``select``, ``compare`` and ``validate`` read their logs with it unless ``--start`` or
``--end`` is given.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from shipid.data.checks import propulsion_dropouts
from shipid.data.io import ReadOptions, read_log
from shipid.data.log import starts_without_headway
from shipid.errors import ShipidError
from shipid.trials.trial import describe_trial

# The marks ``read_trial_log`` leaves in a cut log's attrs.
CUT_TO_MANOEUVRE = "cut_to_manoeuvre"
CUT_AT_DROPOUT = "cut_at_dropout"


def manoeuvres_from_rest(logs: Sequence[pd.DataFrame]) -> list[int]:
    """The indices of ``logs`` that are zig-zags or turns (``describe_trial``) and start without
    headway: read whole, with the ship gathering speed under the helm's corrections before the
    manoeuvre and its propeller stopped after it."""
    return [i for i, log in enumerate(logs) if starts_without_headway(log)
            and describe_trial(log).kind in ("zigzag", "turning")]  # fmt: skip


def read_trial_log(path: str | Path, options: ReadOptions | None = None,
                   **overrides) -> pd.DataFrame:  # fmt: skip
    """The log of ``path`` (``read_log``'s options) cut to the trial it holds: to its
    manoeuvre, from ``options.lead`` seconds before the rudder's execute to its end (``start`` and
    ``end`` 'auto'), where it is a zig-zag or turn that starts without headway
    (``manoeuvres_from_rest``; marked ``attrs['cut_to_manoeuvre']``); else up to its first
    propulsion dropout (``end`` 'dropout'; ``attrs['cut_at_dropout']``); else as read. A
    ``start`` or ``end`` in the options is the caller's: the log is read as ``read_log`` reads
    it. The checks' warnings are those of the log kept: a whole log's (its gathering speed, the
    dropout) do not hold for the cut."""
    options = options or ReadOptions()
    if overrides:
        options = dataclasses.replace(options, **overrides)
    if options.start is not None or options.end is not None:
        return read_log(path, options)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        whole = read_log(path, options)
    cuts = []
    if manoeuvres_from_rest([whole]):
        cuts.append((CUT_TO_MANOEUVRE, {"start": "auto", "end": "auto"}))
    dropouts = propulsion_dropouts(whole)
    if dropouts and dropouts[0].before is not None:
        cuts.append((CUT_AT_DROPOUT, {"end": "dropout"}))
    for key, trim in cuts:
        try:
            cut = read_log(path, dataclasses.replace(options, **trim))
        except ShipidError:
            continue  # kept whole; the commands name it (the approach, the dropout's warning)
        cut.attrs[key] = True
        return cut
    for w in caught:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)
    return whole
