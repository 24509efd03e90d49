"""One registry selects the contact solver (solver/contact_solvers.py): no other module of the
library compares a value with a registered solver's name to choose what to run, keys a table by
one (``{"nlgs": ..., "pcg": ...}[name]``, ``table["pcg"]``) or matches on one (``case "pcg":``)
(the former ``acceleration`` value "off" is not looked for: progress options share the word)."""

import ast
from pathlib import Path

import pytest

from solver import contact_solvers

ROOT = Path(__file__).resolve().parents[2]
NAMES = set(contact_solvers.stepper_methods()) | set(contact_solvers.matrix_methods())
REGISTRY = ROOT / "solver" / "contact_solvers.py"


def _names(nodes) -> bool:
    """Whether one of ``nodes`` is a solver's name written out."""
    return any(isinstance(i, ast.Constant) and i.value in NAMES for i in nodes)


def name_comparisons(source: str) -> list[int]:
    """Lines of ``source`` that choose by a solver's name: a comparison with one (``==``,
    ``!=``, ``in``), a dict keyed by one, a subscript by one, a ``case`` of one."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare) and any(isinstance(op, (ast.Eq, ast.NotEq, ast.In, ast.NotIn))
                                                 for op in node.ops):
            for side in [node.left, *node.comparators]:
                if _names(side.elts if isinstance(side, (ast.Tuple, ast.List, ast.Set)) else [side]):
                    lines.append(node.lineno)
        elif isinstance(node, ast.Dict) and _names(node.keys):
            lines.append(node.lineno)
        elif isinstance(node, ast.Subscript) and _names([node.slice]):
            lines.append(node.lineno)
        elif isinstance(node, ast.MatchValue) and _names([node.value]):
            lines.append(node.lineno)
    return sorted(set(lines))


def library_modules():
    return sorted(p for folder in ("solver", "grainview") for p in (ROOT / folder).rglob("*.py") if p != REGISTRY)


@pytest.mark.parametrize("path", library_modules(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_dispatch_on_solver_names_outside_the_registry(path):
    assert not name_comparisons(path.read_text(encoding="utf-8")), (
        f"{path.relative_to(ROOT)} lines {name_comparisons(path.read_text(encoding='utf-8'))} compare with a solver "
        "name: ask the registry (solver.contact_solvers.method(name)) instead")


def test_the_check_sees_a_dispatch():
    assert name_comparisons('if p.solver == "anderson":\n    pass\n') == [1]
    assert name_comparisons('ok = kind in ("nlgs", "x")\n') == [1]
    assert name_comparisons('if progress != "off_": pass\n') == []


def test_the_check_sees_a_table_or_a_match_on_solver_names():
    assert name_comparisons('run = {"nlgs": sweep, "pcg": cg}[p.solver]\n') == [1]
    assert name_comparisons('TABLE = dict()\nTABLE["pcg"] = cg\n') == [2]
    assert name_comparisons('match p.solver:\n    case "anderson":\n        pass\n') == [2]
    assert name_comparisons('labels = {"off": 1}\nbuffer = scratch.buffer("anderson", 3)\n') == []
