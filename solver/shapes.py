"""Shapes of the bodies: disks and regular polygons, their area, mass, inertia and vertices.

A body is described by its centre ``pos`` (m), its rotation ``angle`` (rad), its circumscribed
radius ``radius`` R (m; the disk radius for a disk) and its number of vertices ``nvert``
(0 = disk, n >= 3 = regular n-gon). Vertex k of a polygon sits at

    x_k = pos + R (cos(angle + 2 pi k / n), sin(angle + 2 pi k / n)),   k = 0 .. n-1,

so the vertices run counter-clockwise, and edge k (from vertex k to vertex k+1) has the
outward unit normal of angle ``angle + pi (2k + 1) / n`` at the distance r = R cos(pi/n)
(the inradius) from the centre. These are the shapes of the data contract
(``grainview.schema``: ``radius`` is the circumscribed radius, ``n_vertices`` 0 for disks).

Formulas (regular n-gon of circumscribed radius R, split into n triangles centre-edge with
apex angle alpha = 2 pi / n):

* area      A = (n/2) R^2 sin(2 pi / n)                         (disk: pi R^2)
* inertia   I/m = R^2 (2 + cos(2 pi / n)) / 6 = R^2 (1 + 2 cos^2(pi/n)) / 6
            about the centroid (disk: R^2 / 2). Each triangle O-a-b of the fan has the polar
            moment (A_t/6)(|a|^2 + |b|^2 + a.b) about its apex O.
* mass      m = rho A t for a slab of thickness t (m) and density rho (kg m-3); I = m (I/m).
"""

from __future__ import annotations

import numpy as np

from grainview.errors import ParameterError
from grainview.schema import particle_area, polygon_vertices

__all__ = ["polygon_area", "polygon_inertia_per_mass", "mass_and_inertia", "vertices", "inradius",
           "check_shapes"]


def check_shapes(radius, nvert):
    """Validate and convert ``radius`` (float64, > 0, finite) and ``nvert`` (int32, 0 or >= 3).

    Returns the two arrays broadcast to a common 1-D shape. Raises
    :class:`grainview.errors.ParameterError` naming the offending parameter.
    """
    radius = np.atleast_1d(np.asarray(radius, dtype=np.float64))
    nvert_in = np.atleast_1d(np.asarray(nvert))
    if nvert_in.dtype.kind not in "iu":
        if nvert_in.dtype.kind == "f" and np.all(nvert_in == np.round(nvert_in)):
            pass
        else:
            raise ParameterError(f"nvert must hold integers (0 = disk, >= 3 = polygon), got dtype {nvert_in.dtype}")
    nvert_arr = nvert_in.astype(np.int32)
    try:
        radius, nvert_arr = np.broadcast_arrays(radius, nvert_arr)
    except ValueError as exc:
        raise ParameterError(f"radius (shape {radius.shape}) and nvert (shape {nvert_arr.shape}) "
                             "must have the same length") from exc
    if radius.ndim != 1:
        raise ParameterError(f"radius must be a 1-D array of circumscribed radii in m, got shape {radius.shape}")
    if not np.all(np.isfinite(radius)) or np.any(radius <= 0):
        raise ParameterError("radius must hold finite circumscribed radii > 0 (m)")
    if np.any((nvert_arr != 0) & (nvert_arr < 3)):
        raise ParameterError("nvert must be 0 (disk) or >= 3 (regular polygon)")
    return np.ascontiguousarray(radius), np.ascontiguousarray(nvert_arr)


def polygon_area(radius, nvert):
    """Area (m2) of each body: (n/2) R^2 sin(2 pi/n) for a regular n-gon of circumscribed
    radius R, pi R^2 for a disk (n = 0). Same definition as ``grainview.schema.particle_area``
    (the contract's shape definition), which it calls."""
    radius, nvert = check_shapes(radius, nvert)
    return particle_area(radius, nvert)


def polygon_inertia_per_mass(radius, nvert):
    """Moment of inertia per unit mass I/m (m2) about the centroid: R^2 (2 + cos(2 pi/n))/6
    for a regular n-gon of circumscribed radius R, R^2/2 for a disk (n = 0)."""
    radius, nvert = check_shapes(radius, nvert)
    safe_n = np.where(nvert >= 3, nvert, 3).astype(np.float64)
    polygon = radius**2 * (2.0 + np.cos(2.0 * np.pi / safe_n)) / 6.0
    return np.where(nvert >= 3, polygon, 0.5 * radius**2)


def mass_and_inertia(radius, nvert, density, thickness=1.0):
    """Mass (kg) and moment of inertia about the centroid (kg m2) of each body.

    m = density * area * thickness (a slab of the given thickness, m; density in kg m-3),
    I = m * (I/m) with I/m from :func:`polygon_inertia_per_mass`. Vectorised over bodies;
    ``density`` may be a scalar or one value per body.
    """
    radius, nvert = check_shapes(radius, nvert)
    density = np.asarray(density, dtype=np.float64)
    if not np.all(np.isfinite(density)) or np.any(density <= 0):
        raise ParameterError("density must be finite and > 0 (kg m-3)")
    if not np.isfinite(thickness) or thickness <= 0:
        raise ParameterError(f"thickness={thickness!r}: expected a finite slab thickness > 0 (m)")
    mass = np.broadcast_to(density, radius.shape) * particle_area(radius, nvert) * float(thickness)
    inertia = mass * polygon_inertia_per_mass(radius, nvert)
    return np.ascontiguousarray(mass, dtype=np.float64), np.ascontiguousarray(inertia, dtype=np.float64)


def inradius(radius, nvert):
    """Radius of the inscribed circle (m): R cos(pi/n) for a regular n-gon, R for a disk.
    It is the distance from the centre to every edge of the polygon."""
    radius, nvert = check_shapes(radius, nvert)
    safe_n = np.where(nvert >= 3, nvert, 3).astype(np.float64)
    return np.where(nvert >= 3, radius * np.cos(np.pi / safe_n), radius)


def vertices(pos, angle, radius, nvert):
    """Vertices (N, maxn, 2) in m of every body, counter-clockwise, vertex k at
    pos + R (cos(angle + 2 pi k/n), sin(angle + 2 pi k/n)); rows beyond a body's own n (and
    all rows of disks) are NaN. ``maxn`` is the largest ``nvert`` (0 if all are disks).
    For plotting and tests; kernels compute vertices on the fly."""
    radius, nvert = check_shapes(radius, nvert)
    pos = np.asarray(pos, dtype=np.float64).reshape(-1, 2)
    angle = np.broadcast_to(np.asarray(angle, dtype=np.float64), radius.shape)
    if pos.shape[0] != radius.shape[0]:
        raise ParameterError(f"pos must have shape (N, 2) with N = {radius.shape[0]}, got {pos.shape}")
    maxn = int(nvert.max()) if nvert.size else 0
    out = np.full((radius.shape[0], maxn, 2), np.nan)
    for n in np.unique(nvert[nvert >= 3]):
        sel = nvert == n
        out[sel, :n] = polygon_vertices(pos[sel], radius[sel], angle[sel], int(n))
    return out
