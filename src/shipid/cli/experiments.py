"""``shipid demo`` (the paper's experiment on the embedded scale ship) and ``shipid study``
(Monte Carlo studies, serial or on Dask)."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from shipid.cli.printing import _warn
from shipid.errors import ShipidError


def cmd_demo(args) -> int:
    """``shipid demo``: the paper's experiment on the embedded scale ship."""
    from shipid.demo import run_demo, summary
    from shipid.outputs import check_outputs

    check_outputs({"--out": (args.out, "dir")})
    t0 = time.perf_counter()
    result = run_demo(args.out, args.seed, progress=lambda m: print(m, file=sys.stderr))
    print(summary(result))
    print(f"figures and report written to {Path(args.out) / 'report.md'} "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0


def cmd_study(args) -> int:
    """``shipid study``: a Monte Carlo study, or the identification of many log sets, on Dask."""
    from shipid.data.io import write_table
    from shipid.evaluation.study import GRID_KEYS, read_spec, run_study, summary
    from shipid.outputs import OutputSet, check_outputs

    check_outputs({"-o": (args.output, "log")}, [args.spec])
    spec = read_spec(args.spec)
    where = ("this process" if args.scheduler == "serial" else args.scheduler
             or f"a local Dask cluster of {args.workers or os.cpu_count() or 1} workers")  # fmt: skip
    if hasattr(spec, "jobs"):
        return _study_logs(args, spec, where)
    if args.models:
        raise ShipidError("--models is for a study of kind logs (model files of its jobs)")
    n = len(spec.trials())
    print(f"{n} trials ({len(spec.seeds)} seeds × {n // len(spec.seeds)} grid points) on {where}")
    start = time.perf_counter()
    results = run_study(spec, scheduler=args.scheduler, workers=args.workers,
                        progress=not args.quiet)  # fmt: skip
    wall = time.perf_counter() - start
    print("Held-out error std of the identified model over the true model's on the same noisy "
          "log (1 = as good as the truth):")  # fmt: skip
    table = summary(results)
    varying = [k for k in GRID_KEYS if table[k].nunique() > 1]
    fixed = ", ".join(f"{k} {table[k].iloc[0]:g}" if isinstance(table[k].iloc[0], float)
                      else f"{k} {table[k].iloc[0]}" for k in GRID_KEYS if k not in varying)
    print(f"({fixed}; per held-out manoeuvre: the median over the seeds and the largest)")
    table.index = [", ".join(f"{k} {row[k]}" for k in varying) or "all"
                   for _, row in table.iterrows()]  # fmt: skip
    print(table.drop(columns=list(GRID_KEYS)).T.to_markdown(floatfmt=".3g"))
    print(f"\n{n} trials in {wall:.1f} s wall ({results['seconds'].sum():.1f} s of trial time)")
    with OutputSet() as out:
        write_table(results, args.output, out)
    failed = results[results["error"] != ""]
    if len(failed):
        _warn(f"{len(failed)} of {n} trials failed (first: seed {failed['seed'].iloc[0]}: "
              f"{failed['error'].iloc[0]}); their rows have the error")  # fmt: skip
    print(f"results written to {args.output}")
    return 0


def _study_logs(args, spec, where: str) -> int:
    """A study of kind logs: every job's model file into --models, the table to -o."""
    from shipid.data.io import write_table
    from shipid.identification.batch import run_batch
    from shipid.outputs import OutputSet, check_outputs

    if not args.models:
        raise ShipidError(f"{args.spec}: a study of kind logs writes model files: give --models DIR")
    inputs = [args.spec, *(p for job in spec.jobs for p in job.logs)]
    check_outputs({"-o": (args.output, "log"), "--models": (args.models, "dir")}, inputs)
    print(f"{len(spec.jobs)} jobs ({sum(len(j.logs) for j in spec.jobs)} logs) on {where}")
    start = time.perf_counter()
    table, texts = run_batch(spec, scheduler=args.scheduler, workers=args.workers,
                             progress=not args.quiet)  # fmt: skip
    cols = ["name", "command", "logs", "terms", "gamma", "prefilter_hz", "cv_score", "seconds",
            "error"]
    print(table[[c for c in cols if c in table]].to_markdown(index=False, floatfmt=".4g"))
    print(f"\n{len(spec.jobs)} jobs in {time.perf_counter() - start:.1f} s wall")
    models = Path(args.models)
    with OutputSet() as out:
        for name, text in texts.items():
            out.write(models / f"{name}.json", lambda p, t=text: p.write_text(t, encoding="utf-8"))
        write_table(table, args.output, out)
    failed = table[table["error"] != ""]
    print(f"{len(texts)} model files written to {models}, the table to {args.output}")
    for _, row in failed.iterrows():  # as validate's batch: the others are written, exit 1
        print(f"shipid: error: job {row['name']}: {row['error']}", file=sys.stderr)
    return 1 if len(failed) else 0
