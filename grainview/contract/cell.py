"""The periodic cell: lattice vectors, minimum images, wrapping, shear.

A snapshot of the contract may hold a **cell** (docs/schema.md, "The periodic cell"): its
lattice vectors ``a`` and ``b`` (rows of ``cell``, shape (2, 2), m) and, for each, whether the
sample repeats along it (``periodic``). The cell is the parallelogram

    origin + s a + t b,    0 <= s, t < 1,    origin = box_min,

in LAMMPS's restricted triclinic form: ``a = (l, 0)`` along x, ``b = (tilt, h)``, with ``l`` and
``h`` the widths of the box (``box_max - box_min``), so that the cell's area is ``l h`` whatever
its tilt. A rectangular periodic cell has ``tilt = 0``; a sheared one (Lees-Edwards, LAMMPS's
``xy`` tilt) has ``tilt != 0`` and the shear ``gamma = tilt / h``. Along a vector that is not
periodic the sample is bounded (by walls). A 3D cell is the same with a third vector.

Positions are ``wrapped`` into the cell or ``unwrapped`` (the global attribute
``cell_positions``); either way a particle stands for all its images ``x + m a + n b`` (m, n
integers along the periodic vectors). A contact's ``branch`` is the **minimum image**: the
shortest of ``x_j + m a + n b - x_i``, of the size of the particles and never of the box.

Every function here is elementwise numpy (no matrix products, so the same bits on every
processor, docs/reproducibility.md) and broadcasts: a vector argument has shape (..., 2), a
cell (..., 2, 2), ``periodic`` (2,).
"""

from __future__ import annotations

import numpy as np

__all__ = ["CELL_VECTORS", "CELL_POSITIONS", "restricted_cell", "cell_area", "fractional", "from_fractional",
           "minimum_image", "image_shift", "wrap", "shear_tilt", "unwrap_tilt", "cell_problems",
           "branch_problems"]

CELL_VECTORS = ("a", "b")
"""The names of the cell's lattice vectors, the coordinate of the dimension ``cell_vector``."""
CELL_POSITIONS = ("wrapped", "unwrapped")
"""Values of the global attribute ``cell_positions``: the particles' centres inside the cell
(along its periodic vectors) or where the particles went, across the cell's boundary."""
RELATIVE_TOLERANCE = 1e-9
"""How far, relative to the box, a cell's vectors may differ from the restricted form."""


def restricted_cell(box_min, box_max, tilt=0.0) -> np.ndarray:
    """The cell (..., 2, 2) of a box and a tilt: ``a = (l, 0)``, ``b = (tilt, h)``.

    Parameters
    ----------
    box_min, box_max : array_like, (..., 2)
        The box's corners, m (the cell's origin is ``box_min``).
    tilt : array_like, (...)
        The x-offset of the top edge from the bottom edge, m (LAMMPS's ``xy``).

    Returns
    -------
    numpy.ndarray
        (..., 2, 2): rows ``a`` and ``b``, m.
    """
    box_min, box_max = np.asarray(box_min, float), np.asarray(box_max, float)
    size = box_max - box_min
    tilt = np.broadcast_to(np.asarray(tilt, float), size.shape[:-1])
    cell = np.zeros(size.shape[:-1] + (2, 2))
    cell[..., 0, 0] = size[..., 0]
    cell[..., 1, 0] = tilt
    cell[..., 1, 1] = size[..., 1]
    return cell


def cell_area(cell) -> np.ndarray:
    """The cell's area |a x b| (m2), shape (...)."""
    cell = np.asarray(cell, float)
    return np.abs(cell[..., 0, 0] * cell[..., 1, 1] - cell[..., 0, 1] * cell[..., 1, 0])


def fractional(d, cell) -> np.ndarray:
    """The coordinates (s, t) of vectors ``d`` in the cell's basis: ``d = s a + t b``.

    Parameters
    ----------
    d : array_like, (..., 2)
        Vectors, m.
    cell : array_like, (..., 2, 2)
        Lattice vectors (rows a, b), m, broadcast against ``d``'s leading axes.

    Returns
    -------
    numpy.ndarray
        (..., 2), dimensionless.
    """
    d, cell = np.asarray(d, float), np.asarray(cell, float)
    ax, ay, bx, by = cell[..., 0, 0], cell[..., 0, 1], cell[..., 1, 0], cell[..., 1, 1]
    det = ax * by - ay * bx
    s = (d[..., 0] * by - d[..., 1] * bx) / det
    t = (ax * d[..., 1] - ay * d[..., 0]) / det
    return np.stack(np.broadcast_arrays(s, t), axis=-1)


def from_fractional(st, cell) -> np.ndarray:
    """The vectors ``s a + t b`` (..., 2), m, of cell coordinates ``st`` (..., 2)."""
    st, cell = np.asarray(st, float), np.asarray(cell, float)
    x = st[..., 0] * cell[..., 0, 0] + st[..., 1] * cell[..., 1, 0]
    y = st[..., 0] * cell[..., 0, 1] + st[..., 1] * cell[..., 1, 1]
    return np.stack(np.broadcast_arrays(x, y), axis=-1)


def _periodic(periodic) -> np.ndarray:
    periodic = np.asarray(periodic).astype(bool)
    if periodic.shape != (2,):
        raise ValueError(f"periodic: expected one flag per cell vector (a, b), got shape {periodic.shape}")
    return periodic


def image_shift(d, cell, periodic) -> np.ndarray:
    """The whole numbers (m, n) of cells that bring ``d`` nearest the origin: ``d - m a - n b``
    is the minimum image (:func:`minimum_image`); zero along vectors that are not periodic.

    The cell is in the restricted form (``a`` along x). Periodic along ``a`` only, m rounds
    ``d_x / l``; along ``b`` only, n rounds ``d . b / |b|^2`` (both exact for a row of images).
    Periodic along both, n is tried around ``d_y / h`` as far as the first candidate's length
    reaches in y, each with its best m, and the shortest is kept (the first on ties), so that
    a tilted cell of any aspect gets its shortest image.

    Parameters
    ----------
    d : array_like, (..., 2)
        Vectors (e.g. ``x_j - x_i``, or a stored branch minus it), m.
    cell : array_like, (..., 2, 2)
        Lattice vectors in the restricted form a = (l, 0), b = (tilt, h), m.
    periodic : array_like of bool, (2,)
        Whether the sample repeats along a and along b.

    Returns
    -------
    numpy.ndarray
        (..., 2) of int64.
    """
    periodic = _periodic(periodic)
    d, cell = np.asarray(d, float), np.asarray(cell, float)
    ax, bx, by = cell[..., 0, 0], cell[..., 1, 0], cell[..., 1, 1]
    zero = np.zeros(np.broadcast_shapes(d.shape[:-1], cell.shape[:-2]))
    if not periodic[1]:
        m = np.rint(d[..., 0] / ax) if periodic[0] else zero
        return np.stack([m + zero, zero], axis=-1).astype(np.int64)
    if not periodic[0]:
        n = np.rint((d[..., 0] * bx + d[..., 1] * by) / (bx * bx + by * by))
        return np.stack([zero, n + zero], axis=-1).astype(np.int64)

    def best_m(n):
        x = d[..., 0] - n * bx
        m = np.rint(x / ax)
        x = x - m * ax
        y = d[..., 1] - n * by
        return m, x * x + y * y

    n0 = np.rint(d[..., 1] / by) + zero
    m0, length0 = best_m(n0)
    best_m_, best_n, best_length = m0, n0, length0
    reach = int(np.ceil(np.sqrt(length0.max(initial=0.0)) / np.abs(by).min(initial=np.inf))) if length0.size else 0
    for dn in range(-reach, reach + 1):
        if dn == 0:
            continue
        m, length = best_m(n0 + dn)
        shorter = length < best_length
        best_m_ = np.where(shorter, m, best_m_)
        best_n = np.where(shorter, n0 + dn, best_n)
        best_length = np.where(shorter, length, best_length)
    return np.stack([best_m_, best_n], axis=-1).astype(np.int64)


def minimum_image(d, cell, periodic) -> np.ndarray:
    """The shortest of the vectors ``d + m a + n b`` (m, n whole numbers along the periodic
    vectors): the branch vector between two particles of a periodic sample.

    Parameters
    ----------
    d : array_like, (..., 2)
        Vectors, e.g. ``x_j - x_i``, m.
    cell : array_like, (..., 2, 2)
        Lattice vectors, m.
    periodic : array_like of bool, (2,)
        Whether the sample repeats along a and along b.

    Returns
    -------
    numpy.ndarray
        (..., 2), m.

    Examples
    --------
    >>> cell = restricted_cell([0, 0], [1, 1])
    >>> minimum_image([0.9, -0.2], cell, [True, True])
    array([-0.1, -0.2])
    """
    d = np.asarray(d, float)
    return d - from_fractional(image_shift(d, cell, periodic).astype(float), cell)


def wrap(x, origin, cell, periodic) -> np.ndarray:
    """Points ``x`` (..., 2) moved by whole cells into the cell ``origin + s a + t b``,
    0 <= s, t < 1, along its periodic vectors (unchanged along the others), m."""
    periodic = _periodic(periodic)
    x, origin = np.asarray(x, float), np.asarray(origin, float)
    st = fractional(x - origin, cell)
    shift = np.where(periodic, np.floor(st), 0.0)
    return x - from_fractional(shift, cell)


def shear_tilt(cell) -> np.ndarray:
    """The tilt ``b_x`` of each cell (...), m: LAMMPS's ``xy``; ``gamma = tilt / h``."""
    return np.asarray(cell, float)[..., 1, 0]


def unwrap_tilt(tilt, width) -> np.ndarray:
    """A tilt series made continuous where a code flipped the cell (LAMMPS sets ``xy`` back by
    the box's width once it passes half of it: the same lattice, another pair of vectors).

    Parameters
    ----------
    tilt, width : array_like, (T,)
        The tilt and the width ``l`` of the cell at each snapshot, m.

    Returns
    -------
    numpy.ndarray
        (T,): each tilt moved by the whole widths that bring it nearest the previous one.
    """
    tilt, width = np.asarray(tilt, float).copy(), np.broadcast_to(np.asarray(width, float), np.shape(tilt))
    for k in range(1, tilt.size):
        tilt[k] -= width[k] * np.rint((tilt[k] - tilt[k - 1]) / width[k])
    return tilt


def cell_problems(cell, box_min, box_max, periodic) -> list[str]:
    """What is wrong with a file's cell, one line each (empty: nothing).

    Checked: the cell (T, 2, 2) finite, in the restricted form ``a = (l, 0)``, ``b = (tilt, h)``
    with ``l, h`` the box's widths (within :data:`RELATIVE_TOLERANCE` of them), and
    ``periodic`` (2,) flags of 0 or 1 with at least one 1.
    """
    problems = []
    periodic = np.asarray(periodic)
    if periodic.shape != (2,) or not np.isin(periodic, (0, 1)).all():
        problems.append(f"periodic: expected 0 or 1 for each of the cell vectors a, b, got {periodic.tolist()}")
    elif not periodic.any():
        problems.append("periodic: no cell vector is periodic (0, 0); a sample bounded on every side has no cell: "
                        "leave cell and periodic out")
    cell = np.asarray(cell, float)
    size = np.asarray(box_max, float) - np.asarray(box_min, float)
    if not np.isfinite(cell).all():
        problems.append(f"cell: {int((~np.isfinite(cell).all(axis=(-1, -2))).sum())} snapshot(s) with a "
                        "non-finite lattice vector")
        return problems
    scale = np.abs(size).max(axis=-1) * RELATIVE_TOLERANCE
    off = (np.abs(cell[..., 0, 1]) > scale) | (np.abs(cell[..., 0, 0] - size[..., 0]) > scale) | (
        np.abs(cell[..., 1, 1] - size[..., 1]) > scale)
    if off.any():
        k = int(np.flatnonzero(off)[0])
        problems.append(f"cell: {int(off.sum())} snapshot(s) whose vectors are not a = (l, 0), b = (tilt, h) with "
                        f"l, h the box's width and height (first: snapshot {k}, a = {cell[k, 0].tolist()}, "
                        f"b = {cell[k, 1].tolist()}, box {size[k].tolist()})")
    return problems


BRANCH_TOLERANCE = 1e-6
"""How far, relative to r_i + r_j, a stored particle pair's branch may be from the minimum
image of its centres (rounding: a reader computes it from the centres)."""
REACH_TOLERANCE = 0.5
"""How much longer than the particles allow a branch may be, in units of the smaller radius:
a code that finds its contacts before it moves the bodies writes, at the end of a step,
pairs slightly farther apart than their radii (the same allowance as the readers' own check,
:func:`grainview.formats.checks.check_contacts`); a branch across the cell is longer by far."""


def branch_problems(position, i, j, branch, count, cell, radius, periodic, gap=None) -> np.ndarray:
    """Per snapshot, the particle pairs whose branch is not the minimum image of their centres,
    and those whose branch is longer than the particles allow.

    A contact's branch in a periodic cell is ``x_j - x_i`` brought to its nearest image
    (:func:`minimum_image`); its length is at most ``r_i + r_j`` (circumscribed radii) plus the
    pair's gap where it is positive (a near contact): the first within :data:`BRANCH_TOLERANCE`
    of ``r_i + r_j``, the second within :data:`REACH_TOLERANCE` of the smaller radius. A branch of the size of the box is the mark of a reader or writer that did
    not take the minimum image.

    Parameters
    ----------
    position : array_like, (T, N, 2)
        Centres, m.
    i, j : array_like of int, (T, C)
        Bodies of the contact slots (walls: ``j >= N``, not checked).
    branch : array_like, (T, C, 2)
        Stored branches, m.
    count : array_like of int, (T,)
        Occupied slots.
    cell : array_like, (T, 2, 2)
        Lattice vectors, m.
    radius : array_like, (N,)
        Circumscribed radii, m.
    periodic : array_like of bool, (2,)
        The periodic cell vectors.
    gap : array_like, (T, C), optional
        Gaps, m.

    Returns
    -------
    numpy.ndarray
        (T, 2) of int64: per snapshot, the pairs whose branch is not the minimum image, and
        those whose branch is too long.
    """
    position, branch = np.asarray(position, float), np.asarray(branch, float)
    i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
    n = position.shape[1]
    slot = np.arange(i.shape[1])
    pair = (slot < np.asarray(count)[:, None]) & (i >= 0) & (j >= 0) & (j < n) & (i < n)
    ii, jj = np.where(pair, i, 0), np.where(pair, j, 0)
    xi = np.take_along_axis(position, ii[..., None], axis=1)
    xj = np.take_along_axis(position, jj[..., None], axis=1)
    image = minimum_image(xj - xi, np.asarray(cell, float)[:, None], periodic)
    r_i, r_j = np.asarray(radius, float)[ii], np.asarray(radius, float)[jj]
    reach = r_i + r_j
    tolerance = BRANCH_TOLERANCE * reach
    dx, dy = branch[..., 0] - image[..., 0], branch[..., 1] - image[..., 1]
    miss = np.sqrt(dx * dx + dy * dy) > tolerance
    allowed = reach + (0.0 if gap is None else np.maximum(np.nan_to_num(np.asarray(gap, float)), 0.0))
    long = np.sqrt(branch[..., 0] * branch[..., 0] + branch[..., 1] * branch[..., 1]) > (
        allowed + REACH_TOLERANCE * np.minimum(r_i, r_j))
    return np.stack([(pair & miss).sum(axis=1), (pair & long).sum(axis=1)], axis=-1).astype(np.int64)
