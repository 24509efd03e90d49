"""Every relative link of the project's Markdown (README.md, docs/, benchmarks/ and notebooks'
neighbours) leads somewhere: the file exists, and a ``#section`` exists as a heading of the
file it names (GitHub's anchors: lower case, punctuation dropped, spaces as hyphens).

Docs move (docs/solver.md became a guide, its measurements went to benchmarks/archive/,
benchmarks' results to benchmarks/results/); a link left behind fails here."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def markdown_files(root: Path = ROOT) -> list[Path]:
    """The Markdown the project writes: README.md, docs/ and benchmarks/ (not benchmarks/_data/)."""
    files = [root / "README.md"] + sorted((root / "docs").rglob("*.md")) + sorted((root / "benchmarks").rglob("*.md"))
    return [f for f in files if "_data" not in f.relative_to(root).parts and f.exists()]


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading's text."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """The anchors of every heading of a Markdown file (outside code blocks)."""
    found, fenced = set(), False
    for line in path.read_text().splitlines():
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced and (m := re.match(r"#{1,6} (.*)", line)):
            found.add(anchor(m.group(1)))
    return found


def broken_links(path: Path) -> list[str]:
    """The relative links of ``path`` whose file or section does not exist."""
    broken, fenced = [], False
    for line in path.read_text().splitlines():
        if line.startswith("```"):
            fenced = not fenced
        if fenced:
            continue
        for target in LINK.findall(line):
            if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
                continue
            name, _, section = target.partition("#")
            where = (path.parent / name).resolve() if name else path
            if not where.exists():
                broken.append(target)
            elif section and where.suffix == ".md" and section not in anchors(where):
                broken.append(target)
    return broken


def test_every_relative_link_resolves():
    bad = {str(f.relative_to(ROOT)): links for f in markdown_files() if (links := broken_links(f))}
    assert not bad, f"broken links: {bad}"


def test_a_missing_file_and_a_missing_section_are_seen(tmp_path):
    (tmp_path / "guide.md").write_text("# Guide\n\n## Both cores: domain-decomposed sweeps\n\ntext\n")
    page = tmp_path / "page.md"
    page.write_text("[ok](guide.md) [ok](guide.md#both-cores-domain-decomposed-sweeps) [web](https://x.org/a)\n"
                    "[gone](old.md) [no section](guide.md#stopping-a-run)\n```\n[in code](nowhere.md)\n```\n")
    assert broken_links(page) == ["old.md", "guide.md#stopping-a-run"]
