"""Photoelastic experiments solved by PeGS2 (adjacency lists) as datasets of the grainview contract.

PeGS2 (MATLAB; the photoelastic grain solver of Kollmer, Daniels and others) fits each disk's
fringe pattern with contact forces and writes, per frame, an **adjacency list** (its module
``adjacencyMatrix``: ``*_Adjacency.txt``, and all frames in ``Adjacency_list.txt``), one
comma-separated row ``frame, id1, id2, tangential force, normal force`` per contact *as fitted on
particle id1* (``id2 = -1``: a wall). The disks come from its ``particleDetect`` module
(``*_centers.txt``: ``x, y, r, edge`` in pixels, one file per frame, the particle id being the row
number) or from ``particleTrack`` (``particle_positions.txt``: ``frame, id, x, y, r, edge``). The
``edge`` flag says which side of the image a disk touches: ``1`` right, ``-1`` left, ``2`` the
image's bottom (image rows grow downward), ``-2`` its top.

How the contract's quantities are made (docs/formats.md states the same for users):

* **Units.** Positions are in pixels and forces in PeGS2's force unit (newtons when its
  ``fsigma`` and ``metersperpixel`` are calibrated). The reader does not guess either:
  ``metres_per_pixel`` (PeGS2's ``metersperpixel``) and ``force_unit_n`` (the newtons in one
  force unit of the file, 1 for a calibrated solve) are required.
* **Axes.** Image rows grow downward; the contract's y grows upward: ``x = x_px s``, ``y =
  (y_0 - y_px) s`` with ``s`` the scale and ``y_0`` the lowest disk edge of all frames (so every
  disk lies at y >= 0).
* **Particles** are the ids in increasing order; every frame must hold the same ids. A disk's
  radius is the median of its detected radii over the frames. Mass and inertia are not
  measured: ``mass = density pi r^2 thickness`` and ``inertia = m r^2 / 2`` from the given
  ``density_kg_m3`` and ``thickness_m`` (recorded in the attributes).
* **Forces.** PeGS2 measures a contact's angles on the disk it fits, with image angles (``beta``
  the contact's direction, ``alpha`` the force's angle from the normal, opposite in sense to
  ``beta``, as its ``forceBalance`` writes the balance); its normal force ``N = f cos(alpha)``
  pushes on the disk and its tangential force ``T = f sin(alpha)``. In the contract's axes this
  is, for a contact of bodies ``i < j`` with ``normal`` from i to j and ``t = (-n_y, n_x)``:
  ``fn = N``, ``ft = T``, whichever disk the row was fitted on. A pair fitted on both disks
  (two rows) gets the mean of the two estimates, as PeGS's own post-processing averaged them;
  a pair fitted on one disk keeps its one estimate. Pairs whose (mean) normal force is not
  compressive are left out and counted in a warning.
* **Walls**: the four walls ``bottom, right, top, left`` (bodies ``N`` .. ``N + 3``). A row
  ``id2 = -1`` is a contact with the wall the disk's ``edge`` flag names; its normal points
  from the disk to that wall, its point is the disk's edge there (``x_i + r n``), its branch
  ``r n``. ``wall_force`` is the total force of the particles on each wall. PeGS2 writes all
  walls as ``-1`` and one wall contact per disk (a corner disk's second wall is lost there).
* ``point = x_i + r_i n`` for a pair, ``branch = x_j - x_i``; ``kind = 1``; ``time = frame x
  frame_interval_s``; the box is the bounding box of the disks of each frame.

Every function checks its input and refuses bad input in one line
(:class:`grainview.contract.errors.FileFormatError` or :class:`~grainview.contract.errors.ParameterError`).

A value that is not finite or is absurd (:mod:`grainview.formats.checks`) and an empty adjacency
list are refused; the frames without a row in the adjacency list are named in one warning.
"""

from __future__ import annotations

import math
import os
import re
import warnings

import numpy as np

from ..contract.errors import FileFormatError, ParameterError
from .checks import Limits, check_contacts, input_file

__all__ = ["pegs_snapshots", "open_pegs", "convert_pegs", "read_adjacency", "read_positions", "WALL_NAMES",
           "EDGE_WALLS"]

WALL_NAMES = ("bottom", "right", "top", "left")
"""The walls of a PeGS2 experiment, in the contract's order (bodies N .. N + 3)."""
ESTIMATES_APART = 10.0
"""How many times apart the two normal forces fitted for one pair (one on each disk) may be
before a note says so: real fits differ by a few times at most; a thousandfold difference is a
failed fit or a unit slip, and their mean is not a measurement."""
EDGE_WALLS = {2: 0, 1: 1, -2: 2, -1: 3}
"""PeGS2's edge flag -> index in :data:`WALL_NAMES` (2: the image's bottom, -2: its top)."""
_WALL_NORMALS = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
"""From a disk to each wall of :data:`WALL_NAMES`, in the contract's axes."""


def _paths(value, what):
    if value is None:
        raise ParameterError(f"{what}: expected a file or a list of files")
    paths = [value] if isinstance(value, (str, os.PathLike)) else list(value)
    if not paths:
        raise ParameterError(f"{what}: an empty list of files")
    return [input_file(path, f"PeGS2's {what}") for path in paths]


def _table(path, columns, what, lines=None):
    """The rows of a comma-separated numeric file, (K, columns); one line on a bad row.
    ``lines``, a list, receives each row's line number."""
    rows, last = [], ""
    with open(path, encoding="utf-8", errors="replace") as handle:
        for number, line in enumerate(handle, start=1):
            if not line.strip():
                continue
            fields = line.replace(",", " ").split()
            try:
                values = [float(v) for v in fields]
            except ValueError:
                raise FileFormatError(f"{path}: line {number}: expected {what}, found {line.strip()[:80]!r}") from None
            if len(values) != columns:
                raise FileFormatError(f"{path}: line {number}: {len(values)} columns, expected {columns} ({what})")
            rows.append(values)
            if lines is not None:
                lines.append(number)
            last = line
    if rows and not last.endswith("\n"):
        raise FileFormatError(f"{path}: truncated: its last line ends without a newline (PeGS2's writematrix ends "
                              "every row with one)")
    return np.array(rows, float).reshape(-1, columns)


def read_adjacency(paths) -> np.ndarray:
    """PeGS2 adjacency lists (``Adjacency_list.txt`` or per-frame ``*_Adjacency.txt``), joined.

    Returns
    -------
    ndarray, (K, 5)
        Rows ``frame, id1, id2, T, N``.

    Raises
    ------
    FileFormatError
        A missing file (or a folder), no row at all (an empty adjacency list), a row without
        its 5 numbers, a frame or id that is not an integer, a non-finite force (naming its
        line).
    """
    tables = []
    paths = _paths(paths, "adjacency list")
    for path in paths:
        lines = []
        table = _table(path, 5, "5 numbers: frame, id1, id2, tangential force, normal force", lines)
        ids = table[:, :3]
        bad = ~np.isfinite(ids).all(axis=1) | (ids != np.round(ids)).any(axis=1) | (table[:, 1] < 1) | (
            (table[:, 2] < 1) & (table[:, 2] != -1)) | (np.abs(ids) > 2**31).any(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise FileFormatError(f"{path}: line {lines[k]}: frame and ids must be integers, id1 >= 1 and id2 >= 1 "
                                  "or -1 (a wall)")
        bad = ~np.isfinite(table[:, 3:]).all(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise FileFormatError(f"{path}: line {lines[k]}: a force that is not a finite number")
        tables.append(table)
    table = np.concatenate(tables)
    if table.shape[0] == 0:
        raise FileFormatError(f"{', '.join(paths)}: no contact at all (an empty adjacency list); expected rows "
                              "frame, id1, id2, tangential force, normal force")
    return table


def _frame_number(path, place):
    digits = re.findall(r"\d+", os.path.basename(path).replace("_centers", ""))
    return int(digits[-1]) if digits else place


def read_positions(paths) -> np.ndarray:
    """PeGS2 particle positions, as rows ``frame, id, x, y, r, edge`` (pixels).

    ``paths`` is ``particle_positions.txt`` of ``particleTrack`` (those six columns), or one or
    more ``*_centers.txt`` of ``particleDetect`` (``x, y, r, edge``; the id is the row number,
    the frame the last group of digits in the file's name, else its place in the list).

    Raises
    ------
    FileFormatError
        A missing file, rows of another width, a particle id twice in a frame, a radius that
        is not > 0, an edge flag other than 0, +-1, +-2.
    """
    paths = _paths(paths, "particle positions")
    tables = []
    for place, path in enumerate(paths, start=1):
        with open(path, encoding="utf-8", errors="replace") as handle:
            first = next((line for line in handle if line.strip()), "")
        width = len(first.replace(",", " ").split())
        lines = []
        if width == 6:
            table = _table(path, 6, "frame, id, x, y, r, edge (particle_positions.txt)", lines)
        elif width == 4:
            table = _table(path, 4, "x, y, r, edge (a *_centers.txt)", lines)
            k = table.shape[0]
            table = np.column_stack([np.full(k, _frame_number(path, place)), np.arange(1, k + 1), table])
        else:
            raise FileFormatError(f"{path}: {width} columns; expected x, y, r, edge (*_centers.txt) or frame, id, x, "
                                  "y, r, edge (particle_positions.txt)")
        if not np.all(table[:, 4] > 0) or not np.all(np.isfinite(table[:, 2:5])):
            raise FileFormatError(f"{path}: radii must be > 0 and positions finite")
        ids = table[:, :2]
        if not (np.isfinite(ids).all() and (ids == np.round(ids)).all() and (np.abs(ids) <= 2**31).all()):
            raise FileFormatError(f"{path}: frame and id must be integers")
        if table.shape[0]:  # in pixels: the bounds are relative to the disks' size
            limits = Limits(table[:, 4], where=path, names=lambda k: f"line {lines[k]}")
            limits.check(table[:, 2:4], ("x", "y"), "position", path, rows=lambda k: f"line {lines[k]}")
        if not np.all(np.isin(table[:, 5], (0, 1, -1, 2, -2))):
            raise FileFormatError(f"{path}: an edge flag other than 0, 1, -1, 2, -2")
        tables.append(table)
    table = np.concatenate(tables)
    key = table[:, 0] * (table[:, 1].max() + 1) + table[:, 1]
    if np.unique(key).size != key.size:
        raise FileFormatError(f"{paths[0]}: a particle id appears twice in a frame")
    return table


def _scale(value, name, unit):
    if value is None:
        raise ParameterError(f"{name} is required: PeGS2 gives positions in pixels and forces in its own unit; give "
                             "metres_per_pixel (PeGS2's metersperpixel; --metres-per-pixel) and force_unit_n (newtons "
                             "per force unit of the file, 1 for a calibrated solve; --force-unit-n)")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}={value!r}: expected a number > 0 ({unit})") from None
    if isinstance(value, bool) or not (math.isfinite(number) and number > 0):
        raise ParameterError(f"{name}={value!r}: expected a number > 0 ({unit})")
    return number


def pegs_snapshots(adjacency, positions, *, metres_per_pixel=None, force_unit_n=None, frame_interval_s=1.0,
                   thickness_m=1.0, density_kg_m3=1000.0):
    """Read a PeGS2 experiment frame by frame, as the contract's per-snapshot arrays.

    Parameters
    ----------
    adjacency : path or list of paths
        ``Adjacency_list.txt`` or per-frame ``*_Adjacency.txt`` files.
    positions : path or list of paths
        ``particle_positions.txt`` (tracked) or per-frame ``*_centers.txt`` files.
    metres_per_pixel : float
        The image scale, m per pixel (required).
    force_unit_n : float
        Newtons per force unit of the adjacency list (required; 1 when PeGS2's ``fsigma`` is
        calibrated in N).
    frame_interval_s : float, default 1
        Time between frames, s (``time = frame x frame_interval_s``).
    thickness_m, density_kg_m3 : float
        The disks' thickness (m; the slab's ``thickness_m``) and density (kg/m^3), for the
        masses, which the images do not give.

    Returns
    -------
    (static, iterator)
        As the other readers (:func:`grainview.formats.lammps.lammps_snapshots`); each
        snapshot also gives ``tensile`` (the contacts left out) and ``apart`` (the pairs whose
        two estimates of the normal force differ more than :data:`ESTIMATES_APART`-fold).

    Raises
    ------
    FileFormatError, ParameterError
        One line: a missing scale, a missing or malformed file, frames of the adjacency list
        that the positions do not have, ids unknown in a frame, frames with other ids, a wall
        contact of a disk not at an edge.
    """
    scale = _scale(metres_per_pixel, "metres_per_pixel", "m per pixel")
    force_scale = _scale(force_unit_n, "force_unit_n", "N per force unit")
    interval = _scale(frame_interval_s, "frame_interval_s", "s")
    thickness = _scale(thickness_m, "thickness_m", "m")
    density = _scale(density_kg_m3, "density_kg_m3", "kg/m^3")
    adjacency_paths, position_paths = _paths(adjacency, "adjacency list"), _paths(positions, "particle positions")
    adj = read_adjacency(adjacency_paths)
    pos = read_positions(position_paths)
    frames = np.unique(pos[:, 0]).astype(np.int64)
    missing = np.setdiff1d(np.unique(adj[:, 0]).astype(np.int64), frames)
    if missing.size:
        raise FileFormatError(f"mismatched frames: {adjacency_paths[0]} has frame {missing[0]}, which "
                              f"{position_paths[0]} does not have (frames {frames.min()}..{frames.max()})")
    ids = np.unique(pos[pos[:, 0] == frames[0], 1]).astype(np.int64)
    for frame in frames[1:]:
        here = np.unique(pos[pos[:, 0] == frame, 1]).astype(np.int64)
        if here.size != ids.size or np.any(here != ids):
            raise FileFormatError(f"{position_paths[0]}: frame {frame} holds other particles than frame {frames[0]} "
                                  f"({here.size} against {ids.size}); the contract needs the same particles in every "
                                  "frame (track them with PeGS2's particleTrack)")
    n = ids.size
    index = {int(v): k for k, v in enumerate(ids)}
    radius_px = np.zeros(n)
    for k, v in enumerate(ids):
        radius_px[k] = np.median(pos[pos[:, 1] == v, 4])
    y0 = float((pos[:, 3] + pos[:, 4]).max())
    inner = adj[adj[:, 2] > 0]
    low, high = np.minimum(inner[:, 1], inner[:, 2]), np.maximum(inner[:, 1], inner[:, 2])
    pair_key = np.column_stack([inner[:, 0], low, high])
    _, fits = np.unique(pair_key, axis=0, return_counts=True)
    radius = radius_px * scale
    mass = density * math.pi * radius**2 * thickness
    attrs = {"source": "PeGS2", "pegs_adjacency": ", ".join(os.path.basename(p) for p in adjacency_paths),
             "pegs_positions": ", ".join(os.path.basename(p) for p in position_paths),
             "pegs_metres_per_pixel": scale, "pegs_force_unit_n": force_scale, "pegs_frame_interval_s": interval,
             "thickness_m": thickness,
             "pegs_mass": f"not measured: {density:g} kg/m^3 x pi r^2 x thickness, inertia m r^2 / 2",
             "pegs_axes": f"x = x_px s, y = ({y0:g} - y_px) s (image rows grow downward), s = {scale:g} m/px",
             "pegs_contact_rule": "compressive pairs; a pair fitted on both disks gets the mean of the two estimates",
             "pegs_pairs": f"{int((fits == 2).sum())} particle pairs fitted on both disks, {int((fits == 1).sum())} on "
                           "one"}
    static = dict(radius=radius, mass=mass, inertia=0.5 * mass * radius**2, n_walls=len(WALL_NAMES),
                  wall_names=list(WALL_NAMES), wall_normal=-_WALL_NORMALS, attrs=attrs,
                  ids=ids, empty_explained=set(np.flatnonzero(~np.isin(frames, adj[:, 0].astype(np.int64))).tolist()))
    limits = Limits(radius, thickness, position_paths[0], mass=mass, names=lambda k: f"particle id {ids[k]}")
    limits.check(adj[:, 3:5], ("tangential force", "normal force"), "force", adjacency_paths[0], scale=force_scale,
                 rows=lambda k: f"frame {int(adj[k, 0])}, ids {int(adj[k, 1])} and {int(adj[k, 2])}")
    limits.check([[frames.min() * interval], [frames.max() * interval]], "time", "time", position_paths[0],
                 rows=lambda k: f"frame {(frames.min(), frames.max())[k]} (frame_interval_s = {interval:g})")
    silent = np.setdiff1d(frames, adj[:, 0].astype(np.int64))
    if silent.size:
        warnings.warn(f"{silent.size} frame(s) of {position_paths[0]} ({_listed(silent)}) have no row in "
                      f"{adjacency_paths[0]} and are written without contacts", UserWarning, stacklevel=2)

    def snapshots():
        for frame in frames:
            rows = pos[pos[:, 0] == frame]
            order = np.array([index[int(v)] for v in rows[:, 1]])
            px = np.zeros((n, 2))
            edge = np.zeros(n, np.int64)
            px[order] = rows[:, 2:4]
            edge[order] = rows[:, 5].astype(np.int64)
            position = np.column_stack([px[:, 0] * scale, (y0 - px[:, 1]) * scale])
            r_frame = np.zeros(n)
            r_frame[order] = rows[:, 4] * scale
            where = f"{adjacency_paths[0]}: frame {frame}"
            contacts, wall_force, tensile, apart = _frame_contacts(adj[adj[:, 0] == frame], index, position, radius,
                                                                   edge, force_scale, where)
            check_contacts(limits, position, contacts, where,
                           lambda k: f"id {ids[k]}" if k < n else f"the {WALL_NAMES[k - n]} wall")
            yield dict(time=float(frame) * interval, position=position, angle=np.zeros(n), contacts=contacts,
                       box_min=(position - r_frame[:, None]).min(axis=0),
                       box_max=(position + r_frame[:, None]).max(axis=0), wall_force=wall_force, tensile=tensile,
                       apart=apart)

    return static, snapshots()


def _listed(frames, most=5) -> str:
    """``frame 3, 7`` or ``frames 1, 2, 3, 4, 5, ...``."""
    shown = ", ".join(str(int(f)) for f in frames[:most]) + (", ..." if len(frames) > most else "")
    return f"frame{'s' if len(frames) > 1 else ''} {shown}"


def _frame_contacts(rows, index, position, radius, edge, force_scale, where):
    """Contract contacts of one frame's adjacency rows, the force on each wall and the number of
    contacts left out for a normal force that is not compressive."""
    n = position.shape[0]
    try:
        first = np.array([index[int(v)] for v in rows[:, 1]], np.int64)
        second = np.array([index[int(v)] if v > 0 else -1 for v in rows[:, 2]], np.int64)
    except KeyError as exc:
        raise FileFormatError(f"{where}: particle id {exc.args[0]} is not among the frame's particles") from None
    wall_rows = second < 0
    if np.any(~wall_rows & (first == second)):
        raise FileFormatError(f"{where}: a contact of a particle with itself")
    pairs = {}
    for a, b, T, N in zip(first[~wall_rows], second[~wall_rows], rows[~wall_rows, 3], rows[~wall_rows, 4]):
        key = (min(a, b), max(a, b))
        fitted = pairs.setdefault(key, {})
        if a in fitted:
            raise FileFormatError(f"{where}: the pair of particles {key[0]}-{key[1]} (indices) appears twice from the "
                                  "same disk")
        fitted[a] = (N, T)
    out = {k: [] for k in ("i", "j", "normal", "fn", "ft", "point", "branch")}
    tensile, apart = 0, []
    for (i, j), fitted in pairs.items():
        if len(fitted) == 2:
            on_i, on_j = fitted[i][0], fitted[j][0]
            if min(on_i, on_j) > 0 and max(on_i, on_j) > ESTIMATES_APART * min(on_i, on_j):
                apart.append((i, j, on_i, on_j))
        N, T = np.mean(list(fitted.values()), axis=0)
        if not N > 0:
            tensile += 1
            continue
        branch = position[j] - position[i]
        if not np.hypot(*branch) > 0:
            raise FileFormatError(f"{where}: a contact of two particles at one centre (indices {i} and {j}); expected "
                                  "disks apart")
        normal = branch / np.hypot(*branch)
        out["i"].append(i)
        out["j"].append(j)
        out["normal"].append(normal)
        out["fn"].append(N * force_scale)
        out["ft"].append(T * force_scale)
        out["point"].append(position[i] + radius[i] * normal)
        out["branch"].append(branch)
    wall_force = np.zeros((len(WALL_NAMES), 2))
    seen = set()
    for a, T, N in zip(first[wall_rows], rows[wall_rows, 3], rows[wall_rows, 4]):
        if edge[a] == 0:
            raise FileFormatError(f"{where}: a wall contact (id2 = -1) of particle {a} (index), which is not at an "
                                  "edge (edge flag 0)")
        if a in seen:
            raise FileFormatError(f"{where}: two wall contacts of particle {a} (index)")
        seen.add(a)
        if not N > 0:
            tensile += 1
            continue
        w = EDGE_WALLS[int(edge[a])]
        normal = _WALL_NORMALS[w]
        fn, ft = N * force_scale, T * force_scale
        out["i"].append(a)
        out["j"].append(n + w)
        out["normal"].append(normal)
        out["fn"].append(fn)
        out["ft"].append(ft)
        out["point"].append(position[a] + radius[a] * normal)
        out["branch"].append(radius[a] * normal)
        wall_force[w] += fn * normal + ft * np.array([-normal[1], normal[0]])
    dtypes = {"i": "i4", "j": "i4"}
    contacts = {k: np.array(v, dtypes.get(k, "f8")) for k, v in out.items()}
    for k in ("normal", "point", "branch"):
        contacts[k] = contacts[k].reshape(-1, 2)
    contacts["kind"] = np.ones(contacts["i"].size, "i1")
    return contacts, wall_force, tensile, apart


def _report(tensile, count, apart=(), ids=None):
    if tensile:
        warnings.warn(f"{tensile} contact(s) over {count} frame(s) had a normal force that is not "
                      "compressive (a fit that failed) and were left out", UserWarning, stacklevel=3)
    if apart:
        i, j, a, b = apart[0]
        warnings.warn(f"{len(apart)} particle pair(s) over {count} frame(s) were fitted on both disks with normal "
                      f"forces more than {ESTIMATES_APART:g} times apart (e.g. ids {ids[i]} and {ids[j]}: {a:.6g} "
                      f"fitted on id {ids[i]}, {b:.6g} on id {ids[j]}, in force units); the mean of the two is stored", UserWarning, stacklevel=3)


def open_pegs(adjacency, positions, *, metres_per_pixel=None, force_unit_n=None, frame_interval_s=1.0,
              thickness_m=1.0, density_kg_m3=1000.0):
    """A PeGS2 experiment as an in-memory dataset of the contract.

    Arguments as :func:`pegs_snapshots`.

    Returns
    -------
    xarray.Dataset
        A dataset of the contract (docs/schema.md; the conversion's rules: docs/formats.md)
        with ``wall_force`` and ``wall_normal``; the attribute ``pegs_pairs`` counts the pairs
        fitted on both disks and on one.
    """
    from .convert import snapshots_dataset

    static, stream = pegs_snapshots(adjacency, positions, metres_per_pixel=metres_per_pixel,
                                    force_unit_n=force_unit_n, frame_interval_s=frame_interval_s,
                                    thickness_m=thickness_m, density_kg_m3=density_kg_m3)
    snaps = list(stream)
    _report(sum(s.pop("tensile") for s in snaps), len(snaps), [a for s in snaps for a in s.pop("apart")],
            static["ids"])
    return snapshots_dataset(static, snaps, ("wall_force",), wall_normal=static["wall_normal"])


def convert_pegs(out, adjacency, positions, *, metres_per_pixel=None, force_unit_n=None, frame_interval_s=1.0,
                 thickness_m=1.0, density_kg_m3=1000.0, overwrite=False, compress=True, progress=False):
    """Convert a PeGS2 experiment into a file of the contract.

    Arguments as :func:`pegs_snapshots`; ``out``, ``overwrite``, ``compress`` and ``progress``
    as :func:`grainview.formats.lammps.convert_lammps`. The file is written under a hidden
    name, validated, compressed and only then moved to ``out``: bad input leaves nothing.

    Returns
    -------
    int
        The number of frames written.
    """
    from .convert import check_out, write_snapshots

    inputs = [path for paths in (adjacency, positions) for path in
              ([paths] if isinstance(paths, (str, os.PathLike)) else list(paths or ()))]
    out = check_out(out, overwrite, inputs)
    static, stream = pegs_snapshots(adjacency, positions, metres_per_pixel=metres_per_pixel,
                                    force_unit_n=force_unit_n, frame_interval_s=frame_interval_s,
                                    thickness_m=thickness_m, density_kg_m3=density_kg_m3)
    tensile, apart = [], []

    def prepare(snap):
        tensile.append(snap.pop("tensile"))
        apart.extend(snap.pop("apart"))
        return snap

    count = write_snapshots(out, static, stream, ("wall_force",), overwrite=overwrite, compress=compress,
                            progress=progress, label="pegs", prepare=prepare, inputs=inputs)
    _report(sum(tensile), count, apart, static["ids"])
    return count
