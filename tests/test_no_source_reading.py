"""Nothing in the product reads a module's source text to get a value: a default or a
constant is imported as the value it is (or read from a function's signature), never parsed
out of a file. The scan covers every module of grainview/ and solver/."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("grainview", "solver")
SOURCE_READING = re.compile(
    r"\binspect\.getsource(?:lines|file)?\b|\bgetsource(?:lines|file)?\(|\bast\.(?:parse|literal_eval)\b"
    r"|\bimport ast\b|\bfrom ast import\b|\btokenize\.open\b|\blinecache\.getlines?\b"
    r"|with_suffix\(\s*[\"']\.py[\"']\s*\)|__file__\)?\.read_text\b")
"""What reading a module's source looks like: parsing it (ast, tokenize), asking inspect or
linecache for it, or opening a ``.py`` file or a module's ``__file__``."""


def source_readers(root: Path = ROOT) -> list[str]:
    """``path:line: text`` of every line of the packages that reads source text."""
    found = []
    for package in PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                code = line.split("#", 1)[0]
                if SOURCE_READING.search(code):
                    found.append(f"{path.relative_to(root)}:{number}: {line.strip()}")
    return found


def test_the_scan_sees_each_way_of_reading_source(tmp_path):
    (tmp_path / "grainview").mkdir()
    (tmp_path / "solver").mkdir()
    (tmp_path / "grainview" / "a.py").write_text(
        "import ast\nx = ast.literal_eval(node)\nimport inspect\ninspect.getsource(f)\n"
        "Path(m).with_suffix('.py').read_text()\n# ast.parse in a comment is words\n")
    (tmp_path / "solver" / "b.py").write_text("text = Path(__file__).read_text()\ny = 1\n")
    assert [line.split(":")[1] for line in source_readers(tmp_path)] == ["1", "2", "4", "5", "1"]


def test_nothing_in_the_tree_reads_a_module_source_to_get_a_value():
    assert source_readers() == []
