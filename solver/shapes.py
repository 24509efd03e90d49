"""Shapes of the bodies: disks and regular polygons, their area, mass, inertia and vertices.

A body is described by its centre ``pos`` (m), its rotation ``angle`` (rad), its circumscribed
radius ``radius`` R (m; the disk radius for a disk) and its number of vertices ``nvert``
(0 = disk, n >= 3 = regular n-gon). Vertex k of a polygon sits at

    x_k = pos + R (cos(angle + 2 pi k / n), sin(angle + 2 pi k / n)),   k = 0 .. n-1,

so the vertices run counter-clockwise, and edge k (from vertex k to vertex k+1) has the
outward unit normal of angle ``angle + pi (2k + 1) / n`` at the distance r = R cos(pi/n)
(the inradius) from the centre. These are the shapes of the data contract
(``grainview.contract.schema``: ``radius`` is the circumscribed radius, ``n_vertices`` 0 for disks).

Formulas (regular n-gon of circumscribed radius R, split into n triangles centre-edge with
apex angle alpha = 2 pi / n):

* area      A = (n/2) R^2 sin(2 pi / n)                         (disk: pi R^2)
* inertia   I/m = R^2 (2 + cos(2 pi / n)) / 6 = R^2 (1 + 2 cos^2(pi/n)) / 6
            about the centroid (disk: R^2 / 2). Each triangle O-a-b of the fan has the polar
            moment (A_t/6)(|a|^2 + |b|^2 + a.b) about its apex O.
* mass      m = rho A t for a slab of thickness t (m) and density rho (kg m-3); I = m (I/m).

The shape table (:class:`Shapes`) holds all of this once per simulation: each body's vertices
and edge normals in its own frame (polar angles measured from the body's ``angle``), its
inradius, area and inertia per unit mass. Detection, mass and inertia, plotting in tests and
the peers' exports read the table; nothing else rebuilds a vertex. A new shape (an irregular
convex polygon) is a new constructor of the table: the kernels read vertex lists of any length.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grainview.contract.errors import ParameterError
from grainview.contract.shapes import particle_area, vertex_phases

__all__ = ["Shapes", "SHAPES", "n_vertices_of", "polygon_area", "polygon_inertia_per_mass", "mass_and_inertia", "vertices", "inradius",
           "check_shapes"]


SHAPES = {"disk": 0, "disks": 0, "pentagon": 5, "pentagons": 5}
"""Shape names the scenes and the command line accept, and their vertex counts."""


def n_vertices_of(shape) -> int:
    """0 for disks, n for regular n-gons; accepts "disk", "pentagon" or an integer."""
    if isinstance(shape, str):
        if shape not in SHAPES:
            raise ParameterError(f"shape={shape!r}: expected 'disk', 'pentagon' or a number of vertices >= 3")
        return SHAPES[shape]
    n = int(shape)
    if n != 0 and n < 3:
        raise ParameterError(f"shape={shape!r}: a polygon needs at least 3 vertices (0 for disks)")
    return n


def check_shapes(radius, nvert):
    """Validate and convert ``radius`` (float64, > 0, finite) and ``nvert`` (int32, 0 or >= 3).

    Returns the two arrays broadcast to a common 1-D shape. Raises
    :class:`grainview.contract.errors.ParameterError` naming the offending parameter.
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
    radius R, pi R^2 for a disk (n = 0). Same definition as ``grainview.contract.shapes.particle_area``
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
    ``density`` may be a scalar or one value per body. Shorthand for
    ``Shapes.regular(radius, nvert).mass_and_inertia(density, thickness)``.
    """
    return Shapes.regular(radius, nvert).mass_and_inertia(density, thickness)


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
    Shorthand for ``Shapes.regular(radius, nvert).world_vertices(pos, angle)``."""
    return Shapes.regular(radius, nvert).world_vertices(pos, angle)


@dataclass(frozen=True, eq=False)
class Shapes:
    """The shape of every body, built once: what detection, dynamics and drawing read.

    Body b owns the vertices ``first_vertex[b]:first_vertex[b + 1]`` of the flat vertex
    arrays (none for a disk). Vertex k of body b, at rotation ``angle`` and centre ``pos``, is

        pos + vertex_radius[k] (cos(angle + vertex_angle[k]), sin(angle + vertex_angle[k])),

    and edge k (vertex k -> k+1, cyclically) has the outward unit normal of angle
    ``angle + normal_angle[k]``. The polar form makes a world vertex one addition and one
    cosine/sine away from the body's angle, with the same arithmetic as the contract's
    definition (``grainview.contract.shapes.world_vertices``), and it describes any polygon that is
    star-shaped about its centroid (every convex polygon).

    Attributes
    ----------
    radius : (N,) m, the circumscribed (bounding) radius; a disk's radius.
    n_vertices : (N,) int32, 0 for a disk.
    first_vertex : (N + 1,) int64, offsets into the vertex arrays.
    vertex_radius, vertex_angle, normal_angle : (V,) m, rad, rad.
    inradius : (N,) m, the distance from the centre to the nearest edge line (R for a disk).
    area : (N,) m2.
    inertia_per_mass : (N,) m2, I/m about the centroid.
    """

    radius: np.ndarray
    n_vertices: np.ndarray
    first_vertex: np.ndarray
    vertex_radius: np.ndarray
    vertex_angle: np.ndarray
    normal_angle: np.ndarray
    inradius: np.ndarray
    area: np.ndarray
    inertia_per_mass: np.ndarray

    @classmethod
    def regular(cls, radius, n_vertices) -> "Shapes":
        """Disks (n = 0) and regular n-gons of circumscribed radius R (module docstring):
        vertex k at the polar angle 2 pi k/n (the contract's ``vertex_phases``), the normal of
        edge k at pi (2k + 1)/n, area and inertia from their closed forms."""
        radius, nvert = check_shapes(radius, n_vertices)
        first = np.zeros(radius.size + 1, np.int64)
        np.cumsum(nvert, out=first[1:])
        vertex_radius = np.repeat(radius, nvert)
        vertex_angle = np.empty(int(first[-1]))
        normal_angle = np.empty(int(first[-1]))
        for n in np.unique(nvert[nvert >= 3]):
            rows = (first[:-1][nvert == n, None] + np.arange(n)).ravel()
            vertex_angle[rows] = np.tile(vertex_phases(int(n)), rows.size // n)
            normal_angle[rows] = np.tile(np.pi * (2 * np.arange(n) + 1) / n, rows.size // n)
        return cls(radius, nvert, first, vertex_radius, vertex_angle, normal_angle,
                   inradius(radius, nvert), polygon_area(radius, nvert), polygon_inertia_per_mass(radius, nvert))

    @classmethod
    def convex(cls, polygons) -> "Shapes":
        """Convex polygons of any shape, each given by its vertices in its own frame: a list of
        (n, 2) arrays in m, counter-clockwise, centroid at the origin. The area is the
        shoelace sum, I/m the fan sum of (A_t/6)(|a|^2 + |b|^2 + a.b) over the triangles
        centre-a-b divided by the area (module docstring), the bounding radius the farthest
        vertex, the inradius the nearest edge line. Detection reads these tables as it reads
        regular ones; the data contract itself stores regular polygons only."""
        tables = []
        for b, vertices in enumerate(polygons):
            v = np.asarray(vertices, dtype=np.float64)
            if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3 or not np.all(np.isfinite(v)):
                raise ParameterError(f"polygon {b}: expected an (n, 2) array of n >= 3 finite vertices (m), "
                                     f"got shape {v.shape}")
            edge = np.roll(v, -1, axis=0) - v
            turn = edge[:, 0] * np.roll(edge, -1, axis=0)[:, 1] - edge[:, 1] * np.roll(edge, -1, axis=0)[:, 0]
            if np.any(turn <= 0):
                raise ParameterError(f"polygon {b}: the vertices must run counter-clockwise around a convex polygon")
            cross = v[:, 0] * np.roll(v, -1, axis=0)[:, 1] - v[:, 1] * np.roll(v, -1, axis=0)[:, 0]
            area = 0.5 * cross.sum()
            centroid = (cross[:, None] * (v + np.roll(v, -1, axis=0))).sum(0) / (6.0 * area)
            size = np.abs(v).max()
            if np.hypot(*centroid) > 1e-9 * size:
                raise ParameterError(f"polygon {b}: its centroid {centroid.tolist()} m must be at the origin")
            nxt = np.roll(v, -1, axis=0)
            polar = (cross / 2.0 / 6.0 * ((v ** 2).sum(1) + (nxt ** 2).sum(1) + (v * nxt).sum(1))).sum()
            outward = np.column_stack([edge[:, 1], -edge[:, 0]]) / np.hypot(edge[:, 0], edge[:, 1])[:, None]
            tables.append((v, outward, area, polar / area))
        n_vertices = np.array([len(t[0]) for t in tables], np.int32)
        first = np.zeros(n_vertices.size + 1, np.int64)
        np.cumsum(n_vertices, out=first[1:])
        v = np.concatenate([t[0] for t in tables]) if tables else np.empty((0, 2))
        outward = np.concatenate([t[1] for t in tables]) if tables else np.empty((0, 2))
        body = np.repeat(np.arange(n_vertices.size), n_vertices)
        vertex_radius = np.hypot(v[:, 0], v[:, 1])
        radius = np.zeros(n_vertices.size)
        np.maximum.at(radius, body, vertex_radius)
        inradius = np.full(n_vertices.size, np.inf)
        np.minimum.at(inradius, body, (outward * v).sum(1))
        return cls(radius, n_vertices, first, vertex_radius, np.arctan2(v[:, 1], v[:, 0]),
                   np.arctan2(outward[:, 1], outward[:, 0]), inradius,
                   np.array([t[2] for t in tables]), np.array([t[3] for t in tables]))

    def __len__(self) -> int:
        return int(self.radius.size)

    @property
    def max_vertices(self) -> int:
        """The largest vertex count (0 if every body is a disk)."""
        return int(self.n_vertices.max()) if self.n_vertices.size else 0

    def local_vertices(self, body: int | None = None) -> np.ndarray:
        """Vertices in the bodies' own frames (centre at the origin, angle 0), m: (n, 2) for
        ``body``, or the whole (V, 2) table (rows ``first_vertex[b]:first_vertex[b + 1]`` for
        body b) — the form other engines and file exports take."""
        rows = (slice(None) if body is None
                else slice(int(self.first_vertex[body]), int(self.first_vertex[body + 1])))
        r, phi = self.vertex_radius[rows], self.vertex_angle[rows]
        return np.stack([r * np.cos(phi), r * np.sin(phi)], -1)

    def world_vertices(self, pos, angle) -> np.ndarray:
        """(N, maxn, 2) m, every body's vertices at centres ``pos`` (N, 2) m and rotations
        ``angle`` (N,) rad, counter-clockwise; rows beyond a body's own count are NaN."""
        n = len(self)
        pos = np.asarray(pos, dtype=np.float64).reshape(-1, 2)
        if pos.shape[0] != n:
            raise ParameterError(f"pos must have shape (N, 2) with N = {n}, got {pos.shape}")
        angle = np.broadcast_to(np.asarray(angle, dtype=np.float64), (n,))
        out = np.full((n, self.max_vertices, 2), np.nan)
        body = np.repeat(np.arange(n), self.n_vertices)
        slot = np.arange(self.vertex_radius.size) - self.first_vertex[body]
        phase = angle[body] + self.vertex_angle
        out[body, slot, 0] = pos[body, 0] + self.vertex_radius * np.cos(phase)
        out[body, slot, 1] = pos[body, 1] + self.vertex_radius * np.sin(phase)
        return out

    def mass_and_inertia(self, density, thickness=1.0):
        """Mass (kg) and moment of inertia about the centroid (kg m2) of every body for a slab
        of ``thickness`` (m) and ``density`` (kg m-3, scalar or per body): m = rho A t, I = m (I/m)."""
        density = np.asarray(density, dtype=np.float64)
        if not np.all(np.isfinite(density)) or np.any(density <= 0):
            raise ParameterError("density must be finite and > 0 (kg m-3)")
        if not np.isfinite(thickness) or thickness <= 0:
            raise ParameterError(f"thickness={thickness!r}: expected a finite slab thickness > 0 (m)")
        mass = np.broadcast_to(density, self.radius.shape) * self.area * float(thickness)
        inertia = mass * self.inertia_per_mass
        return np.ascontiguousarray(mass, dtype=np.float64), np.ascontiguousarray(inertia, dtype=np.float64)
