"""Every code block of the README and of its guides (``docs/*.md``, in ``GUIDES``' order)
runs as written (issue #11 item 15).

```python blocks run in order in one namespace; ```sh blocks run line by line (``make`` lines
excepted: they are this suite's own entry point), in a scratch folder beside a link to the shared
data. Other lines run in bash; a ``.venv/bin/shipid`` line is expanded by bash (variables, globs,
quotes) and then run in this process through ``shipid.cli.main``, the function the installed
command calls, which saves a second of start-up per line (the installed command itself is
exercised by ``test_cli``). Blocks that use ``../shared/data`` are skipped when it is absent.
```text blocks are synopses and are not run.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
# The README's blocks first, then each guide's: a guide's commands use the README's files (the
# Esso logs it imports) and an earlier guide's (docs/evaluation.md exports docs/kvlcc2.md's model).
GUIDES = ("esso", "kvlcc2", "structures", "physics-and-uncertainty", "studies", "evaluation",
          "logs-and-files")
PAGES = [ROOT / "README.md", *(ROOT / "docs" / f"{g}.md" for g in GUIDES)]
FENCED = [(page.relative_to(ROOT).as_posix(), kind, code) for page in PAGES
          for kind, code in re.findall(r"^```(\w+)\n(.*?)^```", page.read_text(encoding="utf-8"),
                                       flags=re.S | re.M)]  # fmt: skip
BLOCKS = [(kind, code) for _, kind, code in FENCED]
# The blocks build on each other's files (import, then select, then validate) in one folder: under
# pytest-xdist they must run on one worker, in order: make test passes --dist loadfile.


def test_every_guide_is_run():
    """A guide added to docs/ without a place in ``GUIDES`` would go untested."""
    assert sorted(GUIDES) == sorted(p.stem for p in (ROOT / "docs").glob("*.md"))


def test_the_readme_has_runnable_blocks():
    kinds = [k for k, _ in BLOCKS]
    assert "python" in kinds and "sh" in kinds
    assert set(kinds) <= {"python", "sh", "text"}, kinds


# What the blocks that read ../shared/data write (-o): a later block that uses one needs the data
# too, though it does not name it (without the data those files are never written).
DATA_OUTPUTS = {out for _, code in BLOCKS if "shared/data" in code
                for out in re.findall(r"-o\s+(\S+)", code)}  # fmt: skip


def _needs_data(code: str) -> bool:
    return "shared/data" in code or any(out in code for out in DATA_OUTPUTS)


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    """A folder laid out like the repository's parent: work/<repo> with ../shared beside it."""
    base = tmp_path_factory.mktemp("readme")
    repo = base / "repo"
    repo.mkdir()
    if DATA.is_dir():
        (base / "shared").symlink_to(DATA.parent)
    (repo / ".venv" / "bin").mkdir(parents=True)
    (repo / ".venv" / "bin" / "shipid").symlink_to(Path(sys.executable).parent / "shipid")
    (repo / ".venv" / "bin" / "python").symlink_to(sys.executable)
    return repo


def test_python_blocks_run(scratch, monkeypatch):
    code = "\n".join(c for k, c in BLOCKS if k == "python")
    if _needs_data(code) and not DATA.is_dir():
        pytest.skip("../shared/data is not present")
    monkeypatch.chdir(scratch)
    exec(compile(code, "README.md (python blocks)", "exec"), {"__name__": "readme"})


def _commands(block: str) -> list[str]:
    joined = re.sub(r"\\\n\s*", " ", block)
    return [ln.strip() for ln in joined.splitlines()
            if ln.strip() and not ln.strip().startswith(("#", "make "))]  # fmt: skip


SH = [c for k, c in BLOCKS if k == "sh"]
SH_PAGES = [page for page, k, _ in FENCED if k == "sh"]


SHIPID = ".venv/bin/shipid "
ASSIGNMENT = re.compile(r"^[A-Za-z_]\w*=\S*$")


def _bash(script: str, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}:{os.environ.get('PATH', '')}")
    return subprocess.run(["bash", "-c", "set -euo pipefail\n" + script], cwd=cwd,
                          capture_output=True, text=True, env=env, timeout=600)  # fmt: skip


@pytest.mark.parametrize("index", range(len(SH)))
def test_shell_blocks_run(scratch, index, monkeypatch, capsys):
    from shipid.cli import main

    block = SH[index]
    commands = _commands(block)
    if not commands:
        pytest.skip("only make commands (this suite is their target)")
    if _needs_data(block) and not DATA.is_dir():
        pytest.skip("../shared/data is not present")
    monkeypatch.chdir(scratch)
    assignments: list[str] = []
    pending: list[str] = []  # bash lines kept together (a here-document spans several)

    def flush():
        if pending:
            res = _bash("\n".join(assignments + pending), scratch)
            assert res.returncode == 0, (
                f"{SH_PAGES[index]}: shell block {index} failed:\n{block}\n{res.stderr[-2000:]}")
            pending.clear()

    for line in commands:
        if ASSIGNMENT.match(line):
            assignments.append(line)
        elif line.startswith(SHIPID) and not re.search(r"[|&;<>]", line.split('"')[0]):
            flush()
            res = _bash("\n".join([*assignments, "printf '%s\\0' " + line[len(SHIPID):]]), scratch)
            assert res.returncode == 0, res.stderr
            argv = res.stdout.split("\0")[:-1]
            code = main(argv)
            err = capsys.readouterr().err
            assert code == 0, (f"{SH_PAGES[index]}: shell block {index}: shipid "
                               f"{' '.join(argv)}\n{err[-2000:]}")  # fmt: skip
        else:
            pending.append(line)
    flush()
