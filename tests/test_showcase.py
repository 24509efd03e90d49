"""The README's showcase: docs/figures/headline_400.md is the headline table `grainview study`
writes with its defaults, and the README quotes that table's numbers.

The first check runs the study (400 particles of each shape to eps_1 = 0.2: minutes on two
cores), so it is marked slow and `.ci/run` runs it apart. How the fresh table is compared with
the committed one depends on what docs/reproducibility.md guarantees:

- **The same platform**: an x86-64 processor with AVX2 and FMA, and the same versions of
  Python, numpy, numba, llvmlite and the C library as those recorded with the table
  (docs/figures/headline_400.machine.json). There the study writes the same bits on any such
  processor, so the tables are compared cell for cell, notes included: any difference is a
  change of the solver, of the analysis or of the report, and the committed table must be
  regenerated with the README's command.
- **Anywhere else** (another library version, another architecture), the trajectories may part
  after a few hundred steps and the run is another sample of the same packing. The settings rows
  and the paper's columns, which no trajectory changes, are still compared cell for cell; each
  residual quantity whose scatter over seeds was measured (:data:`SCATTER`) is compared within
  :data:`SIGMAS` times the standard deviation of the difference of two independent samples;
  the other numbers, without a measured scatter, are not compared.
The second check is fast: every number of the README's showcase table, and the numbers its
paragraph quotes from the table, are the committed table's, rounded as quoted.
"""

from __future__ import annotations

import math
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

SCATTER = {
    "q/p (residual)": (0.025, 0.025),
    "a (residual)": (0.047, 0.032),
    "a_n (residual)": (0.039, 0.034),
    "a_t (residual)": (0.015, 0.006),
    "z (residual)": (0.033, 0.008),
    "weak fraction": (0.010, 0.010),
    "very weak fraction": (0.011, 0.007),
    "alpha (strong-force pdf)": (0.070, 0.075),
    "solid fraction (initial)": (0.004, 0.002),
    "z (initial)": (0.098, 0.024),
}
"""{row: (pentagons, disks)}: the largest standard deviation over seeds of one 400-particle
sample's value, over the tables of benchmarks/archive/same-sample.md (four to eight seeds,
two solvers, two tolerances, two machines); docs/reproducibility.md, "Tolerances from measured
scatter"."""

SIGMAS = 3.0
"""How many standard deviations of the difference of two independent samples (sqrt(2) times a
sample's) a fresh value may be from the committed one on another platform."""

SETTINGS_ROWS = ("particles", "seed", "preparation", "double-contact criterion")
"""Rows that no trajectory changes: compared cell for cell on every platform."""

THIS_RUN = {"pentagons": 0, "disks": 2}
"""The columns (after the quantity) of each shape's run; the others are the paper's."""


def machine() -> dict:
    """What decides whether the study gives the same bits as the recorded one
    (docs/reproducibility.md, "What is guaranteed"): the architecture, whether the processor has
    AVX2 and FMA, and the versions of Python, numpy, numba, llvmlite and the C library. The
    processor's model is not recorded: within the guarantee it changes nothing."""
    import platform

    import llvmlite
    import numba
    import numpy

    flags = set()
    try:
        with open("/proc/cpuinfo") as fh:
            flags = next((set(line.split(":", 1)[1].split()) for line in fh if line.startswith("flags")), set())
    except OSError:
        pass
    libc = " ".join(platform.libc_ver()).strip() or "unknown"
    return {"architecture": platform.machine(), "avx2_fma": {"avx2", "fma"} <= flags,
            "python": platform.python_version(), "numpy": numpy.__version__, "numba": numba.__version__,
            "llvmlite": llvmlite.__version__, "libc": libc}


def same_platform(recorded: dict | None, current: dict) -> bool:
    """Whether ``current`` is within the guarantee of the same bits as ``recorded``: an x86-64
    processor with AVX2 and FMA and the same library versions."""
    return (recorded == current and current["architecture"] in ("x86_64", "AMD64")
            and current["avx2_fma"] is True)


def tolerance(quantity: str, label: str) -> float:
    """How far a fresh ``quantity`` of the ``label`` run ("pentagons" or "disks") may be from
    the committed one on another platform: :data:`SIGMAS` sqrt(2) times its measured scatter."""
    return SIGMAS * math.sqrt(2) * SCATTER[quantity][0 if label == "pentagons" else 1]


def numeric_differences(committed: str, fresh: str) -> list[str]:
    """One line per difference between two headline tables that another sample could not make:
    a row added or removed, a settings row or a paper's cell changed, or a quantity of
    :data:`SCATTER` further than :func:`tolerance` from the committed one. The notes and the
    other numbers of the runs are not compared."""
    old, new = headline_rows(committed), headline_rows(fresh)
    lines = [f"{key}: committed {old.get(key)} , the study gives {new.get(key)}"
             for key in dict.fromkeys([*old, *new]) if key != "notes" and (key not in old or key not in new)]
    for key, cells in old.items():
        if key == "notes" or key not in new:
            continue
        for column, (a, b) in enumerate(zip(cells, new[key])):
            label = next((name for name, index in THIS_RUN.items() if index == column), None)
            if label is None or key in SETTINGS_ROWS:
                if a != b:
                    lines.append(f"{key} (column {column + 1}): committed {a}, the study gives {b}")
            elif key in SCATTER:
                try:
                    x, y = float(a), float(b)
                except ValueError:  # a text such as 'not reached' on either side: compared as written
                    if a != b:
                        lines.append(f"{key} ({label}): committed {a}, the study gives {b}")
                    continue
                if not (abs(x - y) <= tolerance(key, label) or (x != x and y != y)):
                    lines.append(f"{key} ({label}): committed {x}, the study gives {y} "
                                 f"(tolerance {tolerance(key, label):.3f})")
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
    exact = same_platform(recorded, machine())
    changed = (differences if exact else numeric_differences)(SHOWCASE.read_text(), fresh)
    where = ("" if exact else f" (compared within the scatter of a sample: made on {recorded}, this is "
             f"{machine()})")
    assert not changed, (f"{SHOWCASE.relative_to(ROOT)} is not what `grainview study` gives today{where}; "
                         f"regenerate it with `{REGENERATE}` (from the repository root) and update the README's "
                         "numbers:\n" + "\n".join(changed))


def test_numeric_differences_allow_a_samples_scatter_only():
    table = ("| quantity | pentagons (this run) | pentagons (paper) | disks (this run) | disks (paper) |\n"
             "|---|---|---|---|---|\n| particles | 400 5-gons | 14400 | 400 disks | 10000 |\n"
             "| q/p (residual) | 0.546 | 0.350 | 0.269 | 0.280 |\n| z (residual) | 2.880 | 3.750 | 3.020 | 3.850 |\n"
             "| k_d | 0.450 | ~0.47 (implied) | 0.000 | 0.000 |\n\nnote 331\n")
    # another sample: q/p 3.5 sd of a sample away, z 2 sd, an unmeasured row and the notes anything
    moved = (table.replace("0.546", "0.634").replace("| 2.880", "| 2.946").replace("0.450", "0.300")
             .replace("note 331", "note 332"))
    assert numeric_differences(table, moved) == []
    assert numeric_differences(table, table.replace("0.546", "0.660")) == [
        "q/p (residual) (pentagons): committed 0.546, the study gives 0.66 (tolerance 0.106)"]
    assert numeric_differences(table, table.replace("3.020", "2.980")) == [
        "z (residual) (disks): committed 3.02, the study gives 2.98 (tolerance 0.034)"]
    assert numeric_differences(table, table.replace("0.350", "0.35")) == [
        "q/p (residual) (column 2): committed 0.350, the study gives 0.35"]
    assert numeric_differences(table, table.replace("400 disks", "399 disks")) == [
        "particles (column 3): committed 400 disks, the study gives 399 disks"]
    assert numeric_differences(table, table + "| k_s | 0.5 | - | 1.0 | - |\n")[0].startswith("k_s: committed None")
    nan = table.replace("3.020", "nan")
    assert numeric_differences(nan, nan) == []
    unreached = table.replace("3.020", "not reached (eps_q 0.01)")
    assert numeric_differences(unreached, unreached) == []
    assert numeric_differences(table, unreached) == [
        "z (residual) (disks): committed 3.020, the study gives not reached (eps_q 0.01)"]


def test_the_tolerances_are_the_documented_ones():
    """docs/reproducibility.md's table gives this test's spreads and tolerances, in that order."""
    lines = (ROOT / "docs" / "reproducibility.md").read_text().splitlines()
    row = next(line for line in lines if line.startswith("| `tests/test_showcase.py`"))
    spreads, tolerances = [cell.strip() for cell in row.strip().strip("|").split(" | ")][2:]
    for quantity, (pentagons, disks) in SCATTER.items():
        assert f"{quantity} {pentagons:.3f}, {disks:.3f}" in spreads, quantity
        assert f"{quantity} {tolerance(quantity, 'pentagons'):.3f}, {tolerance(quantity, 'disks'):.3f}" in tolerances


def test_same_platform_needs_the_recorded_versions_and_fma():
    here = machine()
    assert same_platform(dict(here), here) == (here["architecture"] in ("x86_64", "AMD64") and here["avx2_fma"])
    assert not same_platform({**here, "numba": "0.0"}, here)
    assert not same_platform(None, here)
    assert not same_platform({**here, "avx2_fma": False}, {**here, "avx2_fma": False})


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
