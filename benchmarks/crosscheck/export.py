"""Between the data contract and the peer engines: the sample out, the peers' snapshots in.

Runs in the project's environment (grainview). :func:`sample_to_npz` writes the last snapshot
of a compacted sample (``grainview run isotropic ...``) as the plain arrays the peer engines
read; :func:`raw_to_contract` turns a peer's raw snapshots (``peer_common.py``) into a netCDF
file of the grainview data contract (``docs/schema.md``).

The contract's conventions for the peers' contacts are applied by grainview's peer reader
(:mod:`grainview.formats.peers`, which this module calls); in short:

* one entry per body pair; ``i < j`` for particle pairs; for a wall contact ``i`` is the
  particle and ``j = N + w`` (walls bottom, right, top, left), which ``i = min, j = max``
  gives as well;
* ``normal``: the unit vector from i to j (the engine's normal, reversed when the engine's
  first body is j); ``fn``, ``ft``: the components along ``normal`` and ``t = (-n_y, n_x)`` of
  the resultant force (N) exerted by i on j, i.e. the engine's force on its second body,
  reversed when its first body is j (fn and ft themselves do not change with the order, only
  the normal does); ``fn > 0`` is compressive and only pairs with ``fn > 0`` are written;
* ``kind``: 2 (double) when the engine's manifold holds two points (Box2D ``pointCount == 2``,
  pymunk ``len(contact_point_set.points) == 2``), else 1 (simple) -- a geometric criterion,
  as the project's solver's edge-to-edge test, not whether both points carry force;
* ``point``: the application point of the resultant, the points weighted by their normal
  forces;
* ``branch``: ``x_j - x_i`` for particle pairs, ``point - x_i`` for wall contacts.

Besides the required variables the files hold ``velocity``, ``angular_velocity``,
``wall_position``, ``wall_velocity``, ``wall_force`` (the sum of the contact forces exerted by
the particles on each wall), ``normal_impulse`` (N s: the normal force of each manifold point
times dt, 0 for a simple contact's second point, so that a double contact whose two points
both carry force can be told from one that carries it at one point), ``step`` and
``max_interpenetration`` (the largest overlap of the configuration measured by this project's
narrow phase: one metric for every engine).
"""

from __future__ import annotations

import numpy as np

from grainview.contract.errors import GrainviewError
from grainview.formats.peers import WALL_NORMALS, WALLS


def sample_to_npz(nc_path, npz_path):
    """Write the last snapshot of the compacted sample ``nc_path`` to ``npz_path`` for the peers.

    Keys (SI): position (N, 2) m, angle rad, velocity m/s, angular_velocity rad/s, radius
    (circumscribed) m, n_vertices (0 disk), mass kg, inertia kg m2, wall_position and
    wall_velocity (4, 2) for bottom, right, top, left; right_wall_mass kg; sigma0 Pa (the
    stress of the right wall); friction, wall_friction; time_step s; thickness m; the shape
    table's body-frame vertices (first_vertex (N + 1,), local_vertices (V, 2) m) and inradius m.
    Returns the dict written. Raises GrainviewError (one line) for a file that is not a
    four-wall box with a stress-driven right wall.
    """
    import grainview

    with grainview.open_dataset(nc_path, chunks=None) as ds:
        names = tuple(str(w) for w in ds["wall"].values) if "wall" in ds.coords else ()
        if names != WALLS or "wall_position" not in ds or "wall_stress_Pa" not in ds.attrs:
            raise GrainviewError(f"{nc_path}: not a compacted sample of this project (needs the walls {WALLS}, "
                                 "wall_position and wall_stress_Pa); make one with `grainview run isotropic`")
        last = ds.isel(time=-1)
        out = {name: last[name].values.astype(float) for name in ("position", "angle", "wall_position")}
        for name, shape in (("velocity", out["position"].shape), ("angular_velocity", out["angle"].shape),
                            ("wall_velocity", (4, 2))):
            out[name] = last[name].values.astype(float) if name in ds else np.zeros(shape)
        for name in ("radius", "mass", "inertia"):
            out[name] = ds[name].values.astype(float)
        out["n_vertices"] = ds["n_vertices"].values.astype(np.int32)
        attrs = ds.attrs
        out["right_wall_mass"] = float(np.asarray(attrs["wall_mass_kg"])[1])
        out["sigma0"] = float(np.asarray(attrs["wall_stress_Pa"])[1])
        out["friction"] = float(attrs["solver_friction"])
        out["wall_friction"] = float(attrs["solver_wall_friction"])
        out["time_step"] = float(attrs["solver_time_step"])
        out["thickness"] = float(attrs.get("thickness_m", 1.0))
    if out["wall_friction"] != 0.0:
        raise GrainviewError(f"{nc_path}: wall friction {out['wall_friction']}; the cross-check's walls are "
                             "frictionless")
    from solver.shapes import Shapes

    shapes = Shapes.regular(out["radius"], out["n_vertices"])
    out["first_vertex"], out["local_vertices"], out["inradius"] = (shapes.first_vertex, shapes.local_vertices(),
                                                                   shapes.inradius)
    np.savez(npz_path, **out)
    return out


def largest_overlap(snap, radius, n_vertices):
    """Largest interpenetration (m) of a snapshot's configuration, by this project's narrow
    phase (particle pairs within 2 % of the smallest diameter, and the walls)."""
    from solver import broadphase, narrowphase
    from solver.shapes import Shapes

    position, angle = snap["position"], snap["angle"]
    margin = 0.02 * 2 * float(np.min(radius))
    wall_point, wall_normal = snap["wall_position"], WALL_NORMALS
    pi, pj = broadphase.candidate_pairs(position, radius, margin)
    wp, ww = broadphase.wall_candidates(position, radius, wall_point, wall_normal, margin)
    shapes = Shapes.regular(radius, n_vertices)
    pts = narrowphase.detect(position, angle, shapes, wall_point, wall_normal, margin, pi, pj, wp, ww)
    return float(max(0.0, -pts.gap.min())) if len(pts.gap) else 0.0


def raw_to_contract(raw_dir, sample_npz, out_path, attrs=None):
    """Write the raw snapshots of ``raw_dir`` (a peer's output) as the contract file
    ``out_path`` (replaced if it exists) with grainview's peer reader
    (:func:`grainview.formats.peers.convert_peer`, which applies the conventions above), adding
    the biaxial test's settings to the global attributes and each snapshot's
    ``max_interpenetration`` by this project's narrow phase. Returns the number of snapshots."""
    from grainview.formats.peers import convert_peer

    with np.load(sample_npz) as data:
        sample = {k: data[k] for k in data.files}
    radius, n_vertices = sample["radius"], sample["n_vertices"]
    run_attrs = {"scene": "biaxial", "sigma0_Pa": float(sample["sigma0"]), "friction": float(sample["friction"]),
                 "wall_friction": float(sample["wall_friction"])}
    run_attrs.update(attrs or {})
    return convert_peer(out_path, raw_dir, sample_npz, attrs=run_attrs, overwrite=True, compress=False,
                        extra=lambda raw: {"max_interpenetration": largest_overlap(raw, radius, n_vertices)})
