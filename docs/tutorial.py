"""Tutorial: from the Esso Osaka trials to an IMO criteria table, with the Python API.

Run it from the repository with ``../shared/data`` beside it::

    .venv/bin/python docs/tutorial.py

(``tests/test_tutorial.py`` runs it.) It takes about ten seconds. Each step prints what it found.
"""

from pathlib import Path

import numpy as np

import shipid
from shipid.evaluation.validate import validate
from shipid.reporting.report import indices_frame, metrics_frame

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "esso-osaka"

# 1. Read the trials. The Osaka reader converts units, unwraps the heading, keeps the relative
#    wind and the rudder convention (positive δ turns this ship to starboard). Zig-zags and turns
#    are trimmed to the manoeuvre; the random runs are used up to a propulsion dropout (the last
#    minute of 31-Jul 14_52_18 logs n = 0 while the ship speeds up). Everything at Δk = 0.5 s.
def read(path, trim):
    kw = {"start": "auto", "end": "auto"} if trim else {"end": "dropout"}
    return shipid.read_log(path, fmt="osaka-frt", dt=0.5, **kw)


zigzags = [read(p, True) for p in sorted((DATA / "zigzag").glob("*.csv"))]
randoms = {p.name: read(p, False) for p in sorted((DATA / "random").glob("*.csv"))}
turns = [read(p, True) for p in sorted((DATA / "turning").glob("*.csv"))]
held_out = "random_31-Jul-2020_12_29_58.csv"
training = zigzags + [log for name, log in randoms.items() if name != held_out]
print(f"{len(training)} training logs, {len(turns)} turns and {held_out} held out")

# 2. Choose the terms and γ by leave-one-log-out free-run error (the held-out logs are not seen)
#    from the low-speed, wind and single-propeller asymmetry terms (see the README).
#    The model is the average of the candidates the choice picks on resampled held-out logs,
#    weighted by how often (select --average); the chosen one is selection.chosen_model.
selection = shipid.select(training, library="low-speed+wind+propeller-asymmetry", average=True)
print(f"selected {selection.candidates.loc[selection.candidates['chosen'], 'n_terms'].item()} "
      f"terms, γ = {selection.gamma:g}, CV score {selection.score:.3f}")
print(selection.model.equations())
print(f"chosen on {100 * selection.chosen_share:.0f} % of resampled held-out logs")
# Its uncertainty, the choice of terms included: each replicate a candidate drawn by its
# share, refitted on the training logs resampled whole, with replacement (select --bootstrap
# 100; from five logs on, so the intervals hold how the logs differ from one another).
ensemble = shipid.selection_ensemble(training, selection, replicates=100)

# 3. Predict what was held out: free-run errors (rmse, fit %) and the turning indices with
#    their 95 % intervals over the ensemble; each log's share of samples inside the error band
#    that select measured on its own held-out folds.
print(selection.error_band.describe())
results = validate(selection.model, turns + [randoms[held_out]], ensemble=ensemble,
                   error_band=selection.error_band)
print(metrics_frame(results).to_markdown(index=False, floatfmt=".3g"))
print(indices_frame(results).dropna(subset=["measured"]).to_markdown(index=False, floatfmt=".3g"))
r_spread = float(np.std(randoms[held_out]["r"]))
print(f"random run: r error {results[-1].metrics['r']['std']:.4f} rad/s, spread {r_spread:.4f}")

# 4. The IMO criteria of the identified model from a steady approach at the first trial's
#    propeller speed: the model's own steady straight speed at that rps (the trial itself was
#    still gathering speed at its start). The model is 1:108.3 (the Esso Osaka is 325 m long),
#    so L/V and the rudder rate are judged at full scale.
particulars = shipid.Particulars(length=3.0, beam=0.489, draught=0.201, block_coefficient=0.83,
                                 mass=244.6, rudder_area=0.0106, propeller_diameter=0.084,
                                 scale=108.3, rho=1000.0)
first = zigzags[0]
approach = shipid.steady_approach(selection.model, trained_speed=float(first["u"].iloc[:10].mean()),
                                  trained_rps=float(first["n"].iloc[:10].mean()))
print(approach.describe())
criteria = shipid.imo_criteria(selection.model, particulars, speed=approach.speed,
                               rps=approach.rps)
table = criteria.table.assign(passed=criteria.table["passed"].map({True: "pass", False: "FAIL"}))
print(table.to_markdown(index=False, floatfmt=".3g"))
print("all criteria met" if criteria.passed else "NOT all criteria met")
