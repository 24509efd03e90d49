"""Coarse-grained continuum fields of a packing on a grid (Goldhirsch, Granular Matter 12, 239
(2010); Weinhart, Thornton, Luding & Bokhove, Granular Matter 14, 289 (2012)).

Each particle i (mass m_i, area A_i, centre r_i, velocity v_i) is spread over the plane with a
kernel phi (m^-2, integral 1; :mod:`grainview.analysis._kernels.coarse_graining`), each contact c along
its branch vector l^c from the centre of i, with the kernel integrated along it,
psi_c(r) = int_0^1 phi(r - r_i - u l^c) du. With t the slab thickness (m):

    density           rho(r)      = (1/t) sum_i m_i phi(r - r_i)                     kg m-3
    solid fraction    nu(r)       = sum_i A_i phi(r - r_i)                           1
    momentum          j(r)        = (1/t) sum_i m_i v_i phi(r - r_i)                 kg m-2 s-1
    velocity          V(r)        = j / rho                                          m s-1
    kinetic stress    sigma^k(r)  = (1/t) sum_i m_i v'_i (x) v'_i phi(r - r_i)       Pa
                                  = (1/t) sum_i m_i v_i (x) v_i phi - rho V (x) V,  v'_i = v_i - V(r)
    contact stress    sigma^c(r)  = (1/t) sum_c f^c (x) l^c psi_c(r)                 Pa
    fabric            F(r)        = sum_c n^c (x) n^c psi_c(r) / sum_c psi_c(r)      1

with f = f_n n + f_t t the force of i on j and l from i to j (from the particle's centre to the
contact point for a wall contact), so that both stresses are positive in compression
(docs/conventions.md §0-1; the references count tension positive). Because each kernel
integrates to 1 over the plane, int rho dA t = sum_i m_i, int nu dA = sum_i A_i and
int sigma^c dA = (1/t) sum_c f (x) l: over a sample of area A, (1/A) int sigma^c dA is the
Love-Weber stress (1/V) sum_c f (x) l of :func:`grainview.analysis.arrays.stress.stress_tensor`, V = A t.
F has trace 1 and is the fabric tensor of :func:`grainview.analysis.arrays.fabric.fabric_tensor` where
the kernel is wider than the sample.
"""

from __future__ import annotations

import numpy as np

from .._kernels.coarse_graining import spread_points, spread_segments
from .._kernels.records import Grid, Points, Segments
from ...contract.cell import fractional, from_fractional, wrap
from ...contract.errors import ParameterError
from .signature import CONTACT, CONTACT_XY, PARTICLE, SCALAR, TENSOR, core_dims
from .vectors import force_vectors

GRID = ("y", "x")
"""Dimension names of a field on the grid: rows along y, columns along x."""
PARTICLE_XY = ("particle", "xy")

__all__ = ["GRID", "CELL", "kernel_radius", "grid_nodes", "check_grid", "image_offsets", "coarse_grained_fields"]


def kernel_radius(width: float, cutoff: float) -> float:
    """The radius c = cutoff w beyond which the kernel is zero, m."""
    return float(width) * float(cutoff)


def grid_nodes(lower: float, upper: float, spacing: float) -> np.ndarray:
    """Cell centres lower + (k + 1/2) spacing, k = 0 .. n-1, of the n = ceil((upper - lower)/spacing)
    cells of side ``spacing`` (m) that cover [lower, upper] (m)."""
    n = max(1, int(np.ceil((upper - lower) / spacing - 1e-9)))
    return lower + (np.arange(n) + 0.5) * spacing


def check_grid(values, name: str) -> np.ndarray:
    """``values`` as a 1-D float array of finite, strictly increasing coordinates (m), or one clear
    :class:`~grainview.contract.errors.ParameterError` naming ``name``."""
    try:
        out = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a 1-D sequence of coordinates in m") from None
    if out.ndim != 1 or out.size == 0:
        raise ParameterError(f"{name}: expected a non-empty 1-D sequence of coordinates in m, got shape {out.shape}")
    if not np.all(np.isfinite(out)) or np.any(np.diff(out) <= 0):
        raise ParameterError(f"{name}: expected finite, strictly increasing coordinates in m")
    return np.ascontiguousarray(out)


def _rows(a, lead, tail=()):
    """``a`` broadcast to ``lead + tail`` and flattened to (B,) + tail, contiguous float64."""
    a = np.broadcast_to(np.asarray(a, dtype=float), lead + tail)
    return np.ascontiguousarray(a.reshape((-1,) + tail))


CELL = ("cell_vector", "xy")
"""Core dimensions of a periodic cell's lattice vectors (rows a, b)."""
XY = ("xy",)


def image_offsets(cell, origin, periodic, x, y, reach):
    """The whole-cell shifts (m, n) whose images of the cell can reach the grid: every
    ``m a + n b`` such that a source wrapped into the cell ``origin + s a + t b`` (0 <= s, t < 1)
    and moved by it comes within ``reach`` of the grid's bounding box, for every snapshot.

    Parameters
    ----------
    cell : numpy.ndarray, (B, 2, 2)
        Lattice vectors, m, in the restricted form a = (l, 0), b = (tilt, h).
    origin : numpy.ndarray, (B, 2)
        The cell's origin (``box_min``), m.
    periodic : array_like of bool, (2,)
        Along which vectors the sample repeats (0: only shift 0 along it).
    x, y : numpy.ndarray
        The grid's coordinates, m.
    reach : float
        How far a source reaches (the kernel's radius plus the longest segment), m.

    Returns
    -------
    numpy.ndarray of int64, (K, 2)
        The shifts (m, n), (0, 0) among them.
    """
    periodic = np.asarray(periodic, bool)
    l, tilt, h = cell[:, 0, 0], cell[:, 1, 0], cell[:, 1, 1]
    ox, oy = origin[:, 0], origin[:, 1]
    if periodic[1]:
        n_lo = int(np.ceil(((y[0] - reach - oy - h) / h).min() - 1e-9))
        n_hi = int(np.floor(((y[-1] + reach - oy) / h).max() + 1e-9))
    else:
        n_lo = n_hi = 0
    shifts = []
    for n in range(n_lo, n_hi + 1):
        if periodic[0]:
            # the wrapped sources lie within x in [ox + min(0, tilt), ox + l + max(0, tilt)]; moved by n b
            left = ox + np.minimum(0.0, tilt) + n * tilt
            right = ox + l + np.maximum(0.0, tilt) + n * tilt
            m_lo = int(np.ceil(((x[0] - reach - right) / l).min() - 1e-9))
            m_hi = int(np.floor(((x[-1] + reach - left) / l).max() + 1e-9))
        else:
            m_lo = m_hi = 0
        shifts.extend((m, n) for m in range(m_lo, m_hi + 1))
    return np.array(shifts, dtype=np.int64).reshape(-1, 2)


def _reaching(lo, hi, alive, offsets, x, y, reach):
    """The images that reach the grid: for each row, which source and which of ``offsets`` each
    drawn copy is, padded to the longest row.

    Parameters
    ----------
    lo, hi : numpy.ndarray, (B, N, 2)
        Each source's lower and upper corner (a point: its centre twice), m.
    alive : numpy.ndarray of bool, (B, N)
        The sources spread.
    offsets : numpy.ndarray, (B, K, 2)
        The shifts m a + n b of the images, m.
    x, y : numpy.ndarray
        The grid's coordinates, m.
    reach : float
        The kernel's radius, m.

    Returns
    -------
    source, image : numpy.ndarray of int64, (B, M)
        The source and the offset of each copy (0 in the padding).
    valid : numpy.ndarray of bool, (B, M)
        The copies (False: padding).
    """
    grid_lo = np.array([x[0], y[0]]) - reach
    grid_hi = np.array([x[-1], y[-1]]) + reach
    near = alive[:, None, :] & np.all((hi[:, None] + offsets[:, :, None] >= grid_lo)
                                      & (lo[:, None] + offsets[:, :, None] <= grid_hi), axis=-1)  # (B, K, N)
    n_rows, n_sources = alive.shape
    flat = near.reshape(n_rows, -1)
    counts = flat.sum(axis=1)
    width = max(int(counts.max(initial=0)), 1)
    rows, which = np.nonzero(flat)  # by row, then image after image
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    rank = np.arange(rows.size) - first[rows]
    source = np.zeros((n_rows, width), np.int64)
    image = np.zeros((n_rows, width), np.int64)
    valid = np.zeros((n_rows, width), bool)
    source[rows, rank], image[rows, rank], valid[rows, rank] = which % n_sources, which // n_sources, True
    return source, image, valid


def _gather(values, index):
    """``values`` (B, N, ...) at ``index`` (B, M) along axis 1: (B, M, ...)."""
    index = index.reshape(index.shape + (1,) * (values.ndim - 2))
    return np.take_along_axis(values, index, axis=1)


@core_dims(PARTICLE_XY, PARTICLE_XY, PARTICLE, PARTICLE, CONTACT, CONTACT, CONTACT, CONTACT_XY, CONTACT_XY,
           CONTACT, CONTACT, SCALAR,
           out=(GRID, GRID, GRID + ("xy",), GRID + ("xy",), GRID + TENSOR, GRID + TENSOR, GRID + TENSOR))
def coarse_grained_fields(position, velocity, mass, area, i, fn, ft, normal, branch, stress_mask, fabric_mask,
                          thickness, cell=None, cell_rate=None, origin=None, *, x, y, width, cutoff=3.0,
                          periodic=None):
    """Density, solid fraction, momentum, velocity, kinetic and contact stress and fabric on the
    grid (x, y) (the module's formulas), for every snapshot of the leading axes.

    Parameters
    ----------
    position, velocity : array_like, (..., P, 2)
        Particle centres (m) and velocities (m s-1).
    mass, area : array_like, (..., P)
        Particle masses (kg, for a slab of thickness t) and areas (m2).
    i : array_like of int, (..., C)
        Particle of each contact (the start of its branch vector).
    fn, ft : array_like, (..., C)
        Normal and tangential force of i on j, N.
    normal, branch : array_like, (..., C, 2)
        Unit normal from i to j and branch vector (m).
    stress_mask, fabric_mask : array_like of bool, (..., C)
        The contacts summed in the contact stress, and in the fabric.
    thickness : float or array_like, (...)
        Slab thickness t, m.
    x, y : array_like, (nx,), (ny,)
        Grid coordinates, m, strictly increasing.
    width : float
        Standard deviation w of the Gaussian kernel, m.
    cutoff : float, default 3
        The kernel is cut at radius ``cutoff * width`` and renormalised to integral 1.
    cell, cell_rate : array_like, (..., 2, 2), optional
        A periodic cell's lattice vectors (rows a, b; m) and their rates of change (m s-1),
        with ``origin`` (..., 2) (m) and ``periodic`` (2,): the sample repeats along the
        vectors flagged in ``periodic``, and every particle and every contact's segment is
        spread with all its images ``+ m a + n b`` that reach the grid (:func:`image_offsets`),
        so that the fields are those of the infinite periodic packing: periodic over the plane,
        a particle near one edge of the cell counted near the opposite one, a contact across
        the boundary spread along its minimum-image branch on both sides. An image's velocity
        is ``v + m da/dt + n db/dt`` (Lees–Edwards: the images above a cell sheared at the
        rate d tilt/dt move that much faster). Without ``cell`` the sample is bounded.

    Returns
    -------
    tuple of numpy.ndarray
        ``density`` (..., ny, nx) kg m-3, ``solid_fraction`` (..., ny, nx), ``momentum``
        (..., ny, nx, 2) kg m-2 s-1, ``velocity`` (..., ny, nx, 2) m s-1 (NaN where rho = 0),
        ``kinetic_stress``, ``contact_stress`` (..., ny, nx, 2, 2) Pa and ``fabric``
        (..., ny, nx, 2, 2) (NaN where no contact of ``fabric_mask`` reaches).
    """
    x = check_grid(x, "x")
    y = check_grid(y, "y")
    if not (np.isfinite(width) and width > 0):
        raise ParameterError(f"width={width!r}: expected a kernel width > 0 in m")
    if not (np.isfinite(cutoff) and cutoff > 0):
        raise ParameterError(f"cutoff={cutoff!r}: expected a cutoff > 0 (in kernel widths)")
    radius = kernel_radius(width, cutoff)
    position = np.asarray(position, dtype=float)
    lead_p = position.shape[:-2]
    normal = np.asarray(normal, dtype=float)
    lead = np.broadcast_shapes(lead_p, normal.shape[:-2], np.shape(mass)[:-1], np.shape(thickness))
    n_p, n_c = position.shape[-2], normal.shape[-2]
    pos = _rows(position, lead, (n_p, 2))
    vel = _rows(velocity, lead, (n_p, 2))
    m = _rows(mass, lead, (n_p,))
    a = _rows(area, lead, (n_p,))
    t = _rows(thickness, lead)
    b = pos.shape[0]

    # particles: m, A, m v, m v (x) v (xx, xy, yy)
    moving = np.isfinite(vel).all(-1)
    v = np.where(moving[..., None], vel, 0.0)
    weights = np.stack([m, a, m * v[..., 0], m * v[..., 1], m * v[..., 0] ** 2, m * v[..., 0] * v[..., 1],
                        m * v[..., 1] ** 2], axis=-1)
    active = np.isfinite(pos).all(-1) & np.isfinite(m) & np.isfinite(a)
    points = np.zeros((b, y.size, x.size, weights.shape[-1]))
    grid = Grid(x, y, float(width), radius)
    if cell is not None:
        cells_ = _rows(cell, lead, (2, 2))
        rates = _rows(0.0 if cell_rate is None else cell_rate, lead, (2, 2))
        start_of = _rows(origin, lead, (2,))
        periodic = np.asarray(periodic, bool)
        seg = np.abs(_rows(branch, lead, (n_c, 2)))
        longest = float(np.nanmax(seg, initial=0.0)) if seg.size else 0.0
        shifts = image_offsets(cells_, start_of, periodic, x, y, radius + longest).astype(float)
        offsets = shifts[None, :, 0:1] * cells_[:, None, 0] + shifts[None, :, 1:2] * cells_[:, None, 1]  # (B, K, 2)
        kicks = shifts[None, :, 0:1] * rates[:, None, 0] + shifts[None, :, 1:2] * rates[:, None, 1]
        home = np.where(np.isfinite(pos), wrap(np.nan_to_num(pos), start_of[:, None], cells_[:, None], periodic), pos)
        into = home - pos  # what wrapping moved each centre by (whole cells)
        fraction = fractional(into, cells_[:, None])
        into_rate = from_fractional(np.rint(fraction), rates[:, None])  # the velocity that move adds
        v_home = v + np.where(moving[..., None], into_rate, 0.0)
        source, image, alive = _reaching(np.nan_to_num(home), np.nan_to_num(home), active, offsets, x, y, radius)
        centres = _gather(home, source) + _gather(offsets, image)
        speeds = np.where(_gather(moving, source)[..., None], _gather(v_home, source) + _gather(kicks, image), 0.0)
        masses, areas = _gather(m, source), _gather(a, source)
        weights = np.stack([masses, areas, masses * speeds[..., 0], masses * speeds[..., 1],
                            masses * speeds[..., 0] ** 2, masses * speeds[..., 0] * speeds[..., 1],
                            masses * speeds[..., 1] ** 2], axis=-1)
        spread_points(Points(np.ascontiguousarray(centres[..., 0]), np.ascontiguousarray(centres[..., 1]), alive,
                             np.ascontiguousarray(np.where(alive[..., None], weights, 0.0))), grid, points)
    else:
        spread_points(Points(np.ascontiguousarray(pos[..., 0]), np.ascontiguousarray(pos[..., 1]), active,
                             np.ascontiguousarray(np.where(active[..., None], weights, 0.0))), grid, points)

    # contacts: f (x) l (xx, xy, yx, yy) where stressed, n (x) n (xx, xy, yy) and 1 where in the fabric
    stress_mask = np.broadcast_to(np.asarray(stress_mask, bool), lead + (n_c,)).reshape(b, n_c)
    fabric_mask = np.broadcast_to(np.asarray(fabric_mask, bool), lead + (n_c,)).reshape(b, n_c)
    nrm = _rows(normal, lead, (n_c, 2))
    arm = _rows(branch, lead, (n_c, 2))
    force = force_vectors(_rows(fn, lead, (n_c,)), _rows(ft, lead, (n_c,)), nrm)
    idx = np.broadcast_to(np.asarray(i), lead + (n_c,)).reshape(b, n_c)
    used = stress_mask | fabric_mask
    if np.any(used & ((idx < 0) | (idx >= n_p))):
        raise ParameterError(f"a selected contact names a particle outside 0..{n_p - 1} (column i)")
    start = np.take_along_axis(pos, np.clip(idx, 0, n_p - 1)[..., None], axis=1)
    stressed = stress_mask & np.isfinite(force).all(-1) & np.isfinite(arm).all(-1)
    counted = fabric_mask & np.isfinite(nrm).all(-1) & np.isfinite(arm).all(-1)
    active = (stressed | counted) & np.isfinite(start).all(-1)
    fl = np.where(stressed[..., None], np.stack([force[..., 0] * arm[..., 0], force[..., 0] * arm[..., 1],
                                                 force[..., 1] * arm[..., 0], force[..., 1] * arm[..., 1]], -1), 0.0)
    nn = np.where(counted[..., None], np.stack([nrm[..., 0] ** 2, nrm[..., 0] * nrm[..., 1], nrm[..., 1] ** 2,
                                                np.ones_like(nrm[..., 0])], -1), 0.0)
    weights = np.where(active[..., None], np.concatenate([fl, nn], axis=-1), 0.0)
    segments = np.zeros((b, y.size, x.size, weights.shape[-1]))
    if cell is not None:
        start = np.where(active[..., None], start, 0.0)
        home = wrap(start, start_of[:, None], cells_[:, None], periodic)
        arm = np.where(active[..., None], arm, 0.0)
        source, image, used_images = _reaching(np.minimum(home, home + arm), np.maximum(home, home + arm), active,
                                               offsets, x, y, radius)
        starts = _gather(home, source) + _gather(offsets, image)
        arms = _gather(arm, source)
        weight_images = np.where(used_images[..., None], _gather(weights, source), 0.0)
        spread_segments(Segments(np.ascontiguousarray(starts[..., 0]), np.ascontiguousarray(starts[..., 1]),
                                 np.ascontiguousarray(arms[..., 0]), np.ascontiguousarray(arms[..., 1]),
                                 used_images, np.ascontiguousarray(weight_images)), grid, segments)
    else:
        spread_segments(Segments(np.ascontiguousarray(np.where(active, start[..., 0], 0.0)),
                                 np.ascontiguousarray(np.where(active, start[..., 1], 0.0)),
                                 np.ascontiguousarray(np.where(active, arm[..., 0], 0.0)),
                                 np.ascontiguousarray(np.where(active, arm[..., 1], 0.0)),
                                 active, np.ascontiguousarray(weights)), grid, segments)

    per_t = (1.0 / t)[:, None, None, None]
    points_t = points * per_t  # per unit volume
    density = points_t[..., 0]
    solid_fraction = points[..., 1]
    momentum = points_t[..., 2:4]
    with np.errstate(invalid="ignore", divide="ignore"):
        velocity_field = np.where(density[..., None] > 0, momentum / density[..., None], np.nan)
        vv = np.where(density[..., None, None] > 0, momentum[..., :, None] * velocity_field[..., None, :], 0.0)
        mvv = np.stack([points_t[..., 4], points_t[..., 5], points_t[..., 5], points_t[..., 6]], -1)
        kinetic = mvv.reshape(mvv.shape[:-1] + (2, 2)) - vv
        contact = (segments[..., 0:4] * per_t).reshape(segments.shape[:-1] + (2, 2))
        count = segments[..., 7]
        fabric = np.stack([segments[..., 4], segments[..., 5], segments[..., 5], segments[..., 6]], -1)
        fabric = np.where(count[..., None] > 0, fabric / count[..., None], np.nan).reshape(count.shape + (2, 2))
    grid = (y.size, x.size)
    return (density.reshape(lead + grid), solid_fraction.reshape(lead + grid),
            momentum.reshape(lead + grid + (2,)), velocity_field.reshape(lead + grid + (2,)),
            kinetic.reshape(lead + grid + (2, 2)), contact.reshape(lead + grid + (2, 2)),
            fabric.reshape(lead + grid + (2, 2)))
