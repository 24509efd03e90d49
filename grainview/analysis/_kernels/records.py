"""The records that carry the analysis kernels' arrays: a ``NamedTuple`` of arrays (structure of
arrays) or of numbers, which numba passes as one argument, as the solver's records do
(:mod:`solver.solve_records`). A kernel reads ``grid.x`` instead of taking the arrays one by one,
so that no kernel takes more than eight arguments and a field is named in one place (here).
Numba compiles a kernel for the record's field types, so the machine code is that of the loose
arrays.

Shapes: R rows (snapshots, batched), C contact slots, P particles or points, K quantities per
source, nx, ny grid nodes. Lengths in m, forces in N.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["XY", "Slots", "Grid", "Points", "Segments"]


class XY(NamedTuple):
    """A vector per entry as its two components, each float64 (R, C) or (R, P).

    Attributes
    ----------
    x, y : float64 array
        The components.
    """

    x: np.ndarray
    y: np.ndarray


class Slots(NamedTuple):
    """The contact slots of each row: their bodies and which count.

    Attributes
    ----------
    i, j : int64 (R, C)
        The two bodies of each slot (a wall or an empty slot: outside [0, P)).
    mask : bool (R, C)
        The slots that count.
    """

    i: np.ndarray
    j: np.ndarray
    mask: np.ndarray


class Grid(NamedTuple):
    """The nodes a coarse-grained field is spread onto, and its truncated Gaussian.

    Attributes
    ----------
    x : float64 (nx,)
        Node abscissae, ascending, m.
    y : float64 (ny,)
        Node ordinates, ascending, m.
    width : float
        Standard deviation w of the Gaussian, m.
    cutoff : float
        Radius c at which it is cut, m.
    """

    x: np.ndarray
    y: np.ndarray
    width: float
    cutoff: float


class Points(NamedTuple):
    """Point sources (the particles' centres) of each row.

    Attributes
    ----------
    x, y : float64 (R, P)
        The points, m.
    active : bool (R, P)
        The points spread.
    weights : float64 (R, P, K)
        What each point carries.
    """

    x: np.ndarray
    y: np.ndarray
    active: np.ndarray
    weights: np.ndarray


class Segments(NamedTuple):
    """Segment sources (the contacts' branch vectors) of each row, from (start_x, start_y) to
    (start_x + length_x, start_y + length_y).

    Attributes
    ----------
    start_x, start_y : float64 (R, C)
        The segments' starts, m.
    length_x, length_y : float64 (R, C)
        The segments themselves, m.
    active : bool (R, C)
        The segments spread.
    weights : float64 (R, C, K)
        What each segment carries.
    """

    start_x: np.ndarray
    start_y: np.ndarray
    length_x: np.ndarray
    length_y: np.ndarray
    active: np.ndarray
    weights: np.ndarray
