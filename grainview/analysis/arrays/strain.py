"""Strains of the sample box (docs/conventions.md §6)."""

from __future__ import annotations

import numpy as np

from ...contract import portable_math

RESIDUAL_STRAIN = 0.3
"""Start of the residual state in shear strain eps_q (the paper reads its residual values at
eps_q >= 0.3: Figs. 7, 8, 10 and the residual plateaus of Figs. 3, 6, 9, 11)."""


def log_strain(size, reference):
    """Logarithmic strain of a box extent, compression positive: ln(1 + (L0 - L)/L0).

    ``size`` is the extent L (m) of each snapshot, ``reference`` the extent L0 (m) of the
    reference snapshot; eps_1 for the height, eps_2 for the width (paper Sec. III). Works on
    numpy arrays and on DataArrays alike (a ufunc expression)."""
    return portable_math.log(1 + (reference - size) / reference)
