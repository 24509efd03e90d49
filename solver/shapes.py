"""Shapes of the bodies: disks, regular polygons and any convex polygon; their area, mass,
inertia and vertices. The geometry itself is the contract's (:mod:`grainview.contract.shapes`,
the one place for it); this module builds the solver's table from it.

A body is described by its centroid ``pos`` (m), its rotation ``angle`` (rad), its circumscribed
radius ``radius`` R (m; the disk radius for a disk, a polygon's farthest vertex) and its number
of vertices ``nvert`` (0 = disk, n >= 3 = polygon). A polygon's vertex k, v_k in its own frame,
sits at pos + Rot(angle) v_k, counter-clockwise. For a regular n-gon (:meth:`Shapes.regular`)

    x_k = pos + R (cos(angle + 2 pi k / n), sin(angle + 2 pi k / n)),   k = 0 .. n-1,

and edge k (from vertex k to vertex k+1) has the outward unit normal of angle
``angle + pi (2k + 1) / n`` at the distance r = R cos(pi/n) (the inradius) from the centre.
Any other convex polygon is given by its vertices (:meth:`Shapes.convex`; families and files
of them in :mod:`solver.shape_families`). These are the shapes of the data contract
(``radius`` the circumscribed radius, ``n_vertices`` 0 for disks, ``vertices`` the polygons'
own-frame vertices).

Formulas (regular n-gon of circumscribed radius R, split into n triangles centre-edge with
apex angle alpha = 2 pi / n; any polygon: the contract's shoelace and fan sums):

* area      A = (n/2) R^2 sin(2 pi / n)                         (disk: pi R^2)
* inertia   I/m = R^2 (2 + cos(2 pi / n)) / 6 = R^2 (1 + 2 cos^2(pi/n)) / 6
            about the centroid (disk: R^2 / 2). Each triangle O-a-b of the fan has the polar
            moment (A_t/6)(|a|^2 + |b|^2 + a.b) about its apex O.
* mass      m = rho A t for a slab of thickness t (m) and density rho (kg m-3); I = m (I/m).

The shape table (:class:`Shapes`) holds all of this once per simulation: each body's vertices
and edge normals in its own frame (polar angles measured from the body's ``angle``), its
inradius, area and inertia per unit mass. Detection, mass and inertia, plotting in tests and
the peers' exports read the table; nothing else rebuilds a vertex. The kernels read vertex
lists of any length, so a regular and an irregular polygon differ only in their table.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grainview.contract import portable_math
from grainview.contract import shapes as contract
from grainview.contract.errors import ParameterError

__all__ = ["Shapes", "SHAPES", "n_vertices_of", "polygon_area", "polygon_inertia_per_mass", "mass_and_inertia", "vertices", "inradius",
           "check_shapes", "polygon_problem", "MAX_SLENDERNESS"]


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
    return contract.particle_area(radius, nvert)


def polygon_inertia_per_mass(radius, nvert):
    """Moment of inertia per unit mass I/m (m2) about the centroid: R^2 (2 + cos(2 pi/n))/6
    for a regular n-gon of circumscribed radius R, R^2/2 for a disk (n = 0)
    (``grainview.contract.shapes.inertia_per_mass``, which it calls)."""
    radius, nvert = check_shapes(radius, nvert)
    return contract.inertia_per_mass(radius, nvert)


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
    return contract.particle_inradius(radius, nvert)


def vertices(pos, angle, radius, nvert):
    """Vertices (N, maxn, 2) in m of every body, counter-clockwise, vertex k at
    pos + R (cos(angle + 2 pi k/n), sin(angle + 2 pi k/n)); rows beyond a body's own n (and
    all rows of disks) are NaN. ``maxn`` is the largest ``nvert`` (0 if all are disks).
    Shorthand for ``Shapes.regular(radius, nvert).world_vertices(pos, angle)``."""
    return Shapes.regular(radius, nvert).world_vertices(pos, angle)


MAX_SLENDERNESS = 10.0
"""The largest ratio R / r of a polygon's circumscribed radius R to its inradius r (both about
its centroid) that the solver accepts. The detection and time-step bounds scale with R, while
a polygon only 2 r thick is crossed once an interpenetration reaches r: then the separating
axis flips and the contact pushes the bodies through one another. Measured (docs/solver.md,
"Shapes"): up to R/r = 10.5 the compaction's largest interpenetration stays below 1% of r;
from R/r = 15 it reaches 0.05 to 5.6 r, the walls passing through particles."""


def polygon_problem(vertices) -> str | None:
    """What keeps ``vertices`` (n, 2) from being a convex polygon given counter-clockwise that
    the solver can simulate, in a few words, or None: fewer than 3 vertices, a non-finite one,
    two equal consecutive ones, a clockwise order, a reflex or straight corner or a boundary
    that winds more than once (a star polygon; the contract's check,
    ``grainview.contract.shapes.shape_problems``), or a polygon more slender than
    R / r = :data:`MAX_SLENDERNESS` (circumscribed radius R over inradius r, about the
    centroid)."""
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 2:
        return f"expected an (n, 2) array of vertices, got shape {v.shape}"
    if len(v) < 3:
        return f"{len(v)} vertices, expected at least 3"
    if not np.all(np.isfinite(v)):
        return "a vertex is not finite"
    edge = np.roll(v, -1, axis=0) - v
    if np.any(np.all(edge == 0, axis=1)):
        return "two consecutive vertices are equal"
    before = np.roll(edge, 1, axis=0)
    if np.all(before[:, 0] * edge[:, 1] - before[:, 1] * edge[:, 0] < 0):
        return "the vertices run clockwise, expected counter-clockwise"
    not_convex = "not convex (expected every corner to turn left, once around)"
    props = contract.polygon_properties(v[None])
    if not props["area"][0] > 0:  # a convex counter-clockwise polygon encloses a positive area
        return not_convex
    centred = v - props["centroid"][0]
    props = contract.polygon_properties(centred[None])
    if contract.shape_problems(props["radius"], [len(v)], centred[None]):
        return not_convex  # centred and sized as the contract asks, convexity is all it can find
    slenderness = props["radius"][0] / props["inradius"][0]
    if not slenderness <= MAX_SLENDERNESS:
        return (f"too slender: its circumscribed radius is {slenderness:.3g} times its inradius (about the "
                f"centroid), expected at most {MAX_SLENDERNESS:g} (thinner polygons let walls and particles pass "
                "through one another)")
    return None


@dataclass(frozen=True, eq=False)
class Shapes:
    """The shape of every body, built once: what detection, dynamics and drawing read.

    Body b owns the vertices ``first_vertex[b]:first_vertex[b + 1]`` of the flat vertex
    arrays (none for a disk). Vertex k of body b, at rotation ``angle`` and centre ``pos``, is

        pos + vertex_radius[k] (cos(angle + vertex_angle[k]), sin(angle + vertex_angle[k])),

    and edge k (vertex k -> k+1, cyclically) has the outward unit normal of angle
    ``angle + normal_angle[k]``. The polar form makes a world vertex one addition and one
    cosine/sine away from the body's angle; it equals the contract's definition
    p + Rot(angle) v_k (``grainview.contract.shapes.world_vertices``) to round-off, and it
    describes any polygon that is star-shaped about its centroid (every convex polygon).

    Attributes
    ----------
    radius : (N,) m, the circumscribed (bounding) radius; a disk's radius.
    n_vertices : (N,) int32, 0 for a disk.
    first_vertex : (N + 1,) int64, offsets into the vertex arrays.
    vertex_radius, vertex_angle, normal_angle : (V,) m, rad, rad.
    inradius : (N,) m, the distance from the centre to the nearest edge line (R for a disk).
    area : (N,) m2.
    inertia_per_mass : (N,) m2, I/m about the centroid.
    vertex_xy : (V, 2) m, the vertices of :meth:`convex` as given (None for :meth:`regular`:
        the contract's regular vertices); what a file stores (:meth:`body_vertices`).
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
    vertex_xy: np.ndarray | None = None

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
            vertex_angle[rows] = np.tile(contract.vertex_phases(int(n)), rows.size // n)
            normal_angle[rows] = np.tile(np.pi * (2 * np.arange(n) + 1) / n, rows.size // n)
        return cls(radius, nvert, first, vertex_radius, vertex_angle, normal_angle,
                   inradius(radius, nvert), polygon_area(radius, nvert), polygon_inertia_per_mass(radius, nvert))

    @classmethod
    def convex(cls, polygons) -> "Shapes":
        """Bodies of any convex shape, each given in its own frame: an (n, 2) array of its
        vertices in m (n >= 3, counter-clockwise, centroid at the origin), or a number, the
        radius in m of a disk. Area, centroid, I/m, circumscribed radius (the farthest vertex)
        and inradius are the contract's (``grainview.contract.shapes.polygon_properties``),
        computed polygon by polygon from its own vertices, so that the same vertices give the
        same tables bit for bit (a run resumed from its file). The vertices are kept as given
        (:meth:`body_vertices`, what a file stores). Raises :class:`ParameterError` naming the
        first polygon that is not convex and counter-clockwise or more slender than
        :data:`MAX_SLENDERNESS` (:func:`polygon_problem`), or whose centroid is off the origin."""
        n_bodies = len(polygons)
        n_vertices = np.zeros(n_bodies, np.int32)
        radius, inner = np.zeros(n_bodies), np.zeros(n_bodies)
        area, polar = np.zeros(n_bodies), np.zeros(n_bodies)
        rows = []
        for b, body in enumerate(polygons):
            if np.ndim(body) == 0:
                r = float(body)
                if not (np.isfinite(r) and r > 0):
                    raise ParameterError(f"body {b}: a disk's radius must be finite and > 0 (m), got {body!r}")
                radius[b] = inner[b] = r
                area[b], polar[b] = np.pi * r ** 2, 0.5 * r ** 2
                continue
            v = np.asarray(body, dtype=np.float64)
            problem = polygon_problem(v)
            if problem:
                raise ParameterError(f"polygon {b}: {problem}")
            props = contract.polygon_properties(v[None])
            if np.hypot(*props["centroid"][0]) > contract.CENTROID_TOLERANCE * props["radius"][0]:
                raise ParameterError(f"polygon {b}: its centroid {props['centroid'][0].tolist()} m must be at the "
                                     "origin of its own frame")
            n_vertices[b] = len(v)
            radius[b], inner[b] = props["radius"][0], props["inradius"][0]
            area[b], polar[b] = props["area"][0], props["inertia_per_mass"][0]
            rows.append(v)
        first = np.zeros(n_bodies + 1, np.int64)
        np.cumsum(n_vertices, out=first[1:])
        v = np.concatenate(rows) if rows else np.empty((0, 2))
        edge = np.concatenate([np.roll(r, -1, axis=0) - r for r in rows]) if rows else np.empty((0, 2))
        return cls(radius, n_vertices, first, np.hypot(v[:, 0], v[:, 1]), portable_math.arctan2(v[:, 1], v[:, 0]),
                   portable_math.arctan2(-edge[:, 0], edge[:, 1]), inner, area, polar, vertex_xy=v)

    @classmethod
    def of(cls, radius, n_vertices, vertices=None) -> "Shapes":
        """The shapes of a file of the contract: ``radius`` (P,) m, ``n_vertices`` (P,) and the
        optional ``vertices`` (P, V, 2) m. Regular ones (:meth:`regular`) when the file has no
        ``vertices`` or holds exactly the regular polygons' (``grainview.contract.shapes.body_vertices``
        of its radii and counts, as :meth:`body_vertices` writes them), so that a regular sample
        read back has the tables it was simulated with; :meth:`convex` of the vertices otherwise."""
        radius, n_vertices = check_shapes(radius, n_vertices)
        if vertices is None:
            return cls.regular(radius, n_vertices)
        vertices = np.asarray(vertices, dtype=np.float64)
        if np.array_equal(vertices, contract.body_vertices(radius, n_vertices), equal_nan=True):
            return cls.regular(radius, n_vertices)
        return cls.convex([vertices[b, :n] if n else radius[b] for b, n in enumerate(n_vertices)])

    def body_vertices(self) -> np.ndarray:
        """(N, V, 2) every body's vertices in its own frame, m, NaN beyond its count (all NaN
        for a disk): the contract's ``vertices`` (``grainview.contract.shapes.body_vertices``).
        Regular polygons give the contract's regular vertices; polygons given to
        :meth:`convex` give their vertices exactly as given."""
        if self.vertex_xy is None:
            return contract.body_vertices(self.radius, self.n_vertices)
        out = np.full((len(self), self.max_vertices, 2), np.nan)
        body = np.repeat(np.arange(len(self)), self.n_vertices)
        out[body, np.arange(body.size) - self.first_vertex[body]] = self.vertex_xy
        return out

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
