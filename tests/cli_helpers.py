"""Running the CLI in-process from tests: exit code, stdout, stderr."""

import shutil
from pathlib import Path

from shipid.cli import main


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def identify_in(folder: Path, log_name: str = "zz.csv", model_name: str = "m.json") -> Path:
    """``shipid identify folder/log_name -o folder/model_name``, once, for a module's tests to
    copy with ``copy_identified``; the folder, or an error with identify's output."""
    code = main(["identify", str(folder / log_name), "-o", str(folder / model_name)])
    assert code == 0, f"identify failed on {folder / log_name}"
    return folder


def copy_identified(source: Path, target: Path, log_name: str = "zz.csv",
                    model_name: str = "m.json") -> tuple[Path, Path]:  # fmt: skip
    """The log and model file of ``identify_in(source)`` copied into ``target``, the model's
    record of its training log's path moved with it: identify's file depends on the log's
    content and path only (``test_cli.test_a_copied_identify_run_is_the_run_in_its_folder``),
    so this is the file it would write in ``target``, without a fit per test."""
    log, model = target / log_name, target / model_name
    shutil.copyfile(source / log_name, log)
    text = (source / model_name).read_text(encoding="utf-8")
    model.write_text(text.replace(str(source / log_name), str(log)), encoding="utf-8")
    return log, model


def validated(model, log, capsys, folder: Path, *options) -> dict:
    """``shipid validate MODEL LOG --json`` (exit 0 asserted): the one log's record."""
    import json

    out = Path(folder) / "validated.json"
    code, _, err = run(["validate", model, log, *options, "--json", out], capsys)
    assert code == 0, err
    (record,) = json.loads(out.read_text())["logs"]
    return record


def fresh_python(code: str) -> str:
    """What ``code`` prints run in a new interpreter (the imports a call makes, which this
    process has made already): its standard output, the run asserted clean."""
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return out.stdout
