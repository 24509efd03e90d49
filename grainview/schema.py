"""The grainview data contract: names, dimensions, units and attributes of a packing file.

This module is the single source of truth for the contract that ``docs/schema.md``
describes in prose. Three things are built from the table :data:`VARIABLES` below:

* :func:`make_dataset` assembles an in-memory :class:`xarray.Dataset` from plain arrays
  (used by tests, demos and anyone converting another code's output);
* :class:`SnapshotWriter` creates a netCDF file and appends snapshots one at a time while a
  simulation runs (used by the solver);
* :func:`grainview.validation.validate` checks a dataset against the same table.

Conventions (docs/conventions.md §0): 2D, SI units, a slab of thickness
``thickness_m`` (global attribute, 1 m by default) so that forces are in N and stresses in Pa.
For a contact between bodies ``i`` and ``j`` (``i < j``; walls are bodies ``N + w``), ``normal``
is the unit vector from i to j, ``t = (-n_y, n_x)``, and ``fn``/``ft`` are the components of the
force exerted by i on j (compressive ``fn > 0``). ``branch`` joins the centre of i to the centre
of j, or the particle centre to the contact point for wall contacts.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .errors import FileFormatError, ParameterError

SCHEMA_VERSION = "1.0"
"""Version of the contract written into every file as ``grainview_schema_version``."""

XY = ("x", "y")

# Sentinels of the integer contact variables in empty slots (integers carry no _FillValue so
# that xarray keeps them integers when a file is opened).
EMPTY_ID = -1
EMPTY_KIND = 0
KIND_SIMPLE = 1
KIND_DOUBLE = 2

KIND_ATTRS = {
    "flag_values": np.array([EMPTY_KIND, KIND_SIMPLE, KIND_DOUBLE], dtype="i1"),
    "flag_meanings": "empty simple double",
    "comment": "simple: one contact point (vertex-edge, or any contact of a disk); "
    "double: edge-edge contact solved at two points, stored once with its resultant",
}

DEFAULT_WALL_NAMES = ("bottom", "right", "top", "left")


@dataclass(frozen=True)
class Var:
    """One variable of the contract."""

    dims: tuple[str, ...]
    dtype: str
    units: str
    long_name: str
    required: bool = True

    @property
    def is_integer(self) -> bool:
        return np.dtype(self.dtype).kind in "iu"


VARIABLES: dict[str, Var] = {
    # per particle (static)
    "radius": Var(("particle",), "f8", "m", "circumscribed radius (disk radius for disks)"),
    "n_vertices": Var(("particle",), "i4", "1", "number of vertices (0 = disk, >= 3 = regular polygon)"),
    "mass": Var(("particle",), "f8", "kg", "particle mass"),
    "inertia": Var(("particle",), "f8", "kg m2", "moment of inertia about the centre of mass"),
    # per particle and time
    "position": Var(("time", "particle", "xy"), "f8", "m", "position of the particle centre"),
    "angle": Var(("time", "particle"), "f8", "rad", "rotation angle of the particle"),
    "velocity": Var(("time", "particle", "xy"), "f8", "m s-1", "velocity of the particle centre", False),
    "angular_velocity": Var(("time", "particle"), "f8", "rad s-1", "angular velocity", False),
    # per contact slot and time
    "contact_count": Var(("time",), "i4", "1", "number of occupied contact slots"),
    "i": Var(("time", "contact"), "i4", "1", "first body of the contact (particle id)"),
    "j": Var(("time", "contact"), "i4", "1", "second body of the contact (particle id, or N + wall index)"),
    "kind": Var(("time", "contact"), "i1", "1", "contact kind"),
    "normal": Var(("time", "contact", "xy"), "f8", "1", "unit contact normal, from i to j"),
    "fn": Var(("time", "contact"), "f8", "N", "normal force exerted by i on j (compression > 0)"),
    "ft": Var(("time", "contact"), "f8", "N", "tangential force exerted by i on j along t = (-n_y, n_x)"),
    "point": Var(("time", "contact", "xy"), "f8", "m", "application point of the contact force"),
    "branch": Var(("time", "contact", "xy"), "f8", "m", "branch vector: centre of i to centre of j (to the contact point for walls)"),
    "gap": Var(("time", "contact"), "f8", "m", "smallest separation of the contact's points along the normal "
               "(negative: overlap)", False),
    # sample box
    "box_min": Var(("time", "xy"), "f8", "m", "lower-left corner of the sample box"),
    "box_max": Var(("time", "xy"), "f8", "m", "upper-right corner of the sample box"),
    # walls
    "wall_normal": Var(("wall", "xy"), "f8", "1", "unit wall normal pointing into the sample", False),
    "wall_position": Var(("time", "wall", "xy"), "f8", "m", "a point of the wall line", False),
    "wall_force": Var(("time", "wall", "xy"), "f8", "N", "total force exerted by the particles on the wall", False),
    # restart state: what a resumed run needs beyond the snapshot itself
    "wall_velocity": Var(("time", "wall", "xy"), "f8", "m s-1", "velocity of the wall (imposed, or reached under its stress)", False),
    "normal_impulse": Var(("time", "contact", "contact_point"), "f8", "N s",
                          "normal impulse of the last time step at each point of the contact, in detection "
                          "order (0 for the second point of a simple contact and in empty slots)", False),
    "tangential_impulse": Var(("time", "contact", "contact_point"), "f8", "N s",
                              "tangential impulse of the last time step at each point of the contact, along t "
                              "(0 for the second point of a simple contact and in empty slots)", False),
    # solver diagnostics
    "step": Var(("time",), "i4", "1", "time-step index of the snapshot", False),
    "nlgs_iterations": Var(("time",), "i4", "1", "NLGS iterations of the last step", False),
    "nlgs_residual": Var(("time",), "f8", "1", "final NLGS residual of the last step", False),
    "max_interpenetration": Var(("time",), "f8", "m", "largest interpenetration between bodies", False),
    "kinetic_energy": Var(("time",), "f8", "J", "total kinetic energy", False),
    # written last in each snapshot by SnapshotWriter (the last bytes of a netCDF-3 record)
    "complete": Var(("time",), "i1", "1", "1 once the snapshot is completely written", False),
}

REQUIRED = tuple(name for name, var in VARIABLES.items() if var.required)
CONTACT_VARIABLES = ("i", "j", "kind", "normal", "fn", "ft", "point", "branch")
OPTIONAL_CONTACT_VARIABLES = ("gap",)
"""Optional variables given per contact, like the required ones, in a snapshot's ``contacts``."""
DIAGNOSTICS = ("step", "nlgs_iterations", "nlgs_residual", "max_interpenetration", "kinetic_energy")


def particle_area(radius, n_vertices):
    """Area of each particle in m2: pi R^2 for a disk (n = 0), (n/2) R^2 sin(2 pi/n) for a
    regular n-gon of circumscribed radius R. Part of the contract's shape definition."""
    radius = np.asarray(radius, dtype=float)
    n = np.asarray(n_vertices)
    safe_n = np.where(n >= 3, n, 3)
    polygon = 0.5 * safe_n * radius**2 * np.sin(2 * np.pi / safe_n)
    return np.where(n >= 3, polygon, np.pi * radius**2)


def complete_snapshots(variables) -> np.ndarray:
    """Boolean per snapshot: ``time`` finite and, where the file has it, ``complete == 1``.

    ``variables`` maps names to array-likes (a netCDF4 or xarray dataset's variables).
    """
    ok = np.isfinite(np.asarray(variables["time"][:], dtype=float))
    if "complete" in variables:
        ok &= np.asarray(variables["complete"][:]) == 1
    return ok


def variable_attrs(name: str) -> dict:
    """The attributes of contract variable ``name`` (units, long_name, flags)."""
    var = VARIABLES[name]
    attrs = {"units": var.units, "long_name": var.long_name}
    if name == "kind":
        attrs.update(KIND_ATTRS)
    if name in ("i", "j"):
        attrs["comment"] = f"{EMPTY_ID} in empty slots"
    return attrs


def contact_slots(n_particles: int, n_walls: int) -> int:
    """Size of the ``contact`` dimension: the most pairs a planar contact graph can hold.

    The contact network of convex bodies in 2D is a planar graph, which has at most
    ``3 V - 6`` edges for ``V >= 3`` vertices (here the particles and the walls).
    """
    v = int(n_particles) + int(n_walls)
    return max(3 * v - 6, v, 1)


def _empty(shape, name):
    var = VARIABLES[name]
    if name in ("i", "j"):
        return np.full(shape, EMPTY_ID, dtype=var.dtype)
    if name == "kind":
        return np.full(shape, EMPTY_KIND, dtype=var.dtype)
    return np.full(shape, np.nan, dtype=var.dtype)


def global_attrs(n_particles: int, n_walls: int, attrs: dict | None = None) -> dict:
    """Global attributes every file carries, merged with the run's own ``attrs``."""
    out = {
        "grainview_schema_version": SCHEMA_VERSION,
        "Conventions": "CF-1.8",
        "thickness_m": 1.0,
        "n_particles": int(n_particles),
        "n_walls": int(n_walls),
    }
    for key, value in (attrs or {}).items():
        if isinstance(value, bool):
            value = int(value)
        elif value is None:
            value = "none"
        elif isinstance(value, (list, tuple)):
            value = np.asarray(value)
        out[key] = value
    return out


def _coords(times, n_walls, wall_names):
    coords = {"time": ("time", np.asarray(times, dtype="f8"), {"units": "s", "long_name": "simulated time", "axis": "T"}),
              "xy": ("xy", np.array(XY), {"long_name": "Cartesian component"})}
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

    Parameters
    ----------
    radius : (N,) array, m
    position : (T, N, 2) array, m (a (N, 2) array is taken as a single snapshot)
    contacts : list of T dicts with keys ``i, j, kind, normal, fn, ft`` and optionally
        ``point``, ``branch`` and ``gap`` (one entry per contact; a double contact is one
        entry; ``gap`` in m, given for every snapshot or none).
        ``branch`` defaults to ``x_j - x_i`` for particle pairs; ``point`` defaults to the
        point on the segment i-j at distance ``r_i`` from i (exact for disks). For wall
        contacts (``j >= N``) both ``point`` and ``branch`` must be given.
    box_min, box_max : (T, 2) or (2,) arrays, m
    n_vertices, mass, inertia, angle : defaults are disks of ``density`` (kg m-3) in a slab of
        unit thickness at zero angle.
    optional : any optional contract variable (``velocity``, ``wall_force``, ``step``...).
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
    area = np.pi * radius**2
    mass = density * area if mass is None else np.broadcast_to(np.asarray(mass, "f8"), (n,))
    inertia = 0.5 * mass * radius**2 if inertia is None else np.broadcast_to(np.asarray(inertia, "f8"), (n,))
    angle = np.zeros((t, n)) if angle is None else np.broadcast_to(np.asarray(angle, "f8"), (t, n))
    slots = n_contact_slots or contact_slots(n, n_walls)

    names = CONTACT_VARIABLES + tuple(v for v in OPTIONAL_CONTACT_VARIABLES if contacts and v in contacts[0])
    data = {name: _empty((t, slots) + ((2,) if VARIABLES[name].dims[-1] == "xy" else ()), name)
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
            data["branch"][k, :m] = position[k, j] - position[k, i]
        if "point" in snap:
            data["point"][k, :m] = np.asarray(snap["point"], "f8").reshape(m, 2)
        else:
            if wall.any():
                raise ParameterError("wall contacts need an explicit 'point'")
            data["point"][k, :m] = position[k, i] + radius[i, None] * normal

    box_min = np.broadcast_to(np.asarray(box_min, "f8"), (t, 2))
    box_max = np.broadcast_to(np.asarray(box_max, "f8"), (t, 2))
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
    ds = xr.Dataset(variables, coords=_coords(np.arange(t, dtype="f8") if time is None else time, n_walls, wall_names))
    ds.attrs = global_attrs(n, n_walls, attrs)
    return ds


def netcdf_encoding(ds: xr.Dataset) -> dict:
    """Encoding for ``Dataset.to_netcdf`` that keeps the contract's integer sentinels.

    Integers get no ``_FillValue`` (xarray would turn masked integers into floats on
    reading); floats use NaN as fill value.
    """
    enc = {}
    for name in ds.variables:
        if name in VARIABLES:
            floating = ds[name].dtype.kind == "f"
            enc[name] = {"_FillValue": np.nan} if floating else {"_FillValue": None}
    if "time" in ds.variables:
        enc["time"] = {"_FillValue": np.nan}
    return enc


def _move_into_place(temporary: str, path: str, overwrite: bool) -> None:
    """Rename ``temporary`` to ``path`` atomically; without ``overwrite`` an existing ``path``
    (even one created meanwhile by another process) is kept and FileExistsError raised."""
    if overwrite:
        os.replace(temporary, path)
        return
    try:
        os.link(temporary, path)  # fails if path exists: no check-then-rename race
    except FileExistsError:
        raise FileExistsError(f"{path} exists; pass overwrite=True to replace it") from None
    except OSError:  # file systems without hard links
        if os.path.exists(path):
            raise FileExistsError(f"{path} exists; pass overwrite=True to replace it") from None
        os.replace(temporary, path)
        return
    os.remove(temporary)


class SnapshotWriter:
    """Create a netCDF file of the contract and append snapshots while a run goes on.

    The file is synced to disk after every snapshot; ``time`` and then the flag ``complete``
    are written last (``complete`` is the last variable of each netCDF-3 record, so a record
    cut short reads 0 there), so a reader (:func:`grainview.open_dataset`) sees every
    completed snapshot and drops a trailing incomplete one. The format is netCDF-3 (64-bit
    offset) by default: its fixed layout survives a killed writer better than HDF5's.

    Use as a context manager::

        with SnapshotWriter.create(path, radius=r, n_vertices=nv, mass=m, inertia=I,
                                   n_walls=4, attrs=params) as w:
            w.append(time=t, position=x, angle=a, contacts=c, box_min=lo, box_max=hi)
    """

    def __init__(self, nc, path):
        self._nc = nc
        self.path = path
        self.n_particles = nc.dimensions["particle"].size
        self.n_slots = nc.dimensions["contact"].size
        self.n_walls = nc.dimensions["wall"].size if "wall" in nc.dimensions else 0

    @classmethod
    def create(cls, path, *, radius, n_vertices, mass, inertia, n_walls=0, wall_names=None,
               wall_normal=None, optional=(),
               attrs=None, n_contact_slots=None, overwrite=False, format="NETCDF3_64BIT_OFFSET"):
        """Create ``path`` with the static particle data; ``optional`` names the optional
        per-snapshot variables this file will hold (e.g. ``("velocity", *DIAGNOSTICS)``);
        the others are not written at all."""
        import netCDF4

        path = os.fspath(path)
        if os.path.exists(path) and not overwrite:
            raise FileExistsError(f"{path} exists; pass overwrite=True to replace it")
        radius = np.asarray(radius, "f8")
        n = radius.shape[0]
        slots = n_contact_slots or contact_slots(n, n_walls)
        unknown = [o for o in optional if o not in VARIABLES or VARIABLES[o].required]
        if unknown:
            raise ParameterError(f"unknown optional variables {unknown}")
        if not n_walls:
            optional = [o for o in optional if "wall" not in VARIABLES[o].dims]
        # The header and the static data are written under a temporary name and the file is
        # moved into place once they are on disk: a run killed while the file is being created
        # leaves either no file or a valid empty one, never a partial header.
        directory, base = os.path.split(os.path.abspath(path))
        temporary = os.path.join(directory, f".{base}.{os.getpid()}.part")
        nc = netCDF4.Dataset(temporary, "w", format=format)
        try:
            nc.set_auto_mask(False)
            nc.createDimension("time", None)
            nc.createDimension("particle", n)
            nc.createDimension("contact", slots)
            if any("contact_point" in VARIABLES[o].dims for o in optional):
                nc.createDimension("contact_point", 2)  # the two points of a double contact
            nc.createDimension("xy", 2)
            nc.createDimension("xy_strlen", 1)
            xy = nc.createVariable("xy", "S1", ("xy", "xy_strlen"))
            xy[:] = np.array([[b"x"], [b"y"]])
            xy.long_name = "Cartesian component"
            xy._Encoding = "utf-8"
            tvar = nc.createVariable("time", "f8", ("time",), fill_value=np.nan)
            tvar.units, tvar.long_name, tvar.axis = "s", "simulated time", "T"
            if n_walls:
                names = tuple(wall_names) if wall_names is not None else DEFAULT_WALL_NAMES[:n_walls]
                width = max(len(s) for s in names)
                nc.createDimension("wall", n_walls)
                nc.createDimension("wall_strlen", width)
                wv = nc.createVariable("wall", "S1", ("wall", "wall_strlen"))
                wv[:] = netCDF4.stringtochar(np.array(names, dtype=f"S{width}"))
                wv.long_name = "wall name"
                wv._Encoding = "utf-8"
            names = [*REQUIRED, *optional]
            if n_walls and wall_normal is not None:
                names.append("wall_normal")
            names.append("complete")  # defined last: the last bytes of each record
            for name in dict.fromkeys(names):
                var = VARIABLES[name]
                fill = None if var.is_integer else np.nan
                v = nc.createVariable(name, var.dtype, var.dims, fill_value=fill)
                v.setncatts(variable_attrs(name))
            static = {"radius": radius, "n_vertices": n_vertices, "mass": mass, "inertia": inertia}
            if "wall_normal" in nc.variables:
                static["wall_normal"] = wall_normal
            for name, value in static.items():
                nc.variables[name][:] = np.broadcast_to(np.asarray(value, VARIABLES[name].dtype),
                                                        nc.variables[name].shape)
            nc.setncatts(global_attrs(n, n_walls, attrs))
            nc.close()
            _move_into_place(temporary, path, overwrite)
        except BaseException:
            if nc.isopen():
                nc.close()
            if os.path.exists(temporary):
                os.remove(temporary)
            raise
        nc = netCDF4.Dataset(path, "a")
        nc.set_auto_mask(False)
        return cls(nc, path)

    @classmethod
    def open_append(cls, path):
        """Open an existing file of the contract to append further snapshots."""
        import netCDF4

        try:
            nc = netCDF4.Dataset(os.fspath(path), "a")
        except OSError as exc:
            raise FileFormatError(f"cannot open {path} for appending: {exc}") from exc
        nc.set_auto_mask(False)
        return cls(nc, path)

    def attribute(self, name, default=None):
        """The file's global attribute ``name`` (``default`` when it has none)."""
        return self._nc.getncattr(name) if name in self._nc.ncattrs() else default

    @property
    def n_snapshots(self) -> int:
        """Number of complete snapshots (trailing ones with no time are not counted)."""
        complete = np.flatnonzero(complete_snapshots(self._nc.variables))
        return int(complete[-1] + 1) if complete.size else 0

    def append(self, *, time, position, angle, contacts, box_min, box_max, **optional):
        """Write one snapshot; ``contacts`` is a dict of the contact variables with one
        entry per contact (any length up to the number of slots)."""
        nc = self._nc
        k = self.n_snapshots
        m = len(contacts["i"])
        if m > self.n_slots:
            raise ParameterError(f"{m} contacts exceed the file's {self.n_slots} contact slots")
        nc.variables["position"][k] = position
        nc.variables["angle"][k] = angle
        nc.variables["box_min"][k] = box_min
        nc.variables["box_max"][k] = box_max
        for name in CONTACT_VARIABLES + tuple(v for v in OPTIONAL_CONTACT_VARIABLES
                                              if v in contacts and v in nc.variables):
            var = VARIABLES[name]
            shape = (self.n_slots, 2) if var.dims[-1] == "xy" else (self.n_slots,)
            buf = _empty(shape, name)
            buf[:m] = np.asarray(contacts[name], var.dtype).reshape((m,) + shape[1:])
            nc.variables[name][k] = buf
        nc.variables["contact_count"][k] = m
        for name, value in optional.items():
            if name in nc.variables:
                nc.variables[name][k] = value
            elif name not in VARIABLES:
                raise ParameterError(f"unknown variable {name!r}")
        nc.variables["time"][k] = time
        nc.variables["complete"][k] = 1  # last: marks the snapshot complete
        nc.sync()

    def close(self):
        if self._nc.isopen():
            self._nc.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
