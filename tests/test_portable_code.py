"""No processor-dependent floating point in the code that computes what a run writes and what an
analysis returns (docs/reproducibility.md): a fast check of the source, the guard in front of the
slow one that compiles for three processors (tests/test_processor_independence.py).

Refused, anywhere in solver/ and grainview/:

- ``fastmath`` on a numba kernel: it lets the compiler reorder sums by the target's vector width;
- numpy's transcendental functions (``np.exp``, ``np.log``, ``np.arctan2``, ...) and powers other
  than squares and square roots: numpy's loops for them change with AVX-512
  (:mod:`grainview.contract.portable_math` has the portable ones); inside a numba kernel they are
  the C library's and allowed;
- BLAS: ``@``, ``np.dot``, ``np.linalg`` (but a ``norm`` along an axis, which numpy sums itself),
  inside kernels too: OpenBLAS picks its kernels, and their order of summation, by processor.

A line may say why it is safe with a ``# portable: <reason>`` comment, on it or just above. Figures (grainview/plot)
and the matrix-form solvers of captured problems, which no run or analysis reaches, are not
checked.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOT_CHECKED = {
    "grainview/plot": "draws figures; writes no number",
    "solver/nonsmooth_newton.py": "matrix-form solver of captured problems, not a stepper method",
    "solver/matrix_form.py": "the matrix form (W, q) of a captured problem, for the matrix-form solvers",
    "solver/contact_solution.py": "residuals of a matrix-form solution, for the matrix-form solvers",
}
TRANSCENDENTAL = {"exp", "exp2", "log", "log2", "log10", "log1p", "expm1", "arctan2", "arctan", "arcsin",
                  "arccos", "arcsinh", "arccosh", "arctanh", "tan", "tanh", "sinh", "cosh", "power",
                  "float_power", "cbrt", "logaddexp", "logaddexp2", "geomspace", "logspace"}
BLAS = {"dot", "vdot", "inner", "matmul", "tensordot", "polyfit", "polyval"}
SAFE_EXPONENTS = {2, 0.5, 1, -1, 0}
KERNEL_DECORATORS = ("njit", "jit", "vectorize", "guvectorize", "stencil")


def checked_files() -> list[Path]:
    files = sorted(p for package in ("solver", "grainview") for p in (ROOT / package).rglob("*.py")
                   if "__pycache__" not in p.parts)
    return [p for p in files if not any(p.relative_to(ROOT).as_posix().startswith(k) for k in NOT_CHECKED)]


def _kernel_nodes(tree) -> set[int]:
    """The ids of every node inside a numba-compiled function."""
    inside = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and any(
                name in ast.unparse(d) for d in node.decorator_list for name in KERNEL_DECORATORS):
            inside.update(id(sub) for sub in ast.walk(node))
    return inside


def _numpy_name(node) -> str | None:
    """'exp' for ``np.exp`` / ``numpy.exp``, 'linalg.solve' for ``np.linalg.solve``, else None."""
    text = ast.unparse(node)
    for prefix in ("np.", "numpy."):
        if text.startswith(prefix):
            return text[len(prefix):]
    return None


def _constant(node):
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
        return node.value
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub) and isinstance(node.operand, ast.Constant):
        return -node.operand.value
    return None


def problems(source: str) -> list[tuple[int, str]]:
    """(line, what) for each processor-dependent operation of ``source`` (module docstring)."""
    tree = ast.parse(source)
    lines = source.splitlines()
    inside = _kernel_nodes(tree)
    found = []
    for node in ast.walk(tree):
        line = getattr(node, "lineno", None)
        if isinstance(node, ast.keyword) and node.arg == "fastmath":
            found.append((node.value.lineno, "fastmath on a numba kernel"))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            name = _numpy_name(node.func)
            if name is None:
                continue
            if name == "linalg.norm" and any(k.arg == "axis" for k in node.keywords):
                continue  # sqrt of numpy's own sum along the axis, no BLAS
            if name.startswith("linalg.") or name in BLAS:
                found.append((line, f"np.{name} (BLAS or LAPACK)"))
            elif name in TRANSCENDENTAL and id(node) not in inside:
                found.append((line, f"np.{name} (numpy's loop depends on the processor; portable_math.{name})"))
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.MatMult):
            found.append((line, "the @ operator (BLAS)"))
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow) and id(node) not in inside:
            exponent, base = _constant(node.right), _constant(node.left)
            if exponent in SAFE_EXPONENTS or (isinstance(base, int) and not isinstance(base, bool)):
                continue  # a square, a root, or an integer power of an integer: exact or correctly rounded
            if base is not None and exponent is not None:
                continue  # a constant folded by Python
            found.append((line, f"a power {ast.unparse(node)} (numpy's np.power depends on the processor)"))
    return [(n, what) for n, what in found if not any("# portable:" in lines[k] for k in (n - 1, n - 2) if k >= 0)]


@pytest.mark.parametrize("path", checked_files(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_no_processor_dependent_floating_point(path):
    assert problems(path.read_text(encoding="utf-8")) == []


def test_the_check_finds_each_kind():
    source = '''
import numpy as np
from numba import njit

@njit(cache=True, fastmath={"reassoc"})
def kernel(x, y):
    a = np.exp(x[0])          # the C library's exp inside a kernel: allowed
    return np.dot(x, y) + a   # BLAS inside a kernel: refused

def host(x, v):
    r = np.linalg.norm(v, axis=1)   # allowed
    s = x ** 2 + x ** 0.5 + 2 ** 10  # allowed
    t = x ** 3                       # refused
    u = np.arctan2(x, 1.0)          # refused
    w = v @ v.T                      # refused
    s = np.linalg.solve(v, x)       # refused
    # portable: the reason
    return np.log(x)
'''
    found = sorted(problems(source))
    assert [n for n, _ in found] == [5, 8, 13, 14, 15, 16]
    assert [what.split(" ")[0] for _, what in found] == ["fastmath", "np.dot", "a", "np.arctan2", "the",
                                                         "np.linalg.solve"]
