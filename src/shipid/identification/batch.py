"""Identification of many log sets (ships, campaigns) as one study, fanned out on Dask.

Each job is the command line one would type, ``shipid identify`` or ``shipid select`` on a set
of logs with that command's options, run by the same code (``shipid.cli.main``) on a worker.
The model files come back as text and are written together by the caller, so a cluster's
workers need the logs (shared storage) but no writable folder. Specification (YAML)::

    kind: logs
    jobs:
      - name: kvlcc2-zz20                 # the model file's name: DIR/kvlcc2-zz20.json
        command: identify                 # identify (default) or select
        logs: [kvlcc2/zz_20.csv]          # paths or globs, relative to this file
        options: {dt: 0.2, model: blanke-speed, filter: auto}
      - name: esso
        command: select
        logs: [esso/zigzag/*.csv, esso/random/*.csv]
        options: {dt: 0.5, library: low-speed+wind}

``options`` maps option names (without ``--``) to values; ``true`` is a flag, a list repeats the
option (``bound: ['r: u*r <= 0', ...]``).
"""

from __future__ import annotations

import glob
import io
import json
import re
import tempfile
import time
from contextlib import redirect_stderr, redirect_stdout
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from shipid.errors import ShipidError

COMMANDS = ("identify", "select")
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


@dataclass(frozen=True)
class Job:
    """One command line: ``shipid COMMAND LOGS... OPTIONS... -o NAME.json``."""

    index: int
    name: str
    command: str
    logs: tuple[str, ...]
    options: tuple[str, ...] = ()

    def argv(self, output: Path) -> list[str]:
        """The command line, writing the model to ``output``."""
        quiet = ["--quiet"] if self.command == "select" else []
        return [self.command, *self.logs, *self.options, *quiet, "-o", str(output)]


@dataclass(frozen=True)
class BatchSpec:
    """Jobs of a ``kind: logs`` study (see the module docstring)."""

    jobs: tuple[Job, ...]
    source: str = field(default="", compare=False)

    @classmethod
    def from_dict(cls, spec: dict, source: str = "", base: str | Path = ".") -> BatchSpec:
        """Jobs from a parsed YAML mapping; paths relative to ``base``; errors name the job."""
        where = f"{source}: " if source else ""
        unknown = sorted(set(spec) - {"kind", "jobs"})
        if unknown:
            raise ShipidError(f"{where}unknown key {unknown[0]!r} (a logs study has kind, jobs)")
        jobs = spec.get("jobs")
        if not isinstance(jobs, list) or not jobs:
            raise ShipidError(f"{where}jobs: give a list of jobs (name, command, logs, options)")
        from shipid.cli.parser import build_parser

        parser = build_parser()
        out, names = [], set()
        for i, job in enumerate(jobs):
            out.append(_job(i, job, f"{where}jobs[{i}]", Path(base)))
            _check_options(parser, out[-1], f"{where}jobs[{i}]")
            if out[-1].name in names:
                raise ShipidError(f"{where}jobs[{i}]: the name {out[-1].name!r} is used twice")
            names.add(out[-1].name)
        return cls(tuple(out), source)


def _job(index: int, job, where: str, base: Path) -> Job:
    if not isinstance(job, dict):
        raise ShipidError(f"{where}: a job is a mapping (name, command, logs, options)")
    unknown = sorted(set(job) - {"name", "command", "logs", "options"})
    if unknown:
        raise ShipidError(f"{where}: unknown key {unknown[0]!r} (name, command, logs, options)")
    name = job.get("name")
    if not isinstance(name, str) or not NAME.match(name):
        raise ShipidError(f"{where}: name {name!r} must be letters, digits, '-', '_' or '.'")
    command = job.get("command", "identify")
    if command not in COMMANDS:
        raise ShipidError(f"{where}: command {command!r} is not one of {', '.join(COMMANDS)}")
    patterns = job.get("logs")
    patterns = [patterns] if isinstance(patterns, str) else patterns
    if not isinstance(patterns, list) or not patterns:
        raise ShipidError(f"{where}: logs: give the log files (paths or globs)")
    logs: list[str] = []
    for pattern in patterns:
        full = str(base / str(pattern))
        matches = sorted(glob.glob(full)) if glob.has_magic(full) else [full]
        if not matches or not all(Path(m).is_file() for m in matches):
            raise ShipidError(f"{where}: logs: no such file {pattern!r} (relative to {base})")
        logs += matches
    options = job.get("options") or {}
    if not isinstance(options, dict):
        raise ShipidError(f"{where}: options is a mapping of option names to values")
    argv: list[str] = []
    for key, value in options.items():
        if key in ("o", "output", "quiet"):
            raise ShipidError(f"{where}: options: {key!r} is set by the study")
        flag = f"--{str(key).replace('_', '-')}"
        for v in value if isinstance(value, list) else [value]:
            if v is True:
                argv.append(flag)
            elif v is not False and v is not None:
                argv += [flag, str(v)]
    return Job(index, name, command, tuple(logs), tuple(argv))


def _check_options(parser, job: Job, where: str) -> None:
    """The job's command line as the command's parser reads it, before any job runs: an option
    the command does not have made argparse exit inside the job, ending the whole study with
    exit code 2 and no word (its message went to the job's captured stderr)."""
    err = io.StringIO()
    try:
        with redirect_stderr(err):
            parsed = parser.parse_args(job.argv(Path(f"{job.name}.json")))
    except SystemExit:
        said = [ln for ln in err.getvalue().splitlines() if "error: " in ln]
        why = said[-1].split("error: ", 1)[1] if said else "not a valid command line"
        raise ShipidError(f"{where}: options: {why} (shipid {job.command} --help)") from None
    # A list repeats the option; one that takes a single value kept the last without a word.
    flags = [a for a in job.options if a.startswith("--")]
    for flag in sorted({f for f in flags if flags.count(f) > 1}):
        if not isinstance(getattr(parsed, flag[2:].replace("-", "_"), None), list):
            raise ShipidError(f"{where}: options: {flag[2:]} takes one value, not a list")


def run_job(job: Job) -> dict:
    """Run one job in this process; its row, with the model file's text (or the error)."""
    from shipid.parallel import single_threaded

    return single_threaded(_run_job, job)


def _run_job(job: Job) -> dict:
    from shipid.cli import main

    start = time.perf_counter()
    row = {"index": job.index, "name": job.name, "command": job.command, "logs": len(job.logs),
           "error": "", "warnings": "", "model_text": None}  # fmt: skip
    out, err = io.StringIO(), io.StringIO()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{job.name}.json"
        with redirect_stdout(out), redirect_stderr(err):
            try:
                code = main(job.argv(path))
            except SystemExit as exc:  # argparse's: the job fails, the study goes on
                code = exc.code if isinstance(exc.code, int) and exc.code else 2
        lines = err.getvalue().splitlines()
        row["warnings"] = "; ".join(ln[len("warning: "):] for ln in lines
                                    if ln.startswith("warning: "))  # fmt: skip
        if code != 0:
            errors = [ln for ln in lines if ln.startswith("shipid: ")]
            row["error"] = (errors[-1].removeprefix("shipid: ").removeprefix("error: ")
                            if errors else f"exit code {code}")  # fmt: skip
        else:
            row["model_text"] = path.read_text(encoding="utf-8")
            row |= _summary(json.loads(row["model_text"]))
    row["seconds"] = time.perf_counter() - start
    return row


def _summary(doc: dict) -> dict:
    """A few facts of a model file for the study's table."""
    ident = doc.get("identification") or {}
    selection = ident.get("selection") or {}
    terms = doc["model"]["structure"]["terms"]
    return {"terms": sum(len(t) for t in terms.values()), "gamma": ident.get("gamma"),
            "prefilter_hz": (ident.get("preprocessing") or {}).get("filter_hz"),
            "cv_score": selection.get("score")}  # fmt: skip


def run_batch(spec: BatchSpec, scheduler: str | None = None, workers: int | None = None,
              progress: bool = True) -> tuple[pd.DataFrame, dict[str, str]]:  # fmt: skip
    """Run every job; the table (one row per job, in order) and {name: model file text}."""
    from shipid.parallel import run_tasks

    rows = run_tasks(run_job, spec.jobs, scheduler, workers, progress, unit="job")
    texts = {r["name"]: r.pop("model_text") for r in rows}
    table = pd.DataFrame(rows).drop(columns="index")
    return table, {k: v for k, v in texts.items() if v is not None}
