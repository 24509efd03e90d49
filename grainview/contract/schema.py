"""The grainview data contract: names, dimensions, units and attributes of a packing file.

This module is the single source of truth for the contract that ``docs/schema.md``
describes in prose: the table :data:`VARIABLES`, the sentinels of empty contact slots, the
global attributes. A particle's shape is
defined in :mod:`grainview.contract.shapes`. It needs numpy only, so the solver can use it
without loading xarray. Built on it:

* :func:`grainview.contract.dataset.make_dataset` assembles an in-memory :class:`xarray.Dataset`
  from plain arrays (used by tests, demos and anyone converting another code's output);
* :class:`grainview.contract.writer.SnapshotWriter` creates a netCDF file and appends snapshots one
  at a time while a simulation runs (used by the solver);
* :func:`grainview.contract.validation.validate` checks a dataset against the same table.

Conventions (docs/conventions.md §0): 2D, SI units, a slab of thickness
``thickness_m`` (global attribute, 1 m by default) so that forces are in N and stresses in Pa.
For a contact between bodies ``i`` and ``j`` (``i < j``; walls are bodies ``N + w``), ``normal``
is the unit vector from i to j, ``t = (-n_y, n_x)``, and ``fn``/``ft`` are the components of the
force exerted by i on j (compressive ``fn > 0``). ``branch`` joins the centre of i to the centre
of j, or the particle centre to the contact point for wall contacts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SCHEMA_VERSION = "3.0"
"""The newest version of the contract: this grainview reads files up to its major number and
refuses newer ones. Written as ``grainview_schema_version`` into the files that need it
(:func:`schema_version`)."""
CELL_VERSION = "3.0"
"""The version written into files holding a periodic cell (``cell``, ``periodic``): a grainview
before 3.0 would take such a sample for one bounded by its box (wrong strains, fields and
pictures), so it must refuse the file rather than misread it."""
IRREGULAR_SHAPES_VERSION = "2.0"
"""The version written into files holding polygons that are not regular (their ``vertices``)
and no cell: a grainview before 2.0 would read every polygon as the regular one of its
``radius`` and ``n_vertices``."""
REGULAR_SHAPES_VERSION = "1.0"
"""The version written into files whose particles are all disks or regular polygons, in a box.
Such a file means the same to every grainview."""


def schema_version(irregular: bool, cell: bool = False) -> str:
    """The version a file is written with: the oldest that reads it right.
    :data:`CELL_VERSION` for a file with a periodic cell (``cell``), else
    :data:`IRREGULAR_SHAPES_VERSION` when it holds polygons that are not regular
    (``irregular``), else :data:`REGULAR_SHAPES_VERSION`."""
    if cell:
        return CELL_VERSION
    return IRREGULAR_SHAPES_VERSION if irregular else REGULAR_SHAPES_VERSION

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

TIME_ATTRS = {"units": "s", "long_name": "simulated time since the start of the simulation",
              "comment": "elapsed model time, not a date: it has no reference time, so it carries no "
                         "CF time axis (axis T would require units 'seconds since <date>')"}
"""Attributes of the ``time`` coordinate. CF (section 4.4) identifies a time axis by units of the
form ``<unit> since <reference date>``; a simulation's clock has no date, so ``time`` is a plain
coordinate in seconds (no ``axis: T``, no ``standard_name: time``), which CF allows and which no
CF reader decodes into dates."""


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
    "radius": Var(("particle",), "f8", "m", "circumscribed radius: a disk's radius, a polygon's farthest vertex "
                  "from its centroid"),
    "n_vertices": Var(("particle",), "i4", "1", "number of vertices (0 = disk, >= 3 = polygon)"),
    "vertices": Var(("particle", "vertex", "xy"), "f8", "m", "polygon vertices in the particle's own frame "
                    "(centroid at the origin, counter-clockwise; NaN beyond n_vertices and for disks); "
                    "absent: regular polygons", False),
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
    # periodic cell (docs/schema.md, "The periodic cell"; grainview.contract.cell)
    "cell": Var(("time", "cell_vector", "xy"), "f8", "m", "lattice vectors a = (l, 0) and b = (tilt, h) of the "
                "periodic cell box_min + s a + t b, 0 <= s, t < 1", False),
    "periodic": Var(("cell_vector",), "i1", "1", "1 where the sample repeats along the cell vector, 0 where walls "
                    "bound it", False),
    "cell_velocity": Var(("time", "cell_vector", "xy"), "f8", "m s-1", "rates of the cell's lattice vectors, da/dt and "
                         "db/dt (a simple shear: db/dt = (gamma_dot h, dh/dt))", False),
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
    "local_law_residual": Var(("time",), "f8", "1", "natural-map residual |F|/|r| of the last step's impulses: "
                              "zero for every solution of the Signorini-Coulomb laws", False),
    "unbalanced_force": Var(("time",), "f8", "1", "largest net force on a particle over the mean force of a "
                            "loaded contact point, last step", False),
    "nlgs_unconverged_steps": Var(("time",), "i4", "1", "steps since the previous snapshot (this one's included) "
                                  "whose NLGS stopped at its sweep cap or stall test before its stopping norms "
                                  "met their tolerances", False),
    "nlgs_unconverged_residual": Var(("time",), "f8", "1", "largest final NLGS quadratic norm (the stopping norm, "
                                     "against solver_tolerance) of those steps; 0 when there are none", False),
    "nlgs_unconverged_local_law_residual": Var(("time",), "f8", "1", "largest natural-map residual |F|/|r| of "
                                               "those steps' impulses; 0 when there are none", False),
    "max_interpenetration": Var(("time",), "f8", "m", "largest interpenetration between bodies", False),
    "kinetic_energy": Var(("time",), "f8", "J", "total kinetic energy", False),
    # written last in each snapshot by SnapshotWriter (the last bytes of a netCDF-3 record)
    "complete": Var(("time",), "i1", "1", "1 once the snapshot is completely written", False),
}

MAX_STEP_INDEX = 2**31 - 1
"""Largest step index the ``step`` variable (a 32-bit integer) holds: a run's steps, its
compaction's and its test's together, must stay below it."""

REQUIRED = tuple(name for name, var in VARIABLES.items() if var.required)
CONTACT_VARIABLES = ("i", "j", "kind", "normal", "fn", "ft", "point", "branch")
OPTIONAL_CONTACT_VARIABLES = ("gap",)
"""Optional variables given per contact, like the required ones, in a snapshot's ``contacts``."""
DIAGNOSTICS = ("step", "nlgs_iterations", "nlgs_residual", "local_law_residual", "unbalanced_force",
               "nlgs_unconverged_steps", "nlgs_unconverged_residual", "nlgs_unconverged_local_law_residual",
               "max_interpenetration", "kinetic_energy")
"""The solver's per-snapshot diagnostics (optional variables along ``time``); the
``nlgs_unconverged_*`` ones count the steps since the previous snapshot, the others describe
the snapshot's own last step."""


def complete_snapshots(variables) -> np.ndarray:
    """Boolean per snapshot: ``time`` finite and, where the file has it, ``complete == 1``.

    ``variables`` maps names to array-likes (a netCDF4 or xarray dataset's variables).
    """
    ok = np.isfinite(np.asarray(variables["time"][:], dtype=float))
    if "complete" in variables:
        ok &= np.asarray(variables["complete"][:]) == 1
    return ok


def leading_complete(complete) -> int:
    """How many snapshots at the start of a file are complete: the index of the first
    incomplete one in ``complete`` (:func:`complete_snapshots`), or all of them."""
    complete = np.asarray(complete, bool)
    return int(np.argmin(complete)) if not complete.all() else complete.size


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


def empty_slots(shape, name):
    """An array of ``shape`` filled with the empty-slot value of contract variable ``name``
    (:data:`EMPTY_ID` for i, j; :data:`EMPTY_KIND` for kind; NaN otherwise)."""
    var = VARIABLES[name]
    if name in ("i", "j"):
        return np.full(shape, EMPTY_ID, dtype=var.dtype)
    if name == "kind":
        return np.full(shape, EMPTY_KIND, dtype=var.dtype)
    return np.full(shape, np.nan, dtype=var.dtype)


def global_attrs(n_particles: int, n_walls: int, attrs: dict | None = None, irregular: bool = False,
                 cell: bool = False) -> dict:
    """Global attributes every file carries, merged with the run's own ``attrs``; the schema
    version is :func:`schema_version` of ``irregular`` (the file holds polygons that are not
    regular) and ``cell`` (it holds a periodic cell)."""
    out = {
        "grainview_schema_version": schema_version(irregular, cell),
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


DIMENSIONLESS = ("1", "", "dimensionless")
"""Spellings accepted for the contract's unit "1"."""


def structure_problems(variables: dict, sizes: dict) -> list[str]:
    """The contract's structural problems of a file or dataset, from its metadata alone.

    ``variables`` maps each variable name to ``(dims, dtype)``; ``sizes`` each dimension to
    its length. Reported: a required variable missing, dims other than the contract's (or in
    another order), an integer variable stored as floats or the reverse, an ``xy`` of size
    other than 2. Shared by :func:`grainview.contract.validation.validate` (xarray) and ``grainview
    info`` (netCDF4 alone), so that both say the same."""
    problems = []
    for name, var in VARIABLES.items():
        if name not in variables:
            if var.required:
                problems.append(f"variable {name!r} is missing (expected dims {var.dims})")
            continue
        dims, dtype = variables[name]
        dims, dtype = tuple(dims), np.dtype(dtype)
        if set(dims) != set(var.dims) or len(dims) != len(var.dims):
            problems.append(f"variable {name!r} has dims {dims}, expected {var.dims}")
        elif dims != var.dims:
            problems.append(f"variable {name!r} has dims in order {dims}, expected {var.dims}")
        if var.is_integer and dtype.kind not in "iu":
            problems.append(f"variable {name!r} has dtype {dtype}, expected an integer type "
                            f"({var.dtype}) with sentinels instead of a _FillValue")
        if not var.is_integer and dtype.kind != "f":
            problems.append(f"variable {name!r} has dtype {dtype}, expected floating point ({var.dtype})")
    if "xy" in sizes and sizes["xy"] != 2:
        problems.append(f"dimension 'xy' has size {sizes['xy']}, expected 2 (x, y)")
    if "cell_vector" in sizes and sizes["cell_vector"] != 2:
        problems.append(f"dimension 'cell_vector' has size {sizes['cell_vector']}, expected 2 (a, b)")
    if "cell_velocity" in variables and "cell" not in variables:
        problems.append("variable 'cell_velocity' without 'cell': the rates of a periodic cell's vectors need the cell")
    if ("cell" in variables) != ("periodic" in variables):
        have, lack = ("cell", "periodic") if "cell" in variables else ("periodic", "cell")
        problems.append(f"variable {have!r} without {lack!r}: a periodic cell needs both its vectors (cell) and "
                        "which of them repeat (periodic)")
    return problems


def unit_problems(units: dict) -> list[str]:
    """Variables whose ``units`` attribute differs from the contract's; ``units`` maps each
    variable name of the file to its units attribute, or None when it has none (then it is
    taken in the contract's units: files built or edited by other tools often carry none)."""
    problems = []
    for name, var in VARIABLES.items():
        if name not in units or name == "complete" or units[name] is None:
            continue
        given = str(units[name]).strip()
        if given != var.units and not (var.units == "1" and given in DIMENSIONLESS):
            problems.append(f"variable {name!r} has units {units[name]!r}, expected {var.units!r} "
                            "(SI, as the contract says)")
    return problems


def missing_units(units: dict) -> list[str]:
    """Contract variables among ``units`` (name -> units attribute or None) without one."""
    return [name for name in VARIABLES if name in units and name != "complete" and units[name] is None]
