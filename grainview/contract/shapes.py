"""The shape of a particle: a disk, or a convex polygon given by its vertices in its own frame.

This module is the one place where a shape's geometry is defined; the solver's shape table,
the analyses, the maps and the exports read it. The contract (docs/schema.md, "Shapes") stores:

* ``radius`` (particle): the circumscribed radius R, m — a disk's radius, a polygon's
  largest distance from its centroid to a vertex;
* ``n_vertices`` (particle): 0 for a disk, n >= 3 for a polygon;
* ``vertices`` (particle, vertex, xy), optional: a polygon's n vertices in its own frame, m —
  centroid at the origin, counter-clockwise, convex; NaN beyond the particle's ``n_vertices``
  and for disks. A file without it holds regular polygons only (every file written before it
  existed): vertex k of a regular n-gon lies at R (cos 2 pi k/n, sin 2 pi k/n)
  (:func:`regular_vertices`).

A particle at ``position`` p and ``angle`` theta has its vertex k at p + Rot(theta) v_k, with
Rot(theta) the counter-clockwise rotation (:func:`world_vertices`): ``angle`` is the rotation
of the particle from its own frame.

Formulas for a polygon of vertices v_0 .. v_{n-1} (counter-clockwise, v_n = v_0), with
c_k = v_k x v_{k+1} = x_k y_{k+1} - x_{k+1} y_k:

* area       A = (1/2) sum_k c_k                                  (disk: pi R^2)
* centroid   g = (1 / 6A) sum_k c_k (v_k + v_{k+1})
* inertia    I/m = (1 / 12 A) sum_k c_k (|v_k|^2 + v_k . v_{k+1} + |v_{k+1}|^2) about the
  origin (disk: R^2 / 2), the fan of triangles origin-v_k-v_{k+1}
* inradius   the smallest distance from the centroid to an edge line (disk: R)

Needs numpy only.
"""

from __future__ import annotations

import numpy as np

CENTROID_TOLERANCE = 1e-9
"""Largest accepted |centroid| of a polygon's vertices, relative to its circumscribed radius."""
RADIUS_TOLERANCE = 1e-9
"""Largest accepted relative difference between ``radius`` and a polygon's farthest vertex."""
REGULAR_TOLERANCE = 1e-6
"""Largest spread, relative to the circumscribed radius, of a polygon's vertex distances from
its centroid and of its edge lengths for it to count as regular (:func:`regular_polygons`)."""


def vertex_phases(n_vertices: int) -> np.ndarray:
    """(n,) polar angles (rad) of the vertices of a regular n-gon in its own frame: 2 pi k/n,
    k = 0 .. n-1, so that vertex 0 lies at the particle's ``angle`` and the vertices run
    counter-clockwise."""
    return 2.0 * np.pi * np.arange(n_vertices) / n_vertices


def regular_vertices(radius: float, n_vertices: int) -> np.ndarray:
    """(n, 2) vertices in m of a regular n-gon of circumscribed radius R in its own frame:
    v_k = R (cos 2 pi k/n, sin 2 pi k/n)."""
    phase = vertex_phases(int(n_vertices))
    return float(radius) * np.stack([np.cos(phase), np.sin(phase)], -1)


def body_vertices(radius, n_vertices, vertices=None) -> np.ndarray:
    """(P, V, 2) every particle's vertices in its own frame, m; V the largest vertex count
    (0 when every particle is a disk), rows beyond a particle's count NaN.

    Parameters
    ----------
    radius : array_like, (P,)
        Circumscribed radii, m.
    n_vertices : array_like of int, (P,)
        0 for a disk, n >= 3 for a polygon.
    vertices : array_like, (P, V', 2), optional
        The file's ``vertices``; absent, the polygons are the regular ones
        (:func:`regular_vertices`), as in files written before ``vertices`` existed.
    """
    radius = np.asarray(radius, dtype=float).reshape(-1)
    n = np.asarray(n_vertices).astype(np.int64).reshape(-1)
    width = int(n.max()) if n.size else 0
    if vertices is not None:
        vertices = np.asarray(vertices, dtype=float)
        out = np.full((n.size, width, 2), np.nan)
        out[:, :min(width, vertices.shape[1])] = vertices[:, :width]
        out[np.arange(width)[None, :] >= n[:, None]] = np.nan
        return out
    out = np.full((n.size, width, 2), np.nan)
    for count in np.unique(n[n >= 3]):
        rows = n == count
        phase = vertex_phases(int(count))
        out[rows, :count, 0] = radius[rows, None] * np.cos(phase)
        out[rows, :count, 1] = radius[rows, None] * np.sin(phase)
    return out


def world_vertices(position, angle, vertices) -> np.ndarray:
    """(..., P, V, 2) vertices in m of particles at ``position`` (..., P, 2) m turned by
    ``angle`` (..., P) rad: p + Rot(angle) v_k for the own-frame ``vertices`` (P, V, 2) of
    :func:`body_vertices` (NaN rows stay NaN)."""
    position = np.asarray(position, dtype=float)
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    x, y = vertices[..., 0], vertices[..., 1]
    return position[..., None, :] + np.stack([c * x - s * y, s * x + c * y], -1)


def _shifted(vertices):
    """The polygons' vertices v_k and v_{k+1} (cyclically within each particle's own count),
    zero in the rows after each count, and which rows are vertices: for (P, V, 2) vertices
    with NaN rows after each count."""
    v = np.asarray(vertices, dtype=float)
    count = np.sum(np.all(np.isfinite(v), axis=-1), axis=-1)
    k = np.arange(v.shape[-2])
    following = np.where(k[None, :] + 1 < count[:, None], k[None, :] + 1, 0)
    nxt = np.take_along_axis(v, following[..., None], axis=-2)
    own = k[None, :] < count[:, None]
    return np.where(own[..., None], np.nan_to_num(v), 0.0), np.where(own[..., None], np.nan_to_num(nxt), 0.0), own


def polygon_properties(vertices) -> dict:
    """Area (m2), centroid (m), I/m about the origin (m2), farthest vertex (m) and inradius
    (m) of (P, V, 2) polygons (NaN rows after each one's count; module docstring's formulas).
    Rows with fewer than three vertices give zeros: callers pass polygons only."""
    v, nxt, own = _shifted(vertices)
    cross = v[..., 0] * nxt[..., 1] - v[..., 1] * nxt[..., 0]
    area = 0.5 * cross.sum(-1)
    safe = np.where(area != 0, area, 1.0)
    centroid = (cross[..., None] * (v + nxt)).sum(-2) / (6.0 * safe[..., None])
    polar = (cross * ((v ** 2).sum(-1) + (v * nxt).sum(-1) + (nxt ** 2).sum(-1))).sum(-1) / 12.0
    edge = nxt - v
    length = np.hypot(edge[..., 0], edge[..., 1])
    real = own & (length > 0)
    distance = np.where(real, (edge[..., 1] * v[..., 0] - edge[..., 0] * v[..., 1]) / np.where(real, length, 1.0),
                        np.inf)
    return {"area": area, "centroid": centroid, "inertia_per_mass": polar / safe,
            "radius": np.hypot(v[..., 0], v[..., 1]).max(-1, initial=0.0),
            "inradius": np.where(np.isfinite(distance).any(-1), distance.min(-1, initial=np.inf), 0.0)}


def particle_area(radius, n_vertices, vertices=None) -> np.ndarray:
    """(P,) area of each particle, m2: pi R^2 for a disk; the shoelace area of a polygon's
    vertices, (n/2) R^2 sin(2 pi/n) for a regular n-gon when ``vertices`` is not given."""
    radius = np.asarray(radius, dtype=float)
    n = np.asarray(n_vertices)
    if vertices is None:
        safe_n = np.where(n >= 3, n, 3)
        polygon = 0.5 * safe_n * radius ** 2 * np.sin(2 * np.pi / safe_n)
        return np.where(n >= 3, polygon, np.pi * radius ** 2)
    area = polygon_properties(body_vertices(radius, n, vertices))["area"]
    return np.where(n.reshape(-1) >= 3, area, np.pi * radius.reshape(-1) ** 2).reshape(radius.shape)


def inertia_per_mass(radius, n_vertices, vertices=None) -> np.ndarray:
    """(P,) moment of inertia per unit mass about the centroid, m2: R^2 / 2 for a disk; the
    fan sum of the module docstring for a polygon, R^2 (2 + cos(2 pi/n)) / 6 for a regular
    n-gon (the fan sum's closed form) when ``vertices`` is not given."""
    radius = np.asarray(radius, dtype=float)
    n = np.asarray(n_vertices)
    if vertices is None:
        safe_n = np.where(n >= 3, n, 3)
        polygon = radius ** 2 * (2.0 + np.cos(2 * np.pi / safe_n)) / 6.0
        return np.where(n >= 3, polygon, 0.5 * radius ** 2)
    polar = polygon_properties(body_vertices(radius, n, vertices))["inertia_per_mass"]
    return np.where(n.reshape(-1) >= 3, polar, 0.5 * radius.reshape(-1) ** 2).reshape(radius.shape)


def regular_polygons(radius, n_vertices, vertices=None) -> np.ndarray:
    """(P,) bool: which particles are regular polygons.

    A convex polygon whose vertices all lie at its circumscribed radius R from its centroid
    and whose edges all have one length is regular, whatever its orientation in its own frame;
    both are checked within :data:`REGULAR_TOLERANCE` R. Disks are not polygons (False).
    Without ``vertices`` (a file of the old layout) every polygon is regular.
    """
    n = np.asarray(n_vertices).astype(np.int64).reshape(-1)
    polygon = n >= 3
    if vertices is None or not polygon.any():
        return polygon
    radius = np.asarray(radius, dtype=float).reshape(-1)
    v, nxt, own = _shifted(body_vertices(radius, n, vertices))
    edge = np.hypot(*(nxt - v).transpose(2, 0, 1))
    distance = np.hypot(v[..., 0], v[..., 1])
    tolerance = REGULAR_TOLERANCE * radius
    on_circle = np.all(~own | (np.abs(distance - radius[:, None]) <= tolerance[:, None]), axis=-1)
    spread = np.where(own, edge, -np.inf).max(-1) - np.where(own, edge, np.inf).min(-1)
    return polygon & on_circle & (spread <= tolerance)


def particle_area_of(ds) -> np.ndarray:
    """:func:`particle_area` of a dataset of the contract (as :func:`body_vertices_of` reads
    it): from its ``vertices`` when it has them, the regular polygons' closed form otherwise."""
    vertices = ds["vertices"].values if "vertices" in ds.variables else None
    return particle_area(ds["radius"].values, ds["n_vertices"].values, vertices)


def shape_problems(radius, n_vertices, vertices) -> list[str]:
    """The contract's problems of a file's shapes, one line each (empty when there are none).

    Checked: ``n_vertices`` 0 or >= 3 and within the ``vertex`` dimension; a polygon's first
    ``n_vertices`` rows finite and the rest NaN (a disk's all NaN); every polygon convex and
    counter-clockwise (each turn v_{k-1} -> v_k -> v_{k+1} strictly to the left, and the
    boundary winding once around: the exterior angles sum to 2 pi, no star), its centroid
    at the origin (within :data:`CENTROID_TOLERANCE` R) and ``radius`` its farthest vertex
    (within :data:`RADIUS_TOLERANCE`).
    """
    radius = np.asarray(radius, dtype=float).reshape(-1)
    n = np.asarray(n_vertices).astype(np.int64).reshape(-1)
    v = np.asarray(vertices, dtype=float)
    problems = []
    bad_count = (n != 0) & (n < 3) | (n > v.shape[1])
    if bad_count.any():
        problems.append(f"n_vertices: {int(bad_count.sum())} particle(s) with a count other than 0 (disk) or 3 .. "
                        f"{v.shape[1]} (the vertex dimension), first particle {int(np.flatnonzero(bad_count)[0])}")
        return problems
    expected = np.arange(v.shape[1])[None, :] < n[:, None]
    finite = np.all(np.isfinite(v), axis=-1)
    layout = np.any(finite != expected, axis=-1)
    if layout.any():
        problems.append(f"vertices: {int(layout.sum())} particle(s) whose first n_vertices rows are not all finite "
                        f"or whose other rows are not NaN, first particle {int(np.flatnonzero(layout)[0])}")
        return problems
    polygon = n >= 3
    if not polygon.any():
        return problems
    p = v[polygon]
    current, nxt, _ = _shifted(p)
    count = n[polygon]
    k = np.arange(p.shape[1])
    previous_index = np.where(k[None, :] > 0, k[None, :] - 1, count[:, None] - 1)
    previous = np.take_along_axis(np.nan_to_num(p), previous_index[..., None], axis=-2)
    a, b = current - previous, nxt - current
    turn = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    real = k[None, :] < count[:, None]
    # left turns everywhere still allow a star (a boundary winding more than once): the
    # exterior angles of a convex polygon add up to one full turn
    # portable: the winding is only compared with 1 (to 1e-5), which the last bit cannot change
    winding = np.where(real, np.arctan2(turn, np.sum(a * b, axis=-1)), 0.0).sum(-1) / (2 * np.pi)
    concave = np.any((turn <= 0) & real, axis=-1) | ~np.isclose(winding, 1.0)
    ids = np.flatnonzero(polygon)
    if concave.any():
        problems.append(f"vertices: {int(concave.sum())} polygon(s) not convex with counter-clockwise vertices, "
                        f"first particle {int(ids[concave][0])}")
        return problems
    props = polygon_properties(p)
    size = radius[polygon]
    off = np.hypot(*props["centroid"].T) > CENTROID_TOLERANCE * size
    if off.any():
        problems.append(f"vertices: {int(off.sum())} polygon(s) whose centroid is not at the origin of their own "
                        f"frame, first particle {int(ids[off][0])}")
    wrong = np.abs(props["radius"] - size) > RADIUS_TOLERANCE * size
    if wrong.any():
        problems.append(f"radius: {int(wrong.sum())} polygon(s) whose radius is not their farthest vertex's "
                        f"distance from the centroid, first particle {int(ids[wrong][0])}")
    return problems


def body_vertices_of(ds) -> np.ndarray:
    """:func:`body_vertices` of a dataset of the contract (xarray, or anything whose
    ``ds[name].values`` and ``ds.variables`` read like it): its ``vertices`` when it has them,
    the regular polygons of ``radius`` and ``n_vertices`` otherwise."""
    vertices = ds["vertices"].values if "vertices" in ds.variables else None
    return body_vertices(ds["radius"].values, ds["n_vertices"].values, vertices)


def particle_inradius(radius, n_vertices, vertices=None) -> np.ndarray:
    """(P,) inradius of each particle, m: the smallest distance from the centroid to an edge
    line; R for a disk, R cos(pi/n) for a regular n-gon of circumscribed radius R when
    ``vertices`` is not given, :func:`polygon_properties`'s inradius of the vertices otherwise."""
    radius = np.asarray(radius, dtype=float)
    n = np.asarray(n_vertices)
    if vertices is None:
        safe_n = np.where(n >= 3, n, 3)
        return np.where(n >= 3, radius * np.cos(np.pi / safe_n), radius)
    inner = polygon_properties(body_vertices(radius, n, vertices))["inradius"]
    return np.where(n.reshape(-1) >= 3, inner, radius.reshape(-1)).reshape(radius.shape)


def has_irregular_polygons(radius, n_vertices, vertices=None) -> bool:
    """Whether any particle is a polygon that is not regular (:func:`regular_polygons`): what
    makes a file need version 2 of the contract (:func:`grainview.contract.schema.schema_version`)."""
    n = np.asarray(n_vertices).astype(np.int64).reshape(-1)
    if vertices is None:
        return False
    return bool(np.any((n >= 3) & ~regular_polygons(radius, n, vertices)))
