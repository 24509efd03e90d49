"""What a sample's particles look like: a shape by name, a family of random convex polygons, or
the polygons of a file of vertex lists.

A ``shape`` (:class:`solver.preparation.Preparation`, ``grainview run --shape``) is one of

* ``"disk"``, ``"pentagon"`` or a number of vertices n >= 3: every particle a disk or a regular
  n-gon (:data:`solver.shapes.SHAPES`, :meth:`solver.shapes.Shapes.regular`);
* ``"irregular"``: random convex polygons, one per particle (:func:`random_convex_polygons`,
  with the parameters :data:`IRREGULAR`);
* the path of a JSON file of vertex lists, ``{"polygons": [[[x, y], ...], ...]}`` (a name
  ending in ``.json``; :func:`read_polygons`): particle k takes the file's polygon k modulo
  their count.

Sizes are the sample's size mix whatever the shape: a particle's circumscribed radius R (its
farthest vertex from its centroid) is the one :func:`solver.packing.deposit` drew for it, and
its polygon is the family's or the file's, scaled to that R (the file gives forms, not sizes).
The deposit places the circumscribed disks, so no two polygons overlap whatever their
orientation; an irregular or file polygon is turned by an angle drawn uniformly in [0, 2 pi).

Randomness: the polygons and then the orientations are drawn from
``numpy.random.default_rng([seed, 1])``, a stream apart from the deposit's
(``default_rng(seed)``, which draws the size order and a regular polygon's orientation), so the
same seed gives the same positions and sizes for every shape.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass

import numpy as np

from grainview.contract import shapes as contract
from grainview.contract.errors import ParameterError

from .shapes import SHAPES, Shapes, n_vertices_of, polygon_problem

__all__ = ["IrregularFamily", "IRREGULAR", "FAMILIES", "check_shape", "shape_label", "random_convex_polygons",
           "read_polygons", "sample_shapes", "unit_polygon"]


@dataclass(frozen=True)
class IrregularFamily:
    """Random convex polygons of unit circumscribed radius (scaled to each particle's size).

    Polygon by polygon: a vertex count n drawn uniformly in ``min_vertices`` .. ``max_vertices``;
    n polar angles 2 pi (k + u_k) / n + phi with u_k uniform in [-``jitter``/2, ``jitter``/2)
    (so no two vertices coincide) and phi uniform in [0, 2 pi); the points at those angles on an
    ellipse of semi-axes 1 and 1/e, e (the elongation) uniform in ``elongation``, each pulled
    towards the centre by a factor uniform in [1 - ``roughness``, 1]; their convex hull
    (``scipy.spatial.ConvexHull``: a point pulled inside is dropped, so a polygon may have fewer
    than n vertices, never fewer than 3), shifted to put its centroid at the origin and scaled
    so that its farthest vertex is at 1.
    """

    min_vertices: int = 4
    max_vertices: int = 8
    elongation: tuple = (1.0, 1.6)
    roughness: float = 0.2
    jitter: float = 0.6

    def validate(self):
        if not (3 <= self.min_vertices <= self.max_vertices):
            raise ParameterError(f"min_vertices={self.min_vertices}, max_vertices={self.max_vertices}: expected "
                                 "3 <= min_vertices <= max_vertices")
        low, high = self.elongation
        if not (1.0 <= low <= high and np.isfinite(high)):
            raise ParameterError(f"elongation={self.elongation!r}: expected a range 1 <= low <= high")
        if not (0.0 <= self.roughness < 0.5) or not (0.0 <= self.jitter < 1.0):
            raise ParameterError(f"roughness={self.roughness!r}, jitter={self.jitter!r}: expected roughness in "
                                 "[0, 0.5) and jitter in [0, 1)")
        return self


IRREGULAR = IrregularFamily()
"""The ``irregular`` family's parameters: 4 to 8 vertices on ellipses of elongation 1 to 1.6,
pulled in by up to 20%, angles jittered by up to +-30% of their spacing."""

FAMILIES = {"irregular": IRREGULAR}
"""Named families of random convex polygons."""

SHAPE_FILE_SUFFIX = ".json"
"""A ``shape`` ending in this is the path of a file of vertex lists (:func:`read_polygons`)."""


def unit_polygon(vertices) -> np.ndarray:
    """(n, 2) the convex polygon ``vertices`` (counter-clockwise) shifted to put its centroid at
    the origin and scaled to a circumscribed radius of 1 (``grainview.contract.shapes.polygon_properties``)."""
    v = np.asarray(vertices, dtype=np.float64)
    v = v - contract.polygon_properties(v[None])["centroid"][0]
    return v / contract.polygon_properties(v[None])["radius"][0]


def random_convex_polygons(count, rng, family: IrregularFamily = IRREGULAR) -> list:
    """``count`` random convex polygons of ``family`` (:class:`IrregularFamily`), each an (n, 2)
    array of unit circumscribed radius, counter-clockwise, centroid at the origin, drawn from
    the numpy Generator ``rng``."""
    from scipy.spatial import ConvexHull

    family.validate()
    low, high = family.elongation
    polygons = []
    for _ in range(int(count)):
        n = int(rng.integers(family.min_vertices, family.max_vertices + 1))
        phase = 2 * np.pi * (np.arange(n) + family.jitter * (rng.random(n) - 0.5)) / n + rng.uniform(0, 2 * np.pi)
        pull = 1.0 - family.roughness * rng.random(n)
        points = pull[:, None] * np.column_stack([np.cos(phase), np.sin(phase) / rng.uniform(low, high)])
        hull = ConvexHull(points).vertices  # counter-clockwise in 2D
        polygons.append(unit_polygon(points[hull]))
    return polygons


def read_polygons(path) -> list:
    """The polygons of a JSON file ``{"polygons": [[[x, y], ...], ...]}``: a list of (n, 2)
    arrays of unit circumscribed radius, centroid at the origin (:func:`unit_polygon`; the
    file's units and sizes do not matter). Each polygon must have at least 3 vertices and be
    convex, its vertices given counter-clockwise. Raises :class:`ParameterError` in one line
    naming the file, the polygon and what is wrong."""
    expected = 'expected a JSON file {"polygons": [[[x, y], ...], ...]} of convex polygons, counter-clockwise'
    try:
        with open(path, encoding="utf-8") as stream:
            content = json.load(stream)
    except FileNotFoundError:
        raise ParameterError(f"{path}: no such file; {expected}") from None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc).splitlines()[0]
        raise ParameterError(f"{path}: cannot read it ({reason}); {expected}") from None
    polygons = content.get("polygons") if isinstance(content, dict) else None
    if not isinstance(polygons, list) or not polygons:
        raise ParameterError(f"{path}: no list of polygons under the key 'polygons'; {expected}")
    out = []
    for k, polygon in enumerate(polygons):
        try:
            v = np.array(polygon, dtype=np.float64)
        except (TypeError, ValueError):
            v = None
        if v is None or v.ndim != 2 or v.shape[1:] != (2,):
            raise ParameterError(f"{path}: polygon {k} is not a list of [x, y] pairs of numbers; {expected}")
        problem = polygon_problem(v)
        if problem:
            raise ParameterError(f"{path}: polygon {k}: {problem}")
        out.append(unit_polygon(v))
    return out


MAX_VERTICES = 64
"""Most vertices a regular polygon of a scene may have (a polygon of more is a disk for every purpose)."""


def _kind(shape):
    """("regular", n), ("family", IrregularFamily) or ("file", path) for a ``shape``."""
    if isinstance(shape, (str, os.PathLike)):
        text = os.fspath(shape)
        if text in FAMILIES:
            return "family", FAMILIES[text]
        if text.lower().endswith(SHAPE_FILE_SUFFIX):
            return "file", text
        if text not in SHAPES:
            raise ParameterError(f"shape={text!r}: expected 'disk', 'pentagon', a number of vertices from 3 to "
                                 f"{MAX_VERTICES}, "
                                 f"{', '.join(repr(name) for name in FAMILIES)} or a {SHAPE_FILE_SUFFIX} file of "
                                 "vertex lists")
    n = n_vertices_of(shape)
    if n > MAX_VERTICES:
        raise ParameterError(f"shape={shape!r}: expected at most {MAX_VERTICES} vertices (a polygon of more is a "
                             "disk for every purpose)")
    return "regular", n


def check_shape(shape):
    """Refuse, in one :class:`ParameterError`, a ``shape`` that is not a regular shape's name or
    vertex count, a family's name, or a readable file of convex polygons (which it reads)."""
    kind, what = _kind(shape)
    if kind == "file":
        read_polygons(what)
    return shape


def is_regular(shape) -> bool:
    """Whether every particle of ``shape`` is a disk or a regular polygon."""
    return _kind(shape)[0] == "regular"


def regular_vertex_count(shape) -> int:
    """The vertex count a regular ``shape`` gives the deposit (0, disks, for the other shapes:
    the deposit places circumscribed disks and leaves their orientation to :func:`sample_shapes`)."""
    kind, what = _kind(shape)
    return what if kind == "regular" else 0


def shape_label(shape) -> str:
    """A short name of ``shape`` for file names and messages: the name, the vertex count, or a
    file's stem."""
    kind, what = _kind(shape)
    return os.path.splitext(os.path.basename(what))[0] if kind == "file" else str(shape)


def sample_shapes(shape, radius, seed=0):
    """The shapes of a deposited sample of ``shape`` (module docstring) whose particles have the
    circumscribed radii ``radius`` (N,) m: ``(shapes, angle)``, a :class:`solver.shapes.Shapes`
    and the particles' orientations (N,) rad, or None for a regular shape (the deposit's)."""
    kind, what = _kind(shape)
    radius = np.asarray(radius, dtype=np.float64)
    if kind == "regular":
        return Shapes.regular(radius, np.full(radius.size, what, np.int32)), None
    rng = np.random.default_rng([int(seed), 1])
    if kind == "family":
        unit = random_convex_polygons(radius.size, rng, what)
    else:
        polygons = read_polygons(what)
        unit = [polygons[k % len(polygons)] for k in range(radius.size)]
    angle = rng.uniform(0.0, 2 * np.pi, radius.size)
    return Shapes.convex([v * r for v, r in zip(unit, radius)]), angle
