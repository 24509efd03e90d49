"""No compiled kernel of the solver takes more than MAX_ARGUMENTS arguments: the contact
problem, the bodies' state and the solvers' scratch reach the kernels as records
(:mod:`solver.solve_records`), not as loose arrays."""

import ast
from pathlib import Path

import pytest

SOLVER = Path(__file__).resolve().parents[2] / "solver"
MAX_ARGUMENTS = 8
MODULES = sorted(path.name for path in SOLVER.glob("*.py"))


def _is_njit(decorator) -> bool:
    """Whether a decorator is numba's ``njit`` or ``jit`` (bare, called, or as ``numba.njit``)."""
    target = decorator.func if isinstance(decorator, ast.Call) else decorator
    name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
    return name in ("njit", "jit")


def kernel_arguments(source: str) -> dict:
    """{kernel name: number of arguments} of every njit-decorated function in ``source``
    (positional, keyword-only, ``*args`` and ``**kwargs`` each count one)."""
    out = {}
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef) and any(_is_njit(d) for d in node.decorator_list):
            args = node.args
            out[node.name] = (len(args.posonlyargs) + len(args.args) + len(args.kwonlyargs)
                              + (args.vararg is not None) + (args.kwarg is not None))
    return out


def test_the_walk_counts_arguments_and_finds_kernels():
    source = ("from numba import njit\nimport numba\n"
              "@njit(cache=True)\ndef wide(a, b, c, d, e, f, g, h, i):\n    pass\n"
              "@numba.njit\ndef narrow(a, *rest, key=0):\n    pass\n"
              "def plain(a, b, c, d, e, f, g, h, i, j):\n    pass\n")
    assert kernel_arguments(source) == {"wide": 9, "narrow": 3}
    assert sum(kernel_arguments((SOLVER / name).read_text()) != {} for name in MODULES) >= 5


@pytest.mark.parametrize("module", MODULES)
def test_no_kernel_takes_more_than_eight_arguments(module):
    wide = {name: count for name, count in kernel_arguments((SOLVER / module).read_text()).items()
            if count > MAX_ARGUMENTS}
    assert not wide, (f"solver/{module}: kernels with more than {MAX_ARGUMENTS} arguments {wide}; pass the "
                      "problem, state and scratch as records (solver/solve_records.py)")
