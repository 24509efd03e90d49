"""docs/solver.md's table of the solvers, by name, reads like the registry: one row per
registered method, in the stepper and on a matrix exactly where the registry says."""

import pathlib
import re

from solver import contact_solvers

GUIDE = pathlib.Path(__file__).resolve().parents[2] / "docs" / "solver.md"


def _table_rows(text):
    """{method: (stepper, matrix)} of the table under '### The solvers, by name'."""
    section = text.split("### The solvers, by name", 1)[1].split("\n#", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        name = re.fullmatch(r"`([a-z_]+)`(?: \(default\))?", cells[0]) if len(cells) >= 4 else None
        if name:
            rows[name.group(1)] = (cells[1] == "yes", cells[2] == "yes")
    return rows


def test_the_guides_table_lists_every_registered_method_where_it_runs():
    rows = _table_rows(GUIDE.read_text(encoding="utf-8"))
    registered = {m: (m in contact_solvers.stepper_methods(), m in contact_solvers.matrix_methods())
                  for m in (*contact_solvers.stepper_methods(), *contact_solvers.matrix_methods())}
    assert rows == registered
    from solver.parameters import Parameters

    assert f"| `{Parameters.solver}` (default) |" in GUIDE.read_text(encoding="utf-8")


def test_the_table_reader_sees_a_missing_or_wrong_row():
    text = GUIDE.read_text(encoding="utf-8")
    assert "pcg" not in _table_rows(re.sub(r"\n\| `pcg` \|[^\n]*", "", text))
    assert _table_rows(text.replace("| `newton` | |", "| `newton` | yes |"))["newton"][0]
