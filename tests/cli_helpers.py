"""Running the CLI in-process from tests: exit code, stdout, stderr."""

from shipid.cli import main


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err
