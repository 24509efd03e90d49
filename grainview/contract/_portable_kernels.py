"""The numba ufuncs behind :mod:`grainview.contract.portable_math` (compiled on import, cached).

Each is a loop of scalar calls to the C library's function of the same name: no fast-math, no
vector math library (the package sets ``NUMBA_DISABLE_INTEL_SVML``), so the bits do not depend on
the compile target.
"""

import math

from numba import vectorize

_F1 = ["float64(float64)"]
_F2 = ["float64(float64, float64)"]


@vectorize(_F2, cache=True)
def arctan2(y, x):
    return math.atan2(y, x)


@vectorize(_F1, cache=True)
def arcsin(x):
    return math.asin(x)


@vectorize(_F1, cache=True)
def exp(x):
    return math.exp(x)


@vectorize(_F1, cache=True)
def expm1(x):
    return math.expm1(x)


@vectorize(_F1, cache=True)
def log(x):
    return math.log(x)


@vectorize(_F1, cache=True)
def log1p(x):
    return math.log1p(x)
