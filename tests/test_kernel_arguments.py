"""No compiled kernel of the tree takes more than MAX_ARGUMENTS arguments: the contact problem,
the bodies' state and the solvers' scratch reach the solver's kernels as records
(:mod:`solver.solve_records`), the analysis's its own records, not loose arrays.

Every module under solver/, grainview/ and benchmarks/research/ (subfolders included) is read,
and a kernel is every function numba compiles: decorated (``@njit``, ``@numba.njit(...)``,
``@jit``) or made by a call (``kernel = njit(cache=True)(function)``, ``njit(function)``)."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("solver", "grainview", "benchmarks/research")
MAX_ARGUMENTS = 8
MODULES = sorted(path.relative_to(ROOT).as_posix() for folder in FOLDERS for path in (ROOT / folder).rglob("*.py")
                 if "__pycache__" not in path.parts)


def _is_njit(node) -> bool:
    """Whether ``node`` is numba's ``njit`` or ``jit`` (bare, called with options, or as
    ``numba.njit``)."""
    target = node.func if isinstance(node, ast.Call) else node
    name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
    return name in ("njit", "jit")


def _count(args: ast.arguments) -> int:
    """Positional, keyword-only, ``*args`` and ``**kwargs``: each counts one."""
    return (len(args.posonlyargs) + len(args.args) + len(args.kwonlyargs) + (args.vararg is not None)
            + (args.kwarg is not None))


def _compiled_by_call(node) -> ast.AST | None:
    """The function argument of a call that compiles it: ``njit(f)``, ``njit(f, cache=True)``
    or ``njit(cache=True)(f)`` (a name or a lambda); None for any other node."""
    if not isinstance(node, ast.Call) or not node.args:
        return None
    if _is_njit(node.func) and isinstance(node.func, ast.Call):  # njit(options)(f)
        return node.args[0]
    if _is_njit(node.func) and isinstance(node.args[0], (ast.Name, ast.Lambda)):  # njit(f)
        return node.args[0]
    return None


def kernel_arguments(source: str) -> dict:
    """{kernel name: number of arguments} of every function of ``source`` that numba compiles
    (module docstring). A kernel made by a call is named after the function it compiles (a
    lambda after the name it is assigned to, or ``<lambda>``)."""
    tree = ast.parse(source)
    functions = {node.name: node for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef,
                                                                                 ast.AsyncFunctionDef))}
    out = {name: _count(node.args) for name, node in functions.items()
           if any(_is_njit(d) for d in node.decorator_list)}
    assigned = {id(node.value): node.targets[0].id for node in ast.walk(tree)
                if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name)}
    for node in ast.walk(tree):
        compiled = _compiled_by_call(node)
        if isinstance(compiled, ast.Name) and compiled.id in functions:
            out[compiled.id] = _count(functions[compiled.id].args)
        elif isinstance(compiled, ast.Lambda):
            out[assigned.get(id(node), "<lambda>")] = _count(compiled.args)
    return out


def test_the_walk_counts_arguments_and_finds_kernels():
    source = ("from numba import njit\nimport numba\n"
              "@njit(cache=True)\ndef wide(a, b, c, d, e, f, g, h, i):\n    pass\n"
              "@numba.njit\ndef narrow(a, *rest, key=0):\n    pass\n"
              "def plain(a, b, c, d, e, f, g, h, i, j):\n    pass\n")
    assert kernel_arguments(source) == {"wide": 9, "narrow": 3}
    assert sum(kernel_arguments((ROOT / name).read_text()) != {} for name in MODULES) >= 10


def test_the_walk_finds_kernels_made_by_calling_njit():
    source = ("from numba import njit\nimport numba\n"
              "def _loose(a, b, c, d, e, f, g, h, i):\n    pass\n"
              "def _called(a, b):\n    pass\n"
              "def _plain(a, b, c, d, e, f, g, h, i, j):\n    pass\n"
              "loose = njit(cache=True)(_loose)\n"
              "called = numba.njit(_called, cache=True)\n"
              "square = njit(lambda a, b, c, d, e, f, g, h, i, j: a)\n"
              "not_a_kernel = len(_plain)\n")
    assert kernel_arguments(source) == {"_loose": 9, "_called": 2, "square": 10}


def test_every_folder_and_subfolder_is_read():
    assert {"solver/contact_solvers.py", "grainview/analysis/_kernels/force_chains.py",
            "benchmarks/research/two_level.py"} <= set(MODULES)
    assert any(name.count("/") >= 3 for name in MODULES)  # a subfolder's subfolder


@pytest.mark.parametrize("module", MODULES)
def test_no_kernel_takes_more_than_eight_arguments(module):
    wide = {name: count for name, count in kernel_arguments((ROOT / module).read_text()).items()
            if count > MAX_ARGUMENTS}
    assert not wide, (f"{module}: kernels with more than {MAX_ARGUMENTS} arguments {wide}; pass the problem, state "
                      "and scratch as records (solver/solve_records.py, grainview/analysis/_kernels/records.py)")
