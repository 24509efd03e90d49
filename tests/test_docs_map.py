"""docs/map.md names every module of solver/ and grainview/, and nothing else.

Each module (every ``.py`` file under the two packages and their subpackages, ``__init__.py``
aside) is one entry of the map: a table row or list item whose first backticked text is the
module's path from the repository root (```solver/nlgs.py```), followed by what it holds (an
empty cell or a bare path is no entry's description). Each subpackage is an entry
too (```grainview/formats/```, its ``__init__.py``). Every ``solver/...`` or ``grainview/...``
path the map names anywhere must exist, so a module that is moved or removed fails here as
much as one that is added and not described.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAP = ROOT / "docs" / "map.md"
PACKAGES = ("solver", "grainview")
PATH = re.compile(r"`((?:solver|grainview)/[\w./]*)`")
ENTRY = re.compile(r"^\s*(?:\|\s*|[-*]\s+)`((?:solver|grainview)/[\w./]*)`")


def modules(root: Path = ROOT) -> set[str]:
    """Every module and subpackage of the packages, as the map names them: ``solver/nlgs.py``,
    ``grainview/formats/`` (a package's ``__init__.py`` is the package)."""
    found = set()
    for package in PACKAGES:
        for path in (root / package).rglob("*.py"):
            if "__pycache__" in path.parts:
                continue
            relative = path.relative_to(root).as_posix()
            if path.name == "__init__.py":
                if path.parent != root / package:
                    found.add(relative[: -len("__init__.py")])
            else:
                found.add(relative)
    return found


def entries(text: str) -> list[str]:
    """The paths that open a table row or a list item of the map, in order."""
    return [m.group(1) for line in text.splitlines() if (m := ENTRY.match(line))]


def undescribed(text: str) -> list[str]:
    """The entries of the map with nothing said of them: a table row whose other cells are empty,
    a list item with no words after its path (punctuation and backticks aside)."""
    empty = []
    for line in text.splitlines():
        if not (m := ENTRY.match(line)):
            continue
        rest = line[m.end():]
        words = re.sub(r"[|:;,.\-–—()`\s]", "", rest.split("`", 1)[-1] if rest.startswith("`") else rest)
        if not words:
            empty.append(m.group(1))
    return empty


def named(text: str) -> set[str]:
    """Every backticked ``solver/...`` or ``grainview/...`` path anywhere in the map."""
    return set(PATH.findall(text))


def test_every_module_has_one_entry():
    listed = entries(MAP.read_text())
    missing = sorted(modules() - set(listed))
    assert not missing, f"docs/map.md has no entry for {missing}"
    twice = sorted({p for p in listed if listed.count(p) > 1})
    assert not twice, f"docs/map.md lists {twice} more than once"


def test_every_entry_says_what_its_module_holds():
    empty = undescribed(MAP.read_text())
    assert not empty, f"docs/map.md says nothing of {empty}"


def test_the_check_sees_an_entry_without_a_description():
    text = ("| module | holds |\n|---|---|\n| `solver/nlgs.py` | the sweeps |\n| `solver/empty.py` |  |\n"
            "| `solver/dash.py` | - |\n- `grainview/formats/`: readers\n- `grainview/bare.py`:\n"
            "- `grainview/tick.py` ``\n")
    assert undescribed(text) == ["solver/empty.py", "solver/dash.py", "grainview/bare.py", "grainview/tick.py"]


def test_every_path_the_map_names_exists():
    stale = sorted(p for p in named(MAP.read_text()) if not (ROOT / p).exists())
    assert not stale, f"docs/map.md names {stale}, which do not exist"


def test_the_checks_see_a_missing_and_a_stale_module(tmp_path):
    # a tree of two modules and a subpackage; a map that lists one of them and one that is gone
    for path in ("solver/__init__.py", "solver/nlgs.py", "grainview/__init__.py",
                 "grainview/formats/__init__.py", "grainview/formats/pegs.py"):
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text("")
    assert modules(tmp_path) == {"solver/nlgs.py", "grainview/formats/", "grainview/formats/pegs.py"}
    text = ("| module | holds |\n|---|---|\n| `solver/nlgs.py` | the sweeps |\n"
            "- `grainview/formats/`: readers, e.g. `grainview/formats/gone.py`\n")
    assert entries(text) == ["solver/nlgs.py", "grainview/formats/"]
    assert modules(tmp_path) - set(entries(text)) == {"grainview/formats/pegs.py"}
    assert {p for p in named(text) if not (tmp_path / p).exists()} == {"grainview/formats/gone.py"}
