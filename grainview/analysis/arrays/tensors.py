"""Principal values and directions of 2x2 tensors, batched over leading axes."""

from __future__ import annotations

import numpy as np

from ...contract import portable_math
from .signature import SCALAR, TENSOR, core_dims


@core_dims(TENSOR, out=(SCALAR, SCALAR, SCALAR))
def principal(tensor):
    """Principal values and major direction of the symmetric part of ``tensor`` (..., 2, 2).

    With ``m = (T_xx + T_yy)/2``, ``d = (T_xx - T_yy)/2``, ``c = (T_xy + T_yx)/2`` and
    ``r = sqrt(d^2 + c^2)``: ``T_1 = m + r >= T_2 = m - r`` and the major direction
    ``theta = atan2(c, d)/2`` folded into [0, pi). Returns ``(T_1, T_2, theta)``.
    """
    t = np.asarray(tensor)
    mean = 0.5 * (t[..., 0, 0] + t[..., 1, 1])
    dev = 0.5 * (t[..., 0, 0] - t[..., 1, 1])
    shear = 0.5 * (t[..., 0, 1] + t[..., 1, 0])
    radius = np.hypot(dev, shear)
    theta = np.mod(0.5 * portable_math.arctan2(shear, dev), np.pi)
    return mean + radius, mean - radius, theta


def signed_anisotropy(t1, t2, theta, theta_ref, normalisation=None):
    """Signed anisotropy ``2 (T_1 - T_2)/norm * cos 2(theta - theta_ref)``.

    With ``normalisation=None`` the norm is ``T_1 + T_2`` (the trace); docs/conventions.md §2 and §3.
    """
    norm = (t1 + t2) if normalisation is None else normalisation
    with np.errstate(invalid="ignore", divide="ignore"):
        return 2.0 * (t1 - t2) / norm * np.cos(2.0 * (theta - theta_ref))
