"""docs/solver.md's table of the solvers, by name, reads like the registry: one row per
registered method, with its status, in the stepper and on a matrix exactly where the registry
says."""

import pathlib
import re

from solver import contact_solvers

GUIDE = pathlib.Path(__file__).resolve().parents[2] / "docs" / "solver.md"


def _table_rows(text):
    """{method: (status, stepper, matrix)} of the table under '### The solvers, by name'."""
    section = text.split("### The solvers, by name", 1)[1].split("\n#", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        name = re.fullmatch(r"`([a-z_]+)`", cells[0]) if len(cells) >= 5 else None
        if name:
            rows[name.group(1)] = (cells[1], cells[2] == "yes", cells[3] == "yes")
    return rows


def registry_rows():
    """{method: (status, stepper, matrix)} as the registry has them: what the table must say."""
    names = (*contact_solvers.stepper_methods(), *contact_solvers.matrix_methods())
    return {m: (contact_solvers.method(m).status, m in contact_solvers.stepper_methods(),
                m in contact_solvers.matrix_methods()) for m in names}


def test_the_guides_table_lists_every_registered_method_with_its_status_and_where_it_runs():
    rows = _table_rows(GUIDE.read_text(encoding="utf-8"))
    expected = registry_rows()
    assert rows == expected, "docs/solver.md's rows should read " + "; ".join(
        f"| `{m}` | {status} | {'yes' if stepper else ''} | {'yes' if matrix else ''} |"
        for m, (status, stepper, matrix) in sorted(expected.items()))
    from solver.parameters import Parameters

    assert rows[Parameters.solver][0] == "default"


def test_the_table_reader_sees_a_missing_or_wrong_row():
    text = GUIDE.read_text(encoding="utf-8")
    assert "pcg" not in _table_rows(re.sub(r"\n\| `pcg` \|[^\n]*", "", text))
    assert _table_rows(text.replace("| `newton` | experimental | |", "| `newton` | experimental | yes |"))["newton"][1]
    assert _table_rows(text.replace("| `nlgs` | alternative |", "| `nlgs` | default |"))["nlgs"][0] == "default"
