"""Export snapshots to the formats other tools read: VTK (ParaView, OVITO) and CSV (pandas,
spreadsheets).

VTK, one pair of files per snapshot k, written by meshio (the well-kept VTK writer), and two
ParaView collections (``.pvd``) that put them on the time axis:

* ``particles_<k>.vtu``: every polygon as a polygon cell (its vertices by the contract's
  definition, :func:`grainview.schema.polygon_vertices`), every disk as a vertex cell at its
  centre with its ``radius`` (ParaView: Glyph by radius); cell fields ``particle`` (index),
  ``radius`` (m), ``n_vertices``, ``velocity`` (m s-1, when the file has it) and the
  per-particle fields of :func:`grainview.particle_fields.particle_fields` (c, m_s, m_d,
  strong, rattler, rotation rad, displacement m);
* ``contacts_<k>.vtu``: every contact as a line from the centre of i along its branch vector
  (to the centre of j, or to the contact point on a wall); cell fields ``fn``, ``ft`` (N),
  ``kind`` (1 simple, 2 double), ``force_class`` (0 a pair without force, 1 very weak, 2 weak,
  3 strong; paper Fig. 17) and the bodies ``i``, ``j`` (walls are N, N+1, ...).

CSV: ``contacts.csv``, the tidy contact table of every exported snapshot
(:func:`grainview.tables.contacts_table`), one row per occupied contact slot, its columns
named with their units (:data:`CSV_COLUMNS`, docs/analysis.md "Exports"): ``snapshot``,
``time_s``, ``i``, ``j``, ``kind`` ("simple" or "double"), ``wall``, ``loaded`` (f_n > 0:
the force-bearing contacts; False for the pairs without force, such as the near pairs of a
file written with them), ``fn_N``, ``ft_N``, ``normal_x``, ``normal_y``, ``point_x_m``,
``point_y_m``, ``branch_x_m``, ``branch_y_m`` and ``gap_m`` (when the file has gaps).

Files are written to a temporary name and moved into place, so that an interrupted export
never leaves a half-written file under the final name; existing files are not overwritten
unless ``overwrite``.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree

import numpy as np
import xarray as xr

from .errors import ParameterError
from .schema import polygon_vertices

__all__ = ["write_vtk", "write_csv", "snapshot_indices", "write_atomically", "CSV_COLUMNS"]

CSV_COLUMNS = {
    "snapshot": "index of the snapshot along time",
    "time_s": "time of the snapshot (s)",
    "i": "first body (particle index)",
    "j": "second body (particle index, or N + wall index for a wall)",
    "kind": "simple (one contact point) or double (two points: an edge facing an edge)",
    "wall": "True when j is a wall",
    "loaded": "True when f_n > 0 (the force-bearing network); False for a pair without force, e.g. a near pair",
    "fn_N": "normal force exerted by i on j, compression > 0 (N)",
    "ft_N": "tangential force exerted by i on j along t = (-n_y, n_x) (N)",
    "normal_x": "unit contact normal from i to j, x component",
    "normal_y": "unit contact normal from i to j, y component",
    "point_x_m": "application point of the contact force, x (m)",
    "point_y_m": "application point of the contact force, y (m)",
    "branch_x_m": "branch vector, centre of i to centre of j (to the contact point for walls), x (m)",
    "branch_y_m": "branch vector, y (m)",
    "gap_m": "smallest separation of the contact's points along the normal, negative: overlap (m; files with gaps)",
}
"""The columns of ``contacts.csv``, in order, and what each holds (units in the names)."""
KIND_NAMES = {1: "simple", 2: "double"}
"""The contract's contact kinds as the CSV writes them."""


def snapshot_indices(ds: xr.Dataset, every: int = 1) -> np.ndarray:
    """Indices 0, every, 2 every, ... of the snapshots to export (and always the last).

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    every : int, default 1
        The step between exported snapshots (>= 1).

    Returns
    -------
    numpy.ndarray
        Increasing snapshot indices, the last snapshot included (empty for no snapshot).

    Raises
    ------
    grainview.errors.ParameterError
        When ``every`` is not an integer >= 1.
    """
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1:
        raise ParameterError(f"every={every!r}: expected an integer >= 1")
    n = ds.sizes["time"]
    return np.unique(np.append(np.arange(0, n, every), n - 1)) if n else np.arange(0)


def write_atomically(path, overwrite, write):
    """Write ``path`` through ``write(temporary path)`` and move it into place.

    An interrupted write never leaves a half-written file under the final name; an existing
    ``path`` is refused unless ``overwrite``.

    Parameters
    ----------
    path : str
        The final file name.
    overwrite : bool
        Replace an existing ``path``.
    write : callable
        Called with the temporary path (``<root>.part<ext>`` beside ``path``); writes the file.

    Returns
    -------
    None

    Raises
    ------
    grainview.errors.ParameterError
        When ``path`` exists and ``overwrite`` is False.
    """
    if os.path.exists(path) and not overwrite:
        raise ParameterError(f"{path} exists; pass overwrite=True to replace it")
    root, ext = os.path.splitext(path)
    temporary = f"{root}.part{ext}"
    write(temporary)
    os.replace(temporary, path)


def _particles_mesh(snap: xr.Dataset, fields: xr.Dataset):
    import meshio

    position = np.asarray(snap["position"].values, float)
    angle = np.asarray(snap["angle"].values, float)
    radius = np.asarray(snap["radius"].values, float)
    n_vertices = np.asarray(snap["n_vertices"].values, int)
    points, cells, order = [], [], []
    start = 0
    disks = np.flatnonzero(n_vertices == 0)
    if disks.size:
        points.append(position[disks])
        cells.append(meshio.CellBlock("vertex", (start + np.arange(disks.size))[:, None]))
        order.append(disks)
        start += disks.size
    for n in np.unique(n_vertices[n_vertices > 0]):
        members = np.flatnonzero(n_vertices == n)
        vertices = polygon_vertices(position[members], radius[members], angle[members], int(n))
        points.append(vertices.reshape(-1, 2))
        cells.append(meshio.CellBlock("polygon", start + np.arange(members.size * n).reshape(members.size, n)))
        order.append(members)
        start += members.size * n
    data = {"particle": np.arange(radius.size), "radius": radius, "n_vertices": n_vertices}
    if "velocity" in snap:
        data["velocity"] = np.column_stack([np.asarray(snap["velocity"].values, float), np.zeros(radius.size)])
    for name in fields.data_vars:
        data[name] = np.asarray(fields[name].values).astype(float if fields[name].dtype.kind == "f" else np.int64)
    cell_data = {name: [values[members] for members in order] for name, values in data.items()}
    xyz = np.column_stack([np.concatenate(points), np.zeros(start)]) if points else np.zeros((0, 3))
    return meshio.Mesh(xyz, cells, cell_data=cell_data)


def _contacts_mesh(snap: xr.Dataset, classes: np.ndarray):
    import meshio

    used = np.flatnonzero(np.asarray(snap["kind"].values) > 0)
    i = np.asarray(snap["i"].values)[used].astype(np.int64)
    start = np.asarray(snap["position"].values, float)[i]
    end = start + np.asarray(snap["branch"].values, float)[used]
    xyz = np.zeros((2 * used.size, 3))
    xyz[0::2, :2], xyz[1::2, :2] = start, end
    cells = [meshio.CellBlock("line", np.arange(2 * used.size).reshape(-1, 2))]
    cell_data = {"fn": [np.asarray(snap["fn"].values, float)[used]], "ft": [np.asarray(snap["ft"].values, float)[used]],
                 "kind": [np.asarray(snap["kind"].values).astype(np.int64)[used]],
                 "force_class": [classes[used].astype(np.int64)],
                 "i": [i], "j": [np.asarray(snap["j"].values)[used].astype(np.int64)]}
    return meshio.Mesh(xyz, cells, cell_data=cell_data)


def _collection(path, entries, overwrite):
    """A ParaView ``.pvd`` collection of (time, file name) entries (ElementTree)."""
    root = ElementTree.Element("VTKFile", type="Collection", version="0.1")
    collection = ElementTree.SubElement(root, "Collection")
    for time, name in entries:
        ElementTree.SubElement(collection, "DataSet", timestep=repr(float(time)), group="", part="0", file=name)
    write_atomically(path, overwrite, lambda temporary: ElementTree.ElementTree(root).write(temporary, xml_declaration=True))


def write_vtk(ds: xr.Dataset, out_dir, every: int = 1, overwrite: bool = False, progress=None) -> list:
    """Write the VTK files of the module docstring for every ``every``-th snapshot into ``out_dir``.

    For ParaView or OVITO; ``out_dir`` is created if needed. Per snapshot k,
    ``particles_<k>.vtu`` and ``contacts_<k>.vtu``, then the collections ``particles.pvd`` and
    ``contacts.pvd``.

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    out_dir : str or path-like
        Output folder, created if needed.
    every : int, default 1
        Write every ``every``-th snapshot (the last always included).
    overwrite : bool, default False
        Replace files that exist; otherwise an existing file is refused before anything is
        written.
    progress : bool, optional
        Show a progress bar (default: none).

    Returns
    -------
    list of str
        The paths written, the two ``.pvd`` collections (particles, contacts) last.

    Raises
    ------
    grainview.errors.ParameterError
        When meshio is not installed, or a file to write exists and ``overwrite`` is False.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Fig. 17 and Secs. V.B-V.C (the force classes of the contacts); docs/conventions.md §4.
    """
    try:
        import meshio
    except ImportError:
        raise ParameterError("VTK export needs meshio (pip install meshio)") from None
    from .force_networks import force_class
    from .particle_fields import particle_fields

    indices = snapshot_indices(ds, every)
    targets = [os.path.join(out_dir, f"{stem}_{int(k):05d}.vtu") for k in indices for stem in ("particles", "contacts")]
    targets += [os.path.join(out_dir, f"{stem}.pvd") for stem in ("particles", "contacts")]
    existing = [t for t in targets if os.path.exists(t)]
    if existing and not overwrite:  # before anything is written
        raise ParameterError(f"{existing[0]} exists ({len(existing)} of the {len(targets)} files to write); "
                             "pass overwrite=True to replace them")
    os.makedirs(out_dir, exist_ok=True)
    fields = particle_fields(ds, walls=True)
    classes = force_class(ds, walls=True)
    written, particles, contacts = [], [], []
    iterator = indices
    if progress:
        from tqdm.auto import tqdm

        iterator = tqdm(indices, desc="VTK export", unit="snapshot")
    for k in iterator:
        snap = ds.isel(time=int(k)).compute()
        time = float(snap["time"].values)
        for stem, mesh, entries in (
                ("particles", _particles_mesh(snap, fields.isel(time=int(k)).compute()), particles),
                ("contacts", _contacts_mesh(snap, np.asarray(classes.isel(time=int(k)).values)), contacts)):
            name = f"{stem}_{int(k):05d}.vtu"
            path = os.path.join(out_dir, name)
            write_atomically(path, overwrite, lambda temporary, mesh=mesh: meshio.write(temporary, mesh, file_format="vtu"))
            written.append(path)
            entries.append((time, name))
    for stem, entries in (("particles", particles), ("contacts", contacts)):
        path = os.path.join(out_dir, f"{stem}.pvd")
        _collection(path, entries, overwrite)
        written.append(path)
    return written


_CSV_NAMES = {"time": "time_s", "fn": "fn_N", "ft": "ft_N", "point_x": "point_x_m", "point_y": "point_y_m",
              "branch_x": "branch_x_m", "branch_y": "branch_y_m", "gap": "gap_m"}


def write_csv(ds: xr.Dataset, out_dir, every: int = 1, overwrite: bool = False) -> str:
    """Write ``contacts.csv``: the tidy contact table of every ``every``-th snapshot.

    The table is :func:`grainview.tables.contacts_table`'s, with columns ``snapshot`` and
    ``time_s`` first, the units in the column names, ``kind`` as "simple" or "double" and a
    column ``loaded`` (f_n > 0) that tells the force-bearing contacts from the pairs without
    force (:data:`CSV_COLUMNS`).

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    out_dir : str or path-like
        Output folder, created if needed.
    every : int, default 1
        Write every ``every``-th snapshot (the last always included).
    overwrite : bool, default False
        Replace an existing ``contacts.csv``.

    Returns
    -------
    str
        The path of ``contacts.csv``.

    Raises
    ------
    grainview.errors.ParameterError
        When ``contacts.csv`` exists and ``overwrite`` is False.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eqs. 1-2 and Sec. II.A (the contact frame, simple and double contacts);
    docs/conventions.md §0.
    """
    import pandas as pd

    from .tables import contacts_table

    os.makedirs(out_dir, exist_ok=True)
    frames = []
    for k in snapshot_indices(ds, every):
        table = contacts_table(ds, time=int(k))
        table.insert(0, "time", table.attrs["time"])
        table.insert(0, "snapshot", int(k))
        table.insert(table.columns.get_loc("fn"), "loaded", table["fn"] > 0)
        table["kind"] = table["kind"].map(lambda code: KIND_NAMES.get(int(code), str(int(code))))
        frames.append(table.rename(columns=_CSV_NAMES))
    path = os.path.join(out_dir, "contacts.csv")
    out = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=[
        c for c in CSV_COLUMNS if c != "gap_m" or "gap" in ds])
    write_atomically(path, overwrite, lambda temporary: out.to_csv(temporary, index=False))
    return path
