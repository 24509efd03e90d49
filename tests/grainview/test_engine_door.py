"""The application reaches the solver through one door, :mod:`solver.engine`: grainview/app
imports nothing else of ``solver``. The engines are one registry: ``--engine``'s choices and
help, the README's table and the scenes each engine runs all come from it."""

import ast
import pathlib
import re
import subprocess
import sys

import pytest

from grainview.contract.errors import ParameterError
from solver import engine as engines

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOOR = "solver.engine"


def solver_imports(source: str) -> list:
    """The modules of ``solver`` that ``source`` imports other than :data:`DOOR`, as written
    (``from solver import x`` names ``solver.x``; imports inside functions count)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and not node.level and node.module:
            if node.module == "solver":
                found += [f"solver.{alias.name}" for alias in node.names if f"solver.{alias.name}" != DOOR]
            elif node.module.split(".")[0] == "solver" and node.module != DOOR:
                found.append(node.module)
        elif isinstance(node, ast.Import):
            found += [alias.name for alias in node.names
                      if alias.name.split(".")[0] == "solver" and alias.name != DOOR]
    return found


def test_the_door_guard_sees_every_other_way_in():
    source = ("import solver\nimport solver.stepper\nfrom solver import engine, scenes\n"
              "def f():\n    from solver.restart import resume\n    import solver.engine\n"
              "    from solver.engine import Parameters\n")
    assert solver_imports(source) == ["solver", "solver.stepper", "solver.scenes", "solver.restart"]


def test_the_application_imports_only_the_engine_interface_of_the_solver():
    found = {path.relative_to(ROOT).as_posix(): solver_imports(path.read_text(encoding="utf-8"))
             for path in sorted((ROOT / "grainview" / "app").rglob("*.py"))}
    assert {path: names for path, names in found.items() if names} == {}, \
        "grainview/app reaches the solver through solver.engine only (re-export or wrap what it needs there)"


def test_every_record_of_the_door_is_its_homes_and_the_door_invents_none():
    import importlib

    for home, names in engines.RECORDS.items():
        for name in names:
            door_name = {v: k for k, v in engines._RENAMED.items()}.get(name, name)
            assert getattr(engines, door_name) is getattr(importlib.import_module(f"solver.{home}"), name)
    with pytest.raises(AttributeError):
        engines.method  # only as solver_method
    with pytest.raises(ImportError):
        exec("from solver.engine import Simulation")


def test_loading_the_door_loads_no_numba():
    code = "import sys, solver.engine; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "False"


class BiaxialOnly:
    """An engine that declares no scenes: the base ones."""

    name = "biaxial-only"


def test_each_engine_declares_its_scenes_and_the_refusal_reads_them(monkeypatch):
    assert "shear" in engines.scenes_of(engines.engine()) and engines.scenes_of(BiaxialOnly()) == engines.BASE_SCENES
    engines.check_scene(None, "shear")
    monkeypatch.setitem(engines.ENGINES, "biaxial-only", f"{__name__}:BiaxialOnly")
    engines.check_scene("biaxial-only", "biaxial")
    with pytest.raises(ParameterError, match=r"^scene shear: the periodic cell is this package's solver's "
                       r"\(solver\), not engine biaxial-only's$"):
        engines.check_scene("biaxial-only", "shear")
    monkeypatch.setattr(BiaxialOnly, "scenes", (*engines.BASE_SCENES, "shear"), raising=False)
    engines.check_scene("biaxial-only", "shear")


def test_the_command_line_refuses_a_scene_its_engine_does_not_declare(monkeypatch, tmp_path, capsys):
    from grainview.app.cli import main

    monkeypatch.setitem(engines.ENGINES, "biaxial-only", f"{__name__}:BiaxialOnly")
    assert main(["run", "shear", "--engine", "biaxial-only", "--out", str(tmp_path / "s.nc"), "--progress", "off"]) == 2
    assert "scene shear: the periodic cell is this package's solver's (solver), not engine biaxial-only's" in \
        capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_engine_option_comes_from_the_registry():
    from grainview.app.cli import build_parser

    action = next(a for a in build_parser()._subparsers._group_actions[0].choices["run"]._actions
                  if "--engine" in a.option_strings)
    assert list(action.choices) == engines.engine_names() and action.default == engines.DEFAULT_ENGINE
    assert action.help == engines.engine_help() and engines.engine_class().summary in action.help


def _readme_rows(text):
    """{engine: (class, scenes, what)} of the README's table of engines."""
    rows = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 4 and re.fullmatch(r"`[\w.:-]+`", cells[1] or "") and ":" in cells[1]:
            rows[cells[0].strip("`")] = (cells[1].strip("`"), tuple(cells[2].split(", ")), cells[3])
    return rows


def test_the_readmes_table_of_engines_is_the_registry():
    rows = _readme_rows((ROOT / "README.md").read_text(encoding="utf-8"))
    expected = {name: (target, engines.scenes_of(engines.engine_class(name)), engines.engine_class(name).summary)
                for name, target in engines.ENGINES.items()}
    assert rows == expected, "README.md's rows should read " + "; ".join(
        f"| `{n}` | `{t}` | {', '.join(s)} | {w} |" for n, (t, s, w) in expected.items())
