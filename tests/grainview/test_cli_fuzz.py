"""Fuzzing the command line: random bytes as files and random arguments give a usage error or
one line, never a traceback, a hang or a changed input."""

import hashlib

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from grainview.app.cli import main

TOKENS = ["--to", "vtk", "csv", "--out", "--every", "0", "-1", "2.5", "--labels", "a,b", "--attrs",
          "--overwrite", "--movie", "--residual-strain", "nan", "", "--", "FILE"]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(content=st.binary(max_size=600), command=st.sampled_from(["info", "export", "report"]),
       extra=st.lists(st.sampled_from(TOKENS), max_size=5))
def test_random_files_and_arguments(tmp_path_factory, capsys, content, command, extra):
    folder = tmp_path_factory.mktemp("fuzz")
    path = folder / "input.nc"
    path.write_bytes(content)
    digest = hashlib.sha256(content).hexdigest()
    argv = [command, *[str(path) if t == "FILE" else (str(folder / "out") if t == "--out" else t) for t in extra],
            str(path)]
    if command == "export" and "--to" not in extra:
        argv += ["--to", "csv", "--out", str(folder / "out")]
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's usage error: one usage line and one error line
        code = exc.code
    err = capsys.readouterr().err
    assert code != 0 and "Traceback" not in err, (argv, err)
    assert hashlib.sha256(path.read_bytes()).hexdigest() == digest  # the input is never changed
