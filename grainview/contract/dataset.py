"""Building an in-memory :class:`xarray.Dataset` of the data contract from plain arrays, and
the encoding that writes one to netCDF with the contract's sentinels intact.

:func:`make_dataset` is how tests, demos and other codes' converters produce a dataset that
every analysis accepts; the contract itself (names, dims, units) is :mod:`grainview.contract.schema`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .errors import ParameterError
from .schema import (CONTACT_VARIABLES, DEFAULT_WALL_NAMES, OPTIONAL_CONTACT_VARIABLES, TIME_ATTRS, VARIABLES,
                     XY, contact_slots, empty_slots, global_attrs, variable_attrs)
from .cell import CELL_VECTORS, minimum_image, restricted_cell, wrap
from .shapes import has_irregular_polygons, inertia_per_mass, particle_area, shape_problems

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["make_dataset", "netcdf_encoding", "netcdf_options"]


def _coords(times, n_walls, wall_names, cell=False):
    coords = {"time": ("time", np.asarray(times, dtype="f8"), dict(TIME_ATTRS)),
              "xy": ("xy", np.array(XY), {"long_name": "Cartesian component"})}
    if cell:
        coords["cell_vector"] = ("cell_vector", np.array(CELL_VECTORS), {"long_name": "lattice vector of the cell"})
    if n_walls:
        names = tuple(wall_names) if wall_names is not None else DEFAULT_WALL_NAMES[:n_walls]
        if len(names) != n_walls:
            raise ParameterError(f"wall_names has {len(names)} names, expected one per wall ({n_walls})")
        coords["wall"] = ("wall", np.array(names), {"long_name": "wall name"})
    return coords


def make_dataset(
    *,
    radius,
    position,
    contacts,
    box_min,
    box_max,
    time=None,
    n_vertices=None,
    mass=None,
    inertia=None,
    angle=None,
    density: float = 2600.0,
    n_walls: int = 0,
    wall_names=None,
    attrs: dict | None = None,
    n_contact_slots: int | None = None,
    **optional,
) -> xr.Dataset:
    """Assemble a dataset of the contract from plain arrays.

    T snapshots of N particles and ``n_walls`` walls; every argument is keyword-only.

    Parameters
    ----------
    radius : array_like, (N,)
        Particle radii, m.
    position : array_like, (T, N, 2)
        Particle centres, m (a (N, 2) array is taken as a single snapshot).
    contacts : list of dict
        T dicts with keys ``i, j, kind, normal, fn, ft`` and optionally ``point``, ``branch``
        and ``gap`` (one entry per contact; a double contact is one entry; forces in N, ``gap``
        in m, given for every snapshot or none). ``branch`` defaults to ``x_j - x_i`` for
        particle pairs (its minimum image in a periodic cell); ``point`` defaults to the point on the segment i-j at distance ``r_i``
        from i (exact for disks). For wall contacts (``j >= N``) both ``point`` and ``branch``
        must be given.
    box_min, box_max : array_like, (T, 2) or (2,)
        Corners of the sample box, m.
    time : array_like, (T,), optional
        Snapshot times, s (default 0, 1, ..., T-1).
    n_vertices, mass, inertia, angle : array_like, optional
        Vertex counts (0 for a disk), masses (kg), moments of inertia (kg m2) and angles
        (rad, broadcast to (T, N)); defaults are disks, masses and inertias those of each
        particle's shape (:mod:`grainview.contract.shapes`; regular polygons unless the optional
        ``vertices`` are given) of ``density`` (kg m-3) in a slab of unit thickness, at zero angle.
    density : float, default 2600.0
        Density of the default masses, kg m-3.
    n_walls : int, default 0
        Number of walls (bodies N, N+1, ...).
    wall_names : sequence of str, optional
        One name per wall (default: the contract's default names).
    attrs : dict, optional
        Global attributes added to the contract's.
    n_contact_slots : int, optional
        Size of the ``contact`` dimension (default: :func:`grainview.contract.schema.contact_slots`).
    **optional
        Any optional contract variable (``velocity``, ``wall_force``, ``step``...). A periodic
        sample gives ``periodic`` (2,) (1 where it repeats along the cell vector a, b) and
        ``cell`` (T, 2, 2) or (2, 2), its lattice vectors (m, :mod:`grainview.contract.cell`),
        or ``cell=None`` for the rectangular cell of the box; the global attribute
        ``cell_positions`` says whether the positions are ``wrapped`` into the cell (the default
        when they all are) or ``unwrapped``.

    Returns
    -------
    xarray.Dataset
        An in-memory dataset of the contract (docs/schema.md) that every analysis accepts.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When the arrays disagree in size, a snapshot holds more contacts than slots, a wall
        contact lacks ``point`` or ``branch``, or an optional variable is unknown.
    """
    radius = np.asarray(radius, dtype="f8")
    n = radius.shape[0]
    position = np.asarray(position, dtype="f8")
    if position.ndim == 2:
        position = position[None]
    t = position.shape[0]
    if len(contacts) != t:
        raise ParameterError(f"contacts has {len(contacts)} snapshots, position has {t}")
    n_vertices = np.zeros(n, "i4") if n_vertices is None else np.broadcast_to(np.asarray(n_vertices, "i4"), (n,))
    if "vertices" in optional:
        problems = shape_problems(radius, n_vertices, np.asarray(optional["vertices"], "f8"))
        if problems:
            raise ParameterError("; ".join(problems))
        if np.shape(optional["vertices"])[1] == 0:  # disks only: nothing to store
            optional = {k: v for k, v in optional.items() if k != "vertices"}
    area = particle_area(radius, n_vertices, optional.get("vertices"))
    mass = density * area if mass is None else np.broadcast_to(np.asarray(mass, "f8"), (n,))
    inertia = mass * inertia_per_mass(radius, n_vertices, optional.get("vertices")) if inertia is None else np.broadcast_to(np.asarray(inertia, "f8"), (n,))
    angle = np.zeros((t, n)) if angle is None else np.broadcast_to(np.asarray(angle, "f8"), (t, n))
    slots = n_contact_slots or contact_slots(n, n_walls)
    box_min = np.broadcast_to(np.asarray(box_min, "f8"), (t, 2))
    box_max = np.broadcast_to(np.asarray(box_max, "f8"), (t, 2))
    periodic = optional.get("periodic")
    if "cell_velocity" in optional and periodic is None:
        raise ParameterError("cell_velocity given without periodic: the rates of a periodic cell's vectors need "
                             "the cell")
    if "cell" in optional and periodic is None:
        raise ParameterError("cell given without periodic: say along which cell vectors (a, b) the sample repeats")
    if periodic is not None:
        periodic = np.asarray(periodic, "i1")
        cell = optional.get("cell")
        cell = restricted_cell(box_min, box_max) if cell is None else np.broadcast_to(np.asarray(cell, "f8"),
                                                                                      (t, 2, 2))
        optional = {**optional, "cell": cell, "periodic": periodic}
        if "cell_velocity" in optional:
            optional["cell_velocity"] = np.broadcast_to(np.asarray(optional["cell_velocity"], "f8"), (t, 2, 2))
        attrs = dict(attrs or {})
        if "cell_positions" not in attrs:
            inside = np.allclose(wrap(position, box_min[:, None], cell[:, None], periodic), position, rtol=0,
                                 atol=1e-12 * float(np.abs(box_max - box_min).max()))
            attrs["cell_positions"] = "wrapped" if inside else "unwrapped"

    names = CONTACT_VARIABLES + tuple(v for v in OPTIONAL_CONTACT_VARIABLES if contacts and v in contacts[0])
    data = {name: empty_slots((t, slots) + ((2,) if VARIABLES[name].dims[-1] == "xy" else ()), name)
            for name in names}
    count = np.zeros(t, "i4")
    for k, snap in enumerate(contacts):
        i = np.asarray(snap["i"], "i4")
        m = i.shape[0]
        if m > slots:
            raise ParameterError(f"snapshot {k} has {m} contacts, more than the {slots} contact slots")
        j = np.asarray(snap["j"], "i4")
        count[k] = m
        data["i"][k, :m] = i
        data["j"][k, :m] = j
        data["kind"][k, :m] = np.asarray(snap.get("kind", np.ones(m)), "i1")
        normal = np.asarray(snap["normal"], "f8").reshape(m, 2)
        data["normal"][k, :m] = normal
        data["fn"][k, :m] = snap["fn"]
        data["ft"][k, :m] = snap.get("ft", np.zeros(m))
        for name in names[len(CONTACT_VARIABLES):]:
            if name not in snap:
                raise ParameterError(f"snapshot {k} lacks {name!r}: give it for every snapshot or none")
            data[name][k, :m] = snap[name]
        wall = j >= n
        if "branch" in snap:
            data["branch"][k, :m] = np.asarray(snap["branch"], "f8").reshape(m, 2)
        else:
            if wall.any():
                raise ParameterError("wall contacts need an explicit 'branch' (particle centre to contact point)")
            d = position[k, j] - position[k, i]
            data["branch"][k, :m] = d if periodic is None else minimum_image(d, optional["cell"][k], periodic)
        if "point" in snap:
            data["point"][k, :m] = np.asarray(snap["point"], "f8").reshape(m, 2)
        else:
            if wall.any():
                raise ParameterError("wall contacts need an explicit 'point'")
            data["point"][k, :m] = position[k, i] + radius[i, None] * normal

    arrays = {
        "radius": radius, "n_vertices": n_vertices, "mass": mass, "inertia": inertia,
        "position": position, "angle": angle, "contact_count": count, **data,
        "box_min": box_min, "box_max": box_max,
    }
    for name, value in optional.items():
        if name not in VARIABLES or VARIABLES[name].required:
            raise ParameterError(f"unknown optional variable {name!r}; expected one of "
                                 f"{[v for v in VARIABLES if not VARIABLES[v].required]}")
        arrays[name] = np.asarray(value)
    variables = {}
    for name, value in arrays.items():
        var = VARIABLES[name]
        variables[name] = (var.dims, np.asarray(value).astype(var.dtype, copy=False), variable_attrs(name))
    import xarray as xr

    ds = xr.Dataset(variables, coords=_coords(np.arange(t, dtype="f8") if time is None else time, n_walls, wall_names,
                                              periodic is not None))
    ds.attrs = global_attrs(n, n_walls, attrs, has_irregular_polygons(radius, n_vertices, optional.get("vertices")),
                            periodic is not None)
    return ds


def netcdf_encoding(ds: xr.Dataset, zlib: bool = False, complevel: int | None = None) -> dict:
    """Encoding for ``Dataset.to_netcdf`` that keeps the contract's integer sentinels.

    Integers get no ``_FillValue`` (xarray would turn masked integers into floats on
    reading); floats use NaN as fill value. With ``zlib`` the contract's variables are also
    deflated at ``complevel`` (1-9, with byte shuffling), for a file in
    :data:`grainview.contract.writer.COMPRESSED_FORMAT` (docs/schema.md, "Compression"),
    chunked and filtered as :func:`grainview.contract.writer.compress_file` does (one snapshot
    per chunk; a per-snapshot variable that zlib shrinks by less than
    :data:`~grainview.contract.writer.MIN_SAVING` is not deflated; every variable but the scalars
    with Fletcher-32 checksums, :data:`~grainview.contract.writer.CHECKSUMS`);
    :func:`grainview.open_dataset` reads it unchanged. :func:`netcdf_options` gives the format
    and the encoding together.

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset of the contract.
    zlib : bool
        Deflate the contract's variables.
    complevel : int, optional
        zlib level, 1 (fastest) to 9 (smallest); used with ``zlib`` (default:
        :data:`grainview.contract.writer.DEFAULT_COMPLEVEL`).

    Returns
    -------
    dict
        Variable name -> encoding, for ``ds.to_netcdf(path, encoding=...)``.

    Examples
    --------
    >>> ds = grainview.open_dataset("run.nc")                                  # doctest: +SKIP
    >>> ds.to_netcdf("run-zlib.nc", format="NETCDF4_CLASSIC",
    ...              encoding=grainview.contract.dataset.netcdf_encoding(ds, zlib=True))  # doctest: +SKIP
    """
    from . import writer

    if zlib:
        complevel = writer.check_complevel(writer.DEFAULT_COMPLEVEL if complevel is None else complevel)
    enc = {}
    for name in ds.variables:
        if name in VARIABLES:
            floating = ds[name].dtype.kind == "f"
            enc[name] = {"_FillValue": np.nan} if floating else {"_FillValue": None}
            if zlib:
                deflate = {"zlib": True, "complevel": int(complevel), "shuffle": True}
                var = ds[name]
                if var.ndim and var.dims[0] == "time" and var.shape[0]:
                    chunks = writer.chunk_shape(var.shape, var.dtype.itemsize, floating)
                    fill = np.nan if floating and var.ndim > 1 and chunks[1] < var.shape[1] else None
                    enc[name]["chunksizes"] = chunks
                    sample = [writer.without_fill(var[block].values, fill)
                              for block in writer.sample_blocks(var.shape[0], chunks[0])]
                    if writer.deflate_saving(sample, complevel) < writer.MIN_SAVING:
                        deflate = {}
                enc[name].update(deflate)
    if "time" in ds.variables:
        enc["time"] = {"_FillValue": np.nan}
    if zlib and writer.CHECKSUMS:  # every chunk verified as it is read, as compress_file writes it
        for name in ds.variables:
            if ds[name].ndim:
                enc.setdefault(name, {})["fletcher32"] = True
    return enc


def netcdf_options(ds: xr.Dataset, compress: bool = True, complevel: int | None = None) -> dict:
    """Keyword arguments of ``Dataset.to_netcdf`` that write ``ds`` as the solver writes a finished run.

    Compressed (:data:`grainview.contract.writer.COMPRESSED_FORMAT`, zlib at ``complevel``) or, with
    ``compress=False``, netCDF-3 (the format of :data:`grainview.contract.writer.APPEND_FORMAT`, under
    xarray's name ``NETCDF3_64BIT``); the contract's integer sentinels kept either way
    (:func:`netcdf_encoding`).

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset of the contract.
    compress : bool, default True
        Write compressed (NETCDF4_CLASSIC with zlib) rather than netCDF-3.
    complevel : int, optional
        zlib level, 1 (fastest) to 9 (smallest); used with ``compress`` (default:
        :data:`grainview.contract.writer.DEFAULT_COMPLEVEL`).

    Returns
    -------
    dict
        ``format`` and ``encoding``, for ``ds.to_netcdf(path, **options)``.

    Examples
    --------
    >>> ds.to_netcdf("copy.nc", **grainview.contract.dataset.netcdf_options(ds))      # doctest: +SKIP
    """
    from .writer import APPEND_FORMAT, COMPRESSED_FORMAT

    plain = APPEND_FORMAT.removesuffix("_OFFSET")  # xarray's name for the same format
    return {"format": COMPRESSED_FORMAT if compress else plain,
            "encoding": netcdf_encoding(ds, zlib=bool(compress), complevel=complevel)}
