"""The README's showcase: docs/figures/headline_400.md is the headline table `grainview study`
writes with its defaults, and the README quotes that table's numbers.

The first check runs the study (400 particles of each shape to eps_1 = 0.2: 2-3 minutes on
two free cores, longer on busy ones), so it is marked slow and `.ci/run` runs it apart. Two runs of the study on the
same machine give the same files bit for bit (one process per sample, each serial), so on the
machine the table was made on (its processor and the numba, llvmlite and numpy versions,
recorded in docs/figures/headline_400.machine.json) the tables are compared cell for cell, as
written: any difference is a change of the solver, of the analysis or of the report, and the
committed table must be regenerated with the README's command. Elsewhere numba compiles other
machine code (other vector widths change the order of sums), the trajectories part after a
while, and the numbers are compared within the scatter of one 400-particle sample instead
(docs/fidelity.md: 0.05-0.1 between seeds), which still catches a table gone stale by a change
of the code larger than that. The second check is fast: every number of the README's showcase table, and the
numbers its paragraph quotes from the table, are the committed table's, rounded as quoted.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHOWCASE = ROOT / "docs" / "figures" / "headline_400.md"
README = ROOT / "README.md"
MACHINE = ROOT / "docs" / "figures" / "headline_400.machine.json"
REGENERATE = ("grainview study --out study --overwrite && cp study/report/figures/"
              "fig{03_q_over_p,13_force_chains_pentagons,14_force_pdfs}.png docs/figures/ && "
              "cp study/report/headline.md docs/figures/headline_400.md && python3 tests/test_showcase.py --record-machine")


def machine() -> dict:
    """What decides the study's machine code: the processor (model, widest vector extension) and
    the versions of numba, llvmlite, numpy and Python."""
    import platform

    import llvmlite
    import numba
    import numpy

    model, flags = platform.processor() or platform.machine(), set()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name") and model in ("", platform.machine()):
                    model = line.split(":", 1)[1].strip()
                elif line.startswith("flags"):
                    flags = set(line.split(":", 1)[1].split())
                    break
    except OSError:
        pass
    vector = next((f for f in ("avx512f", "avx2", "avx", "sse4_2") if f in flags), "unknown")
    return {"processor": model, "vector": vector, "numba": numba.__version__, "llvmlite": llvmlite.__version__,
            "numpy": numpy.__version__, "python": platform.python_version()}


def numeric_differences(committed: str, fresh: str, absolute=0.1, relative=0.05) -> list[str]:
    """One line per number of the table (not the notes) that differs by more than
    ``absolute + relative |committed|`` between two headline tables; text cells are skipped."""
    old, new = headline_rows(committed), headline_rows(fresh)
    lines = []
    for key, cells in old.items():
        if key == "notes":
            continue
        for column, (a, b) in enumerate(zip(cells, new.get(key, [None] * len(cells)))):
            try:
                a, b = float(a), float(b)
            except (TypeError, ValueError):
                continue
            if not abs(a - b) <= absolute + relative * abs(a) and not (a != a and b != b):
                lines.append(f"{key} (column {column + 1}): committed {a}, the study gives {b}")
    return lines


def headline_rows(text: str) -> dict:
    """{quantity: [cells]} of a headline table in Markdown, and {"notes": [paragraphs]} under it."""
    rows, notes = {}, []
    for line in text.splitlines():
        if line.startswith("|---"):
            continue
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
            rows[cells[0]] = cells[1:]
        elif line.strip():
            notes.append(line.strip())
    rows["notes"] = notes
    return rows


def differences(committed: str, fresh: str) -> list[str]:
    """One line per row (or note) that differs between two headline tables."""
    old, new = headline_rows(committed), headline_rows(fresh)
    lines = []
    for key in dict.fromkeys([*old, *new]):
        if old.get(key) != new.get(key):
            lines.append(f"{key}: committed {old.get(key)} , the study gives {new.get(key)}")
    return lines


def test_differences_name_each_changed_row():
    table = "| quantity | a | b |\n|---|---|---|\n| q/p | 0.546 | 0.350 |\n| z | 2.880 | 3.750 |\n\nnote one\n"
    assert differences(table, table) == []
    changed = table.replace("2.880", "2.835").replace("note one", "note two")
    assert differences(table, changed) == ["z: committed ['2.880', '3.750'] , the study gives ['2.835', '3.750']",
                                           "notes: committed ['note one'] , the study gives ['note two']"]
    assert differences(table, table + "| k_s | 0.5 | - |\n")[0].startswith("k_s: committed None")


@pytest.mark.slow
def test_the_committed_headline_is_what_the_study_gives(tmp_path):
    from grainview.app.cli import main

    import json

    assert main(["study", "--out", str(tmp_path / "study"), "--progress", "off"]) == 0
    fresh = (tmp_path / "study" / "report" / "headline.md").read_text()
    recorded = json.loads(MACHINE.read_text()) if MACHINE.exists() else None
    same_machine = recorded == machine()
    changed = (differences if same_machine else numeric_differences)(SHOWCASE.read_text(), fresh)
    where = ("" if same_machine else f" (compared within the scatter of a sample: made on {recorded}, this is "
             f"{machine()})")
    assert not changed, (f"{SHOWCASE.relative_to(ROOT)} is not what `grainview study` gives today{where}; "
                         f"regenerate it with `{REGENERATE}` (from the repository root) and update the README's "
                         "numbers:\n" + "\n".join(changed))


def test_numeric_differences_allow_a_samples_scatter_only():
    table = "| quantity | a | b |\n|---|---|---|\n| q/p | 0.546 | 0.350 |\n| z | 2.880 | text |\n\nnote 331\n"
    moved = table.replace("0.546", "0.590").replace("note 331", "note 332")
    assert numeric_differences(table, moved) == []
    stale = table.replace("2.880", "2.500")
    assert numeric_differences(table, stale) == ["z (column 1): committed 2.88, the study gives 2.5"]


def test_the_machine_of_the_committed_table_is_recorded():
    import json

    recorded = json.loads(MACHINE.read_text())
    assert set(recorded) == set(machine())


CROSS_TERM = "(a' + a_n + a_t)/(2 + a' a_n) (residual)"


def _value(rows, quantity, column):
    """The committed table's number in ``column`` (0: pentagons, this run; 2: disks, this run)."""
    return float(rows[quantity][column])


README_ROWS = {"stress ratio q/p": ("q/p (residual)", "{:.2f}"), "fabric anisotropy a": ("a (residual)", "{:.2f}"),
               "strong-force exponent alpha": ("alpha (strong-force pdf)", "{:.2f}"),
               "coordination z": ("z (residual)", "{:.2f}")}
"""The rows of the README's headline table: the committed table's quantity and how it is rounded."""


def readme_table(section: str) -> dict:
    """{row: {"disks": cell, "pentagons": cell}} of the README's headline table (its first table
    whose header starts with 'residual state')."""
    lines = section.splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("| residual state"))
    header = [c.strip() for c in lines[first].strip().strip("|").split("|")]
    rows = {}
    for line in lines[first + 2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        rows[cells[0]] = {"disks": cells[header.index("disks")], "pentagons": cells[header.index("pentagons")]}
    return rows


def test_the_readme_quotes_the_committed_headline():
    rows = headline_rows(SHOWCASE.read_text())
    readme = README.read_text()
    section = readme[readme.index("## What it looks like"):readme.index("## Speed and accuracy")]
    table = readme_table(section)
    assert set(table) == set(README_ROWS)
    pent, disk = 0, 2
    for label, (quantity, rounding) in README_ROWS.items():
        assert table[label]["disks"] == rounding.format(_value(rows, quantity, disk)), label
        assert table[label]["pentagons"] == rounding.format(_value(rows, quantity, pent)), label
    prose = " ".join(section.split())  # the paragraph's line breaks do not matter
    assert f"({rows[CROSS_TERM][pent]} against {rows['q/p (residual)'][pent]} here)" in prose
    # the steps that ended at the sweep cap, as the notes under the table count them
    counts = {}
    for note in rows["notes"]:
        label, steps, of = re.match(r"\*\*(\w+)\.\*\* NLGS convergence: (\d+) of the test's (\d+) steps", note).groups()
        counts[label] = f"{int(steps):,} of the {label}' {int(of):,}"
    assert f"({counts['pentagons']}, {counts['disks']})" in prose


def test_the_readme_table_is_read_cell_by_cell():
    section = ("text\n\n| residual state | disks | paper | pentagons | paper |\n|---|---|---|---|---|\n"
               "| stress ratio q/p | 0.27 | 0.28 | 0.55 | 0.35 |\n| coordination z | 3.02 | 3.85 | 2.88 | 3.75 |\n\nmore\n")
    assert readme_table(section) == {"stress ratio q/p": {"disks": "0.27", "pentagons": "0.55"},
                                     "coordination z": {"disks": "3.02", "pentagons": "2.88"}}


if __name__ == "__main__":
    import json
    import sys

    if sys.argv[1:] != ["--record-machine"]:
        sys.exit("usage: python3 tests/test_showcase.py --record-machine")
    MACHINE.write_text(json.dumps(machine(), indent=1) + "\n")
    print(f"wrote {MACHINE.relative_to(ROOT)}")
