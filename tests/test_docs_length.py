"""The guides stay guides: docs/solver.md at most 400 lines (measurements belong in
benchmarks/), the README's speed section at most 12 lines under its heading."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def section_lines(text: str, heading: str) -> list[str]:
    """The lines under ``heading`` (a '## ' line) up to the next '## ' heading, blank ends trimmed."""
    lines = text.splitlines()
    start = lines.index(heading) + 1
    end = next((k for k in range(start, len(lines)) if lines[k].startswith("## ")), len(lines))
    body = lines[start:end]
    while body and not body[0].strip():
        body.pop(0)
    while body and not body[-1].strip():
        body.pop()
    return body


def test_solver_guide_is_at_most_400_lines():
    assert len((ROOT / "docs" / "solver.md").read_text(encoding="utf-8").splitlines()) <= 400


def test_readme_speed_section_is_at_most_12_lines():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(section_lines(readme, "## Speed and accuracy")) <= 12


def test_section_lines_by_hand():
    assert section_lines("# t\n## A\n\nx\ny\n\n## B\nz\n", "## A") == ["x", "y"]
