"""Snapshots as VTK files, for ParaView and OVITO.

Written as VTK's XML PolyData (:mod:`grainview.export.vtk_xml`), per snapshot k:

* ``particles_<k>.vtp``: every particle as a point at its centre (one vertex cell each), with
  point data ``id`` (the particle's index, as ``i`` and ``j`` of the contacts), ``radius`` (m;
  the circumscribed radius of a polygon), ``n_vertices`` (0 for a disk), ``angle`` (rad),
  ``v`` (velocity, m s-1, z = 0; when the file has it) and the per-particle fields of
  :func:`grainview.analysis.particle_fields.particle_fields` (``c``, ``m_s``, ``m_d``, ``strong``,
  ``rattler``, ``rotation`` rad, ``displacement`` m);
* ``contacts_<k>.vtp``: every particle–particle contact as a line from the centre of i along
  its branch vector to the centre of j, with cell data ``id1``, ``id2`` (i, j), ``fn``, ``ft``
  (N), ``kind`` (1 simple, 2 double) and ``force_class`` (0 a pair without force, 1 very
  weak, 2 weak, 3 strong; paper Fig. 17); no file, and an empty block, for a snapshot without
  particle–particle contact (OVITO 3.17 stops on a contacts file without lines);
* ``wall_contacts_<k>.vtp``: every particle–wall contact as a line from the centre of i to its
  contact point on the wall, with cell data ``particle_id`` (i), ``wall_id`` (j - N, the wall's
  index), ``fn``, ``ft``, ``kind``, ``force_class``;
* ``snapshot_<k>.vtm``: the three as the named blocks of one multi-block dataset;
* ``polygons_<k>.vtp`` (files with polygons): every polygon's outline as a polygon cell, its
  vertices by the contract's definition (:mod:`grainview.contract.shapes`), with the
  particles' data as cell data; not a block of the ``.vtm``: OVITO 3.17 renders such a flat
  mesh blank, and its Tachyon renderer stopped (segmentation fault) on such a mesh of a few
  polygons;

In a periodic cell (a file with ``cell``) the particles are written wrapped into the cell
(whatever the file's ``cell_positions``), each contact as one line from the wrapped centre of i
along its minimum-image branch (a contact across the boundary sticks out of the cell by at
most its branch, to the image of j, never a line across the box; one line per contact, so sums
over the lines and OVITO's bond list count it once), and ``cell_<k>.vtp`` holds the cell's
outline, the parallelogram origin, origin + a, origin + a + b, origin + b, as one closed line
with cell data ``periodic_a``, ``periodic_b``; not a block of the ``.vtm`` (the blocks of a
file without a cell stay as they were);

then ``snapshots.pvd`` and ``polygons.pvd``, the ParaView collections that put the ``.vtm``
and the polygons' files on the time axis. The names ``id``, ``radius``, ``v``, ``id1``/``id2``,
``particle_id``/``wall_id`` and the one-vertex-per-point, two-points-per-line layout are those
OVITO's readers of ParaView files (written for the DEM code Aspherix) take as particles, their
identifiers, radii and velocities, and particle–particle and particle–wall contacts; VTK and
ParaView read every array under its name.

Files are written to a temporary name and moved into place, so that an interrupted export
never leaves a half-written file under the final name; existing files are not overwritten
unless ``overwrite``.
"""

from __future__ import annotations

import os

import numpy as np
import xarray as xr

from ..analysis.snapshots import snapshot_indices
from ..contract.cell import wrap
from ..contract.errors import ParameterError
from ..contract.shapes import body_vertices_of, world_vertices
from ..contract.writer import write_atomically
from ._docs import fill_doc
from .vtk_xml import collection, multiblock, polydata, write_xml

__all__ = ["write_vtk", "VTK_BLOCKS"]


VTK_BLOCKS = ("particles", "contacts", "wall_contacts")
"""The blocks of each snapshot's ``.vtm`` file, in order, each the stem of its ``.vtp`` file."""


def _centres(snap: xr.Dataset) -> np.ndarray:
    """The centres (P, 2) written: as stored, or wrapped into a periodic cell."""
    position = np.asarray(snap["position"].values, float)
    if "cell" not in snap.variables:
        return position
    periodic = np.asarray(snap["periodic"].values, bool)
    home = wrap(np.nan_to_num(position), np.asarray(snap["box_min"].values, float),
                np.asarray(snap["cell"].values, float), periodic)
    return np.where(np.isfinite(position), home, position)


def _cell_outline(snap: xr.Dataset):
    """The periodic cell's outline: its four corners, closed (5 points), one polyline."""
    cell, origin = np.asarray(snap["cell"].values, float), np.asarray(snap["box_min"].values, float)
    corners = origin + np.array([[0.0, 0.0], cell[0], cell[0] + cell[1], cell[1], [0.0, 0.0]])
    periodic = np.asarray(snap["periodic"].values, np.int64)
    return polydata(corners, lines=np.array([5]), cell_data={"periodic_a": periodic[:1], "periodic_b": periodic[1:]})


def _particle_data(snap: xr.Dataset, fields: xr.Dataset) -> dict:
    """Per-particle arrays by name: id, radius, n_vertices, angle, v (when present), the fields."""
    n = snap.sizes["particle"]
    data = {"id": np.arange(n), "radius": np.asarray(snap["radius"].values, float),
            "n_vertices": np.asarray(snap["n_vertices"].values, np.int64),
            "angle": np.asarray(snap["angle"].values, float)}
    if "velocity" in snap:
        data["v"] = np.column_stack([np.asarray(snap["velocity"].values, float), np.zeros(n)])
    for name in fields.data_vars:
        values = np.asarray(fields[name].values)
        data[name] = values.astype(float if values.dtype.kind == "f" else np.int64)
    return data


def _polygons(snap: xr.Dataset, data: dict):
    """The polygons' outlines, grouped by vertex count: their vertices (one polygon after the
    other), each polygon's vertex count and its data."""
    position = _centres(snap)
    n_vertices = data["n_vertices"]
    groups = [np.flatnonzero(n_vertices == n) for n in np.unique(n_vertices[n_vertices > 0])]
    world = world_vertices(position, data["angle"], body_vertices_of(snap))
    points = [world[members, :int(n_vertices[members[0]])].reshape(-1, 2) for members in groups]
    order = np.concatenate(groups) if groups else np.arange(0)
    return (np.concatenate(points) if points else np.zeros((0, 2)), n_vertices[order],
            {name: values[order] for name, values in data.items()})


def _contact_lines(snap: xr.Dataset, classes: np.ndarray, walls: bool):
    """Line end points (centre of i, then centre of i + branch) and cell data of the occupied
    slots whose j is a wall (``walls``) or a particle."""
    n = snap.sizes["particle"]
    kind = np.asarray(snap["kind"].values)
    j = np.asarray(snap["j"].values).astype(np.int64)
    used = np.flatnonzero((kind > 0) & ((j >= n) if walls else (j < n)))
    i = np.asarray(snap["i"].values)[used].astype(np.int64)
    start = _centres(snap)[i]
    points = np.empty((2 * used.size, 2))
    points[0::2], points[1::2] = start, start + np.asarray(snap["branch"].values, float)[used]
    ids = {"particle_id": i, "wall_id": j[used] - n} if walls else {"id1": i, "id2": j[used]}
    data = dict(ids, fn=np.asarray(snap["fn"].values, float)[used], ft=np.asarray(snap["ft"].values, float)[used],
                kind=kind[used].astype(np.int64), force_class=classes[used].astype(np.int64))
    return points, data


def _snapshot_files(snap: xr.Dataset, fields: xr.Dataset, classes: np.ndarray, polygons: bool) -> dict:
    """The PolyData trees of one snapshot by block name (:data:`VTK_BLOCKS`, then "polygons"
    when ``polygons``); None for the contacts of a snapshot without particle-particle contact
    (no file: OVITO stops on a contacts file without lines)."""
    data = _particle_data(snap, fields)
    trees = {"particles": polydata(_centres(snap), verts=True, point_data=data)}
    for block, walls in (("contacts", False), ("wall_contacts", True)):
        points, cell_data = _contact_lines(snap, classes, walls)
        empty = len(points) == 0 and not walls
        trees[block] = None if empty else polydata(points, lines=np.full(len(points) // 2, 2), cell_data=cell_data)
    if polygons:
        points, sizes, cell_data = _polygons(snap, data)
        trees["polygons"] = polydata(points, polys=sizes, cell_data=cell_data)
    if "cell" in snap.variables:
        trees["cell"] = _cell_outline(snap)
    return trees


@fill_doc
def write_vtk(ds: xr.Dataset, out_dir, every: int = 1, overwrite: bool = False, progress=None) -> list:
    """Write the VTK files of the module docstring for every ``every``-th snapshot into ``out_dir``.

    For ParaView and OVITO (open ``snapshots.pvd``: every snapshot on the time axis, or one
    ``snapshot_<k>.vtm``; in ParaView also ``polygons.pvd``); ``out_dir`` is created if
    needed. Per snapshot k, ``particles_<k>.vtp``, ``contacts_<k>.vtp``,
    ``wall_contacts_<k>.vtp``, ``polygons_<k>.vtp`` (files with polygons), ``cell_<k>.vtp``
    (files with a periodic cell: its outline; the particles wrapped into it) and
    ``snapshot_<k>.vtm``, then ``snapshots.pvd`` and ``polygons.pvd`` (files with polygons).

    Parameters
    ----------
    {written}
    overwrite : bool, default False
        Replace files that exist; otherwise an existing file is refused before anything is
        written.
    progress : bool, optional
        Show a progress bar (default: none).

    Returns
    -------
    list of str
        The paths written, snapshot by snapshot in the order above, the collections last.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When a file to write exists and ``overwrite`` is False.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Fig. 17 and Secs. V.B-V.C (the force classes of the contacts); docs/conventions.md §4.
    """
    from ..analysis.force_networks import force_class
    from ..analysis.particle_fields import particle_fields

    indices = snapshot_indices(ds, every)
    polygons = bool((np.asarray(ds["n_vertices"].values) > 0).any())
    stems = list(VTK_BLOCKS) + ["polygons"] * polygons + ["cell"] * ("cell" in ds.variables)
    collections = ["snapshots"] + ["polygons"] * polygons
    targets = [os.path.join(out_dir, name) for k in indices
               for name in [f"{stem}_{int(k):05d}.vtp" for stem in stems] + [f"snapshot_{int(k):05d}.vtm"]]
    targets += [os.path.join(out_dir, f"{name}.pvd") for name in collections]
    existing = [t for t in targets if os.path.exists(t)]
    if existing and not overwrite:  # before anything is written
        raise ParameterError(f"{existing[0]} exists ({len(existing)} of the {len(targets)} files to write); "
                             "pass overwrite=True to replace them")
    os.makedirs(out_dir, exist_ok=True)
    fields = particle_fields(ds, walls=True)
    classes = force_class(ds, walls=True)
    written, entries = [], {name: [] for name in collections}
    iterator = indices
    if progress:
        from tqdm.auto import tqdm

        iterator = tqdm(indices, desc="VTK export", unit="snapshot")
    for k in iterator:
        k = int(k)
        snap = ds.isel(time=k).compute()
        trees = _snapshot_files(snap, fields.isel(time=k).compute(), np.asarray(classes.isel(time=k).values), polygons)
        files = {stem: None if tree is None else f"{stem}_{k:05d}.vtp" for stem, tree in trees.items()}
        blocks = multiblock((block, files[block]) for block in VTK_BLOCKS)
        trees[f"snapshot_{k:05d}"], files[f"snapshot_{k:05d}"] = blocks, f"snapshot_{k:05d}.vtm"
        for stem, tree in trees.items():
            if tree is None:  # no file; one left by an earlier export is not this snapshot's
                stale = os.path.join(out_dir, f"{stem}_{k:05d}.vtp")
                if os.path.exists(stale):
                    os.remove(stale)
                continue
            path = os.path.join(out_dir, files[stem])
            write_atomically(path, overwrite, lambda temporary, tree=tree: write_xml(tree, temporary))
            written.append(path)
        time = float(snap["time"].values)
        entries["snapshots"].append((time, files[f"snapshot_{k:05d}"]))
        if polygons:
            entries["polygons"].append((time, files["polygons"]))
    for name in collections:
        path = os.path.join(out_dir, f"{name}.pvd")
        write_atomically(path, overwrite, lambda temporary, name=name: write_xml(collection(entries[name]), temporary))
        written.append(path)
    return written
