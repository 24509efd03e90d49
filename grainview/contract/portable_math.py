"""Elementwise functions that give the same bits on every x86-64 processor.

numpy picks the loops of ``np.exp``, ``np.log``, ``np.arctan2``, ``np.arcsin`` (and most other
transcendental functions) by the processor it runs on: with AVX-512 it takes vectorised
implementations whose results differ in the last bit from those it takes on a processor with
AVX2 only. A value that feeds a simulation, or a number a report prints, must not depend on
that. The functions here take the C library's scalar function instead: one implementation on
every x86-64 processor with FMA (docs/reproducibility.md says what is and is not covered).

Small numpy inputs (at most :data:`SMALL` elements: a time series, a polygon's vertices) go
through Python's :mod:`math`, which calls the C library's function, so the light paths
(``grainview info``) load no compiler; larger ones, and dask arrays, through numba ufuncs
(:mod:`grainview.contract._portable_kernels`) that call the same function in a compiled loop.
Both give the same bits (``tests/grainview/test_portable_math.py``). The results follow numpy's
conventions: float64, broadcast, ``log(0) = -inf``, nan outside the domain, inf on overflow,
with numpy's floating-point warnings for the latter (``np.errstate`` silences them).
DataArrays keep their coordinates.

``np.sin``, ``np.cos``, ``np.hypot`` and ``np.sqrt`` need no replacement: numpy's results for
them are the same with and without AVX-512.
"""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np

__all__ = ["arctan2", "arcsin", "exp", "expm1", "log", "log1p", "SMALL"]

SMALL = 4096
"""Inputs of at most this many elements are computed with :mod:`math` (no numba)."""

_INF, _NAN = math.inf, math.nan


@functools.cache
def _kernels():
    from . import _portable_kernels  # numba loads here, on the first large input, not on import

    return _portable_kernels


def _log(x):
    if x > 0:
        return math.log(x)
    return -_INF if x == 0 else _NAN


def _log1p(x):
    if x > -1:
        return math.log1p(x)
    return -_INF if x == -1 else _NAN


def _exp(x):
    try:
        return math.exp(x)
    except OverflowError:
        return _INF


def _expm1(x):
    try:
        return math.expm1(x)
    except OverflowError:
        return _INF


def _asin(x):
    return math.asin(x) if -1.0 <= x <= 1.0 else _NAN


_SCALAR = {"arctan2": math.atan2, "arcsin": _asin, "exp": _exp, "expm1": _expm1, "log": _log, "log1p": _log1p}
"""The scalar function of each name, numpy's conventions at the edges of its domain."""


def _warn(name, args, out):
    """numpy's floating-point warnings for what the scalar loop produced: 'invalid' where a
    finite input gave nan, 'divide' for log(0), 'overflow' where a finite input gave inf; each
    acted on as ``np.errstate`` says (ignored, warned, or raised)."""
    finite_in = np.logical_and.reduce([np.isfinite(a) for a in args])
    if (np.isnan(out) & finite_in).any():
        _signal("invalid", name)
    if (np.isinf(out) & finite_in).any():
        _signal("divide" if name in ("log", "log1p") else "overflow", name)


def _signal(kind, name):
    """Act on numpy's floating-point condition ``kind`` met in ``name`` as numpy's error state
    says: nothing, a RuntimeWarning, or a FloatingPointError."""
    action = np.geterr()[{"overflow": "over", "divide": "divide", "invalid": "invalid"}[kind]]
    text = {"invalid": "invalid value", "divide": "divide by zero", "overflow": "overflow"}[kind]
    if action == "raise":
        raise FloatingPointError(f"{text} encountered in {name}")
    if action != "ignore":
        warnings.warn(f"{text} encountered in {name}", RuntimeWarning, stacklevel=4)


def _apply(name, *args):
    """``name`` of the C library on ``args`` elementwise: :mod:`math` for small numpy inputs,
    the numba ufunc otherwise (module docstring)."""
    data = [getattr(a, "data", a) if _is_numpy_dataarray(a) else a for a in args]
    if all(isinstance(d, (np.ndarray, float, int, np.floating, np.integer)) for d in data):
        arrays = np.broadcast_arrays(*[np.asarray(d, dtype=np.float64) for d in data])
        if arrays[0].size <= SMALL:
            function = _SCALAR[name]
            out = np.fromiter(map(function, *[a.ravel().tolist() for a in arrays]), np.float64,
                              count=arrays[0].size).reshape(arrays[0].shape)
            _warn(name, arrays, out)
            wrapped = next((a for a in args if _is_numpy_dataarray(a)), None)
            if wrapped is not None:
                return wrapped.copy(data=out) if wrapped.shape == out.shape else getattr(_kernels(), name)(*args)
            return out[()] if out.ndim == 0 else out
    return getattr(_kernels(), name)(*args)


def _is_numpy_dataarray(value) -> bool:
    """An xarray DataArray (or Variable) holding a numpy array (duck-typed: the contract does
    not import xarray)."""
    return hasattr(value, "dims") and hasattr(value, "copy") and isinstance(getattr(value, "data", None), np.ndarray)


def arctan2(y, x):
    """Angle of the point (x, y) in (-pi, pi], rad: the C library's ``atan2``, elementwise."""
    return _apply("arctan2", y, x)


def arcsin(x):
    """Inverse sine in [-pi/2, pi/2], rad (nan outside [-1, 1]): the C library's ``asin``."""
    return _apply("arcsin", x)


def exp(x):
    """e^x: the C library's ``exp``, elementwise."""
    return _apply("exp", x)


def expm1(x):
    """e^x - 1, accurate for small x: the C library's ``expm1``, elementwise."""
    return _apply("expm1", x)


def log(x):
    """Natural logarithm (nan for x < 0, -inf at 0): the C library's ``log``, elementwise."""
    return _apply("log", x)


def log1p(x):
    """log(1 + x), accurate for small x: the C library's ``log1p``, elementwise."""
    return _apply("log1p", x)
