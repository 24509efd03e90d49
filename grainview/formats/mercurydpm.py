"""MercuryDPM 2D runs (``.data`` + ``.fstat`` + ``.restart``) as datasets of the grainview contract.

A MercuryDPM run named ``NAME`` writes ``NAME.data`` (particles, per snapshot), ``NAME.fstat``
(contacts, per snapshot) and ``NAME.restart`` (the model: dimensions, species, walls, particle
masses). The file layer is :mod:`grainview.formats.mercurydpm_text`; this module builds the
contract from it. docs/formats.md states the same for users.

* **Units.** MercuryDPM has no units of its own: a run is in whatever consistent units its
  driver chose, often nondimensional (diameter, density and gravity 1). The reader does not
  guess: ``units="si"`` says the run is in m, kg, s; otherwise ``units={"length": L, "mass":
  M, "time": T}`` gives one MercuryDPM unit of each in SI (m, kg, s), and every quantity is
  scaled by its dimension (forces by ``M L / T^2``).
* **Particles** are the ``.data`` lines in order (MercuryDPM's particle index); the same
  particles must be in every snapshot, with the same radii. ``position``, ``velocity``, ``angle``
  (``angleZ``) and ``angular_velocity`` (the ``.data`` column is ``-omegaZ``, written negated
  for XBalls) come from ``.data``; ``mass = 1 / invMass`` from ``.restart``, ``inertia = m r^2 /
  2`` for disks (``particleDimensions 2``) or ``2 m r^2 / 5`` for spheres in a 2D system
  (``particleDimensions 3``), as MercuryDPM computes them. A 2D system's particles are slabs
  one length unit thick: ``thickness_m = L``.
* **Contacts.** ``.fstat`` writes each particle pair twice, once from each side: the line of
  particle P with body I gives the force on P, ``fn n + ft t``, with ``n`` the unit normal from
  I to P and ``t`` the unit direction of the tangential force (the second line has ``-n``,
  ``-t``). A wall contact is written once, from the particle's side, with I = ``-w - 1`` and
  ``n`` pointing from the particle to the wall, and there the force on the particle is
  ``-(fn n + ft t)`` (MercuryDPM's own source calls this flip an old bug, and its ``.fstat``
  reader undoes it the same way). The reader keeps one contact per pair: bodies ``i < j`` (a
  wall is ``N + w``), ``normal`` the unit vector from i to j, the force exerted by i on j,
  ``fn``, ``ft`` its components along ``normal`` and ``(-normal_y, normal_x)``; ``point`` is
  MercuryDPM's contact point (the middle of the overlap), ``branch = x_j - x_i`` (the centre
  to the contact point for a wall), ``gap = -overlap``. Pairs whose two lines disagree (force,
  normal, overlap or contact point) are refused, and so are pairs written on one side only,
  except in the last snapshot, the mark of a file cut while it was written: that snapshot is
  left out with a warning. Pairs that do not overlap or whose normal force is tensile (viscous damping as they
  separate) are left out and counted in a warning.
* **Walls** are the ``.restart``'s walls in its order. An ``InfiniteWall`` whose outward
  normal is ``-y, +x, +y, -x`` is named ``bottom, right, top, left``; any other wall
  ``<type><index>``. ``wall_force`` is the total force the particles exert on each wall.
* ``time`` is the snapshots' time (MercuryDPM's ``t``, scaled); the box (``box_min``,
  ``box_max``) is the ``.data`` header's domain (``xmin ymin xmax ymax``).
* **Periodic cells** (docs/schema.md, "The periodic cell") come from the ``.restart``'s
  boundaries. A ``PeriodicBoundary`` of normal ``(1, 0, 0)`` makes the run periodic in x
  between its ``distanceLeft`` and ``distanceRight``, one of normal ``(0, 1, 0)`` in y (its
  ``shift``'s x component, set by ``setPlanewiseShift``, is the cell's tilt: only with x
  periodic too); a ``LeesEdwardsBoundary`` makes it periodic in x between ``left`` and
  ``right`` and in y between ``down`` and ``up``, the images across the top and the bottom
  shifted in x by its shift: the cell ``a = (l, 0)``, ``b = (tilt, h)`` with ``tilt`` the shift
  (moved by whole widths into ``[-l/2, l/2]``). The ``.restart`` holds the shift ``s`` and its
  rate ``v`` at its own time ``T`` only; MercuryDPM reads a restart as the shift ``s + v t``
  (a constant rate), and so does the reader: the shift of a snapshot at ``t > 0`` is ``s + v (t
  - dt - T)``, ``dt`` the time step, because the positions and contacts MercuryDPM writes at
  ``t`` are those of the step that began at ``t - dt``, whose ghost particles were shifted by
  the shift of that time; at ``t = 0`` (the forces of MercuryDPM's initial computation) it is
  ``s - v T``. The box is the cell's bounds along its periodic directions (the
  ``.data`` header's domain along a bounded one). Branches and contact points are minimum
  images (a contact across the boundary is computed on a ghost particle; MercuryDPM writes it
  under the real particles' indices, its contact point at the ghost): ``branch`` the shortest
  image of ``x_j - x_i``, ``point`` moved by whole cell vectors to its image nearest ``x_i``.
  Positions are wrapped into the cell (MercuryDPM wraps them into its rectangle; in a tilted
  cell they are moved by whole widths into the parallelogram), ``cell_positions = wrapped``.
  Refused in one line: another periodic boundary type (``AngledPeriodicBoundary``,
  ``CircularPeriodicBoundary``, ``TimeDependentPeriodicBoundary``...), a ``PeriodicBoundary``
  whose normal is not along x or y or whose shift is not its width along it, two boundaries
  across one direction, a ``LeesEdwardsBoundary`` with a ``PeriodicBoundary`` in the plane, a
  restart that lists only some of its boundaries (``...``), and a centre outside the cell.

Every function checks its input and refuses bad input in one line
(:class:`grainview.contract.errors.FileFormatError` or :class:`~grainview.contract.errors.ParameterError`).

A value that is not finite or is absurd (:mod:`grainview.formats.checks`) on a ``.data`` or
``.fstat`` line is refused naming the file and the line, and so is a contact that cannot exist
for its bodies' positions and sizes (:func:`grainview.formats.checks.check_contacts`).
"""

from __future__ import annotations

import math
import os
import warnings

import numpy as np

from ..contract.cell import minimum_image, restricted_cell, wrap
from ..contract.errors import FileFormatError, ParameterError
from .checks import Limits, check_contacts
from .mercurydpm_text import iter_data, iter_fstat, read_restart

__all__ = ["mercurydpm_snapshots", "open_mercurydpm", "convert_mercurydpm", "unit_scales", "BOX_WALLS"]

BOX_WALLS = {(0, -1): "bottom", (1, 0): "right", (0, 1): "top", (-1, 0): "left"}
"""Names of the axis-aligned InfiniteWalls by their outward normal (pointing out of the sample)."""
UNIT_RANGE = (1e-30, 1e30)
"""The SI values one unit of length (m), mass (kg) or time (s) of a run may have: far beyond
any granular run's, and narrow enough that the derived units (a force's ``M L / T^2``) stay
finite and > 0."""
_UNITS_HINT = ("MercuryDPM runs carry no units: give units='si' (m, kg, s) or the SI value of one unit of "
               "length, mass and time of the run (units={'length': m, 'mass': kg, 'time': s}; --units si or "
               "--units length=L,mass=M,time=T)")


def unit_scales(units) -> dict:
    """The SI value of one MercuryDPM unit of length, mass and time.

    Parameters
    ----------
    units : "si" or dict
        ``"si"`` (the run is in m, kg, s), or ``{"length": L, "mass": M, "time": T}`` with
        L in m, M in kg, T in s, each > 0.

    Returns
    -------
    dict
        ``length``, ``mass``, ``time`` and the derived ``velocity = L/T``, ``force = M L /
        T^2``, ``inertia = M L^2``.

    Raises
    ------
    ParameterError
        ``units`` missing, or not one of the two forms, or a value outside :data:`UNIT_RANGE`.
    """
    if units is None:
        raise ParameterError(_UNITS_HINT)
    if isinstance(units, str):
        if units.lower() != "si":
            raise ParameterError(f"units={units!r}: {_UNITS_HINT}")
        units = {"length": 1.0, "mass": 1.0, "time": 1.0}
    if not isinstance(units, dict) or set(units) != {"length", "mass", "time"}:
        raise ParameterError(f"units={units!r}: {_UNITS_HINT}")
    scales = {}
    for key, value in units.items():
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"units: {key}={value!r} is not a number; {_UNITS_HINT}") from None
        if isinstance(units[key], bool) or not (math.isfinite(value) and value > 0):
            raise ParameterError(f"units: {key}={units[key]!r}: expected a finite number > 0")
        if not UNIT_RANGE[0] <= value <= UNIT_RANGE[1]:
            unit = {"length": "m", "mass": "kg", "time": "s"}[key]
            raise ParameterError(f"units: {key}={units[key]!r}: expected the SI value of one unit of the run from "
                                 f"{UNIT_RANGE[0]:g} to {UNIT_RANGE[1]:g} ({unit})")
        scales[key] = value
    L, M, T = scales["length"], scales["mass"], scales["time"]
    scales.update(velocity=L / T, force=M * L / T**2, inertia=M * L**2)
    return scales


def _sibling(data, suffix, given):
    if given is not None:
        return os.fspath(given)
    stem, extension = os.path.splitext(os.fspath(data))
    return (stem if extension == ".data" else os.fspath(data)) + suffix


def _wall_names(restart):
    """Each .restart wall's name and, for an axis-aligned InfiniteWall, its outward normal (2,)."""
    names, normals = [], []
    for index, (kind, values) in enumerate(restart.walls):
        name = f"{kind or 'wall'}{index}"
        normal = None
        q = values.get("orientation", [])
        if kind == "InfiniteWall" and len(q) == 4 and np.all(np.abs(q) <= 1 + 1e-9):  # a unit quaternion
            w, x, y, z = q
            normal = np.array([1 - 2 * (y * y + z * z), 2 * (x * y + w * z)])  # the wall's axis (1, 0, 0), rotated
            key = tuple(int(round(c)) for c in normal)
            if np.allclose(normal, key, atol=1e-9) and key in BOX_WALLS:
                normal = np.array(key, float)
                if BOX_WALLS[key] not in names:
                    name = BOX_WALLS[key]
        names.append(name)
        normals.append(normal)
    return names, normals


PERIODIC_BOUNDARIES = ("PeriodicBoundary", "LeesEdwardsBoundary")
"""The ``.restart`` boundaries that give the reader a periodic cell."""
_OTHER_PERIODIC = ("Periodic", "LeesEdwards", "Maser", "StressStrainControl", "ShearBox")
"""Parts of the names of MercuryDPM's other boundaries that repeat the sample (refused)."""


class _Cell:
    """A run's periodic cell, from its ``.restart``'s boundaries: ``periodic`` (x, y) flags,
    ``bounds`` {axis: (lo, hi)} along the periodic directions, and the tilt of each snapshot
    (a ``PeriodicBoundary``'s planewise shift, or a ``LeesEdwardsBoundary``'s shift at the
    snapshot's force computation); all in MercuryDPM's units."""

    def __init__(self, info, path):
        self.path = path
        self.periodic = [False, False]
        self.bounds = {}
        self.tilt = 0.0
        self.lees_edwards = None  # (shift, velocity, restart time, time step)
        self.described = []
        kinds = [(kind, values, line) for kind, values, line in info.boundaries
                 if kind in PERIODIC_BOUNDARIES or any(part in kind for part in _OTHER_PERIODIC)]
        if info.boundary_count > len(info.boundaries):
            raise FileFormatError(f"{path}: 'Boundaries {info.boundary_count}' lists {len(info.boundaries)} of them "
                                  "and '...' (MercuryDPM writes every boundary only when it has fewer than 9); the "
                                  "reader cannot tell whether the run is periodic")
        for kind, values, line in kinds:
            where = f"{path}: line {line}: {kind}"
            if kind == "PeriodicBoundary":
                self._periodic(values, where)
            elif kind == "LeesEdwardsBoundary":
                self._lees_edwards(values, where, info)
            else:
                raise FileFormatError(f"{where}; the reader takes a periodic cell from PeriodicBoundary and "
                                      "LeesEdwardsBoundary only")
        if self.lees_edwards is not None and len(kinds) > 1:
            raise FileFormatError(f"{path}: a LeesEdwardsBoundary and {len(kinds) - 1} other periodic "
                                  "boundar(y/ies); expected the LeesEdwardsBoundary alone (it is periodic in x and y)")
        if self.tilt != 0.0 and not self.periodic[0]:
            raise FileFormatError(f"{path}: a PeriodicBoundary in y whose images are shifted in x by {self.tilt:.10g} "
                                  "but no PeriodicBoundary in x; a shifted (tilted) cell is read only when periodic in "
                                  "x and y")

    def _number(self, values, key, where, count=1):
        numbers = values.get(key, [])
        if len(numbers) != count or not np.all(np.isfinite(numbers)):
            raise FileFormatError(f"{where}: expected '{key}' with {count} finite number(s), found "
                                  f"{' '.join(f'{v:g}' for v in numbers) or 'none'}")
        return numbers[0] if count == 1 else np.array(numbers, float)

    def _axis(self, axis, lo, hi, where):
        if self.periodic[axis]:
            raise FileFormatError(f"{where}: a second periodic boundary across {'xy'[axis]}; expected one per "
                                  "direction")
        if not hi > lo:
            raise FileFormatError(f"{where}: bounds {lo:.10g} to {hi:.10g} along {'xy'[axis]}; expected the lower "
                                  "below the upper")
        self.periodic[axis] = True
        self.bounds[axis] = (lo, hi)

    def _periodic(self, values, where):
        normal = self._number(values, "normal", where, 3)
        left, right = self._number(values, "distanceLeft", where), self._number(values, "distanceRight", where)
        shift = self._number(values, "shift", where, 3)
        axis = next((a for a in (0, 1) if np.allclose(normal, np.eye(3)[a], rtol=0, atol=1e-12)), None)
        if axis is None:
            raise FileFormatError(f"{where}: normal {' '.join(f'{v:g}' for v in normal)}; expected a cell periodic "
                                  "along x (normal 1 0 0) or y (normal 0 1 0)")
        width = right - left
        planewise = shift[1 - axis]
        if abs(shift[axis] - width) > 1e-9 * max(abs(width), 1.0) or shift[2] != 0 or (axis == 0 and planewise != 0):
            raise FileFormatError(f"{where}: shift {' '.join(f'{v:.10g}' for v in shift)} for the width {width:.10g}; "
                                  "expected the width along the normal (and, for the boundary across y only, a shift "
                                  "in x: the cell's tilt)")
        self._axis(axis, left, right, where)
        if axis == 1:
            self.tilt = planewise
        self.described.append(f"PeriodicBoundary in {'xy'[axis]} from {left:.10g} to {right:.10g}"
                              + (f" shifted by {planewise:.10g} in x" if axis == 1 and planewise else ""))

    def _lees_edwards(self, values, where, info):
        left, right, down, up, shift, velocity = (self._number(values, key, where) for key in
                                                  ("left", "right", "down", "up", "shift", "vel"))
        self._axis(0, left, right, where)
        self._axis(1, down, up, where)
        if info.time is None or info.time_step is None:
            raise FileFormatError(f"{where}: the restart has no 'timeStep dt time t' line, which gives the time its "
                                  "shift was written at")
        self.lees_edwards = (shift, velocity, info.time, info.time_step)
        self.described.append(f"LeesEdwardsBoundary x from {left:.10g} to {right:.10g}, y from {down:.10g} to "
                              f"{up:.10g}, shift {shift:.10g} + {velocity:.10g} (t - {info.time:.10g}) at the force "
                              f"computation (t - {info.time_step:.10g})")

    def box_and_tilt(self, bounds):
        """The box (xmin, ymin, xmax, ymax) of a snapshot whose ``.data`` header has ``bounds``:
        the cell's bounds along its periodic directions, the header's along the others."""
        box = np.array(bounds, float)
        for axis, (lo, hi) in self.bounds.items():
            box[axis], box[axis + 2] = lo, hi
        return box

    def tilt_at(self, time):
        """The cell's tilt at a snapshot of MercuryDPM time ``time``, within [-l/2, l/2]."""
        if self.lees_edwards is None:
            tilt = self.tilt
        else:
            shift, velocity, written, step = self.lees_edwards
            # the forces of a snapshot at t > 0 are those of the step that began at t - dt; the
            # first snapshot's (t = 0) those of MercuryDPM's initial force computation, at t
            computed = time if time <= 0 else max(time - step, 0.0)
            tilt = shift + velocity * (computed - written)
        width = self.bounds[0][1] - self.bounds[0][0] if self.periodic[0] else 0.0
        return tilt - width * np.rint(tilt / width) if width else tilt


class _Model:
    """The static part of a run: particles (from the first ``.data`` snapshot and ``.restart``),
    walls and the unit scales."""

    def __init__(self, first, restart, restart_path, data_path, scales):
        if restart.system_dimensions != 2:
            raise FileFormatError(f"{restart_path}: systemDimensions {restart.system_dimensions}; only 2D runs "
                                  "(setDimension(2)) can be read")
        if restart.particle_dimensions not in (2, 3):
            raise FileFormatError(f"{restart_path}: particleDimensions {restart.particle_dimensions}; expected 2 "
                                  "(disks) or 3 (spheres)")
        n = first.values.shape[0]
        if len(restart.particles) != n:
            raise FileFormatError(f"{restart_path}: {len(restart.particles)} particles, but {data_path} has {n} (the "
                                  "contract needs the same particles throughout)")
        radius = first.values[:, 4]
        restart_radius = np.array([p["radius"][0] for p in restart.particles])
        for values, path, rows in ((radius, data_path, lambda k: f"line {first.line + 1 + k}"),
                                   (restart_radius, restart_path, lambda k: f"particle {k}")):
            bad = ~(np.isfinite(values) & (values > 0))
            if bad.any():
                k = int(np.flatnonzero(bad)[0])
                raise FileFormatError(f"{path}: {rows(k)}: radius = {values[k]:.6g}; expected a finite radius > 0")
        if not np.allclose(restart_radius, radius, rtol=1e-8, atol=0):
            k = int(np.argmax(np.abs(restart_radius - radius)))
            raise FileFormatError(f"{restart_path}: particle {k} has radius {restart_radius[k]:.10g} but "
                                  f"{radius[k]:.10g} in {data_path} (not the same run?)")
        inv_mass = np.array([p["invMass"][0] for p in restart.particles])
        if not (np.all(radius > 0) and np.all(inv_mass > 0)):
            raise FileFormatError(f"{restart_path}: radii and masses must be > 0 (a fixed particle has invMass 0 and "
                                  "cannot be held by the contract)")
        mass = 1.0 / inv_mass
        factor = 0.5 if restart.particle_dimensions == 2 else 0.4
        self.n = n
        self.radius_raw = radius.copy()
        self.radius = radius * scales["length"]
        self.mass = mass * scales["mass"]
        self.inertia = factor * mass * radius**2 * scales["inertia"]
        self.inertia_rule = "m r^2 / 2 (particleDimensions 2)" if factor == 0.5 else \
            "2 m r^2 / 5 (particleDimensions 3)"
        self.wall_names, self.wall_axes = _wall_names(restart)
        self.scales = scales
        self.data_path = data_path
        self.limits = Limits(self.radius, scales["length"], restart_path, mass=self.mass, inertia=self.inertia)

    def name(self, k):
        """Body k's name in a message: MercuryDPM's particle index, or the wall's index and name."""
        return f"particle {k}" if k < self.n else f"wall {k - self.n} ({self.wall_names[k - self.n]})"


def _particles(model, snap, where):
    values = snap.values
    line = lambda k: f"line {snap.line + 1 + k}"  # noqa: E731
    s, limits = model.scales, model.limits
    limits.check([[snap.time]], "t", "time", where, rows=lambda k: "the header", scale=s["time"])
    limits.check(values[:, 0:2], ("x", "y"), "position", where, rows=line, scale=s["length"])
    limits.check(snap.bounds.reshape(2, 2), ("x", "y"), "position", where,
                 rows=lambda k: ("the header's xmin, ymin", "the header's xmax, ymax")[k], scale=s["length"],
                 centre=np.median(values[:, 0:2], axis=0))
    limits.check(values[:, 2:4], ("vx", "vy"), "speed", where, rows=line, scale=s["velocity"])
    limits.check(values[:, 4], "r", "length", where, rows=line, scale=s["length"])
    limits.check(values[:, 5], "angleZ", "angle", where, rows=line)
    limits.check(values[:, 6], "-omegaZ", "angular_velocity", where, rows=line, scale=1 / s["time"])
    if values.shape[0] != model.n:
        raise FileFormatError(f"{where}: {values.shape[0]} particles against {model.n} in the first snapshot; the "
                              "contract needs the same particles throughout")
    if not np.allclose(values[:, 4], model.radius_raw, rtol=1e-8, atol=0):
        raise FileFormatError(f"{where}: radii changed during the run; the contract holds one radius per particle")
    s = model.scales
    position = values[:, 0:2] * s["length"]
    return dict(position=position, velocity=values[:, 2:4] * s["velocity"], angle=values[:, 5].copy(),
                angular_velocity=-values[:, 6] / s["time"])


def _wrapped(model, position, box, cell, periodic, where):
    """The centres (MercuryDPM's units) wrapped into the periodic cell; one line for a centre
    more than a particle's diameter outside MercuryDPM's rectangle along a periodic direction
    (MercuryDPM moves a particle that crossed the boundary back every step)."""
    for axis in np.flatnonzero(periodic):
        lo, hi = box[axis], box[axis + 2]
        slack = 2 * model.radius_raw
        out = (position[:, axis] < lo - slack) | (position[:, axis] > hi + slack)
        if out.any():
            k = int(np.flatnonzero(out)[0])
            raise FileFormatError(f"{where}: particle {k} at ({position[k, 0]:.10g}, {position[k, 1]:.10g}) lies outside "
                                  f"the periodic cell along {'xy'[axis]} ({lo:.10g} to {hi:.10g}) by more than its "
                                  "diameter; expected the positions MercuryDPM keeps inside its periodic boundaries")
    return wrap(position, box[:2], cell, periodic)


class OneSidedPair(FileFormatError):
    """A particle pair written on one side only in an ``.fstat`` snapshot (``count``: how many):
    the mark of a file cut while it was written, accepted in its last snapshot only (left out
    with a note)."""

    def __init__(self, message, count):
        super().__init__(message)
        self.count = count


def fstat_contacts(rows, n_particles, n_walls, where):
    """One contact per body pair from an ``.fstat`` snapshot's lines, in MercuryDPM's units.

    Parameters
    ----------
    rows : ndarray, (K, 16)
        The snapshot's contact lines (:data:`~grainview.formats.mercurydpm_text.FSTAT_COLUMNS`).
    n_particles, n_walls : int
        N and the number of walls W (a wall w is body ``N + w``).
    where : str
        The file and snapshot, for messages.

    Returns
    -------
    (dict, int)
        Arrays ``i, j`` (i < j), ``normal`` (K', 2, from i to j), ``force`` (K', 2: exerted by
        i on j), ``point`` (K', 2), ``overlap`` (K',), and the number of lines of touching pairs
        with a tensile normal force (left out), for the overlapping pairs with ``fn > 0``.

    Raises
    ------
    FileFormatError
        A body index out of range, a particle pair whose two lines disagree (force, normal,
        overlap or contact point), a pair written more than twice, and (:class:`OneSidedPair`)
        a particle pair written on one side only.
    """
    ids = rows[:, 1:3]
    if not (np.all(np.abs(ids) < 2**31) and np.all(ids == np.round(ids))):  # NaN fails both
        raise FileFormatError(f"{where}: a body index that is not an integer")
    p = rows[:, 1].astype(np.int64)
    other = rows[:, 2].astype(np.int64)
    bad = (p < 0) | (p >= n_particles) | (other >= n_particles) | (other < -n_walls)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise FileFormatError(f"{where}: a contact of bodies {p[k]} and {other[k]}, but the run has {n_particles} "
                              f"particles (0..{n_particles - 1}) and {n_walls} walls (-1..{-n_walls})")
    n = rows[:, 10:12]
    t = rows[:, 13:15]
    on_p = rows[:, 8:9] * n + rows[:, 9:10] * t  # as written; for a wall line, minus the force on P
    wall = other < 0
    body = np.where(wall, n_particles + (-other - 1), other)
    i, j = np.minimum(p, body), np.maximum(p, body)
    # exerted by i on j, and the normal from i to j: a particle line of P = j gives the force on j
    # (from i) along n from i to j; a line of P = i gives the force on i, to be negated with n; a
    # wall line (P = i) gives the force exerted by the particle on the wall along n (particle to wall)
    flip = ~wall & (p == i)
    force = np.where(flip[:, None], -on_p, on_p)
    normal = np.where(flip[:, None], -n, n)
    key = i * np.int64(n_particles + n_walls) + j
    unique, first, counts = np.unique(key, return_index=True, return_counts=True)
    if np.any(counts > 2):
        k = int(first[np.argmax(counts > 2)])
        raise FileFormatError(f"{where}: the pair {i[k]}-{j[k]} is written {counts.max()} times (expected once per "
                              "side)")
    one_sided = ~wall[first] & (counts == 1)
    if one_sided.any():
        k = int(first[np.flatnonzero(one_sided)[0]])
        raise OneSidedPair(f"{where}: the pair of particles {i[k]} and {j[k]} is written on one side only (line of "
                           f"particle {p[k]}); expected the two lines MercuryDPM writes for each particle pair (a file "
                           f"cut while being written?)", int(one_sided.sum()))
    index = np.searchsorted(unique, key)
    size = np.abs(rows[:, 6]).max(initial=0.0) + np.abs(rows[:, 3:5]).max(initial=1.0)
    same = np.isclose(force, force[first[index]], rtol=1e-6, atol=1e-9 * np.abs(force).max(initial=1.0)).all(axis=1) \
        & np.isclose(normal, normal[first[index]], rtol=0, atol=1e-6).all(axis=1)
    if not same.all():
        k = int(np.flatnonzero(~same)[0])
        raise FileFormatError(f"{where}: the two lines of the pair {i[k]}-{j[k]} disagree (force on one is not minus "
                              "the force on the other)")
    same = np.isclose(rows[:, 6], rows[first[index], 6], rtol=1e-6, atol=1e-12 * size) \
        & np.isclose(rows[:, 3:5], rows[first[index], 3:5], rtol=0, atol=1e-9 * size).all(axis=1)
    if not same.all():
        k = int(np.flatnonzero(~same)[0])
        raise FileFormatError(f"{where}: the two lines of the pair {i[k]}-{j[k]} disagree (overlap "
                              f"{rows[first[index[k]], 6]:.10g} and {rows[k, 6]:.10g}, contact points "
                              f"({rows[first[index[k]], 3]:.10g}, {rows[first[index[k]], 4]:.10g}) and "
                              f"({rows[k, 3]:.10g}, {rows[k, 4]:.10g})); expected one contact written from each side")
    keep = first
    i, j, normal, force = i[keep], j[keep], normal[keep], force[keep]
    point, overlap = rows[keep, 3:5], rows[keep, 6]
    fn = np.einsum("ij,ij->i", force, normal)
    touching = overlap > 0
    loaded = touching & (fn > 0)
    tensile = int((touching & ~loaded).sum())
    out = dict(i=i[loaded], j=j[loaded], normal=normal[loaded], force=force[loaded], point=point[loaded],
               overlap=overlap[loaded])
    return out, tensile


def _check_rows(model, position_raw, snap, where):
    """One line for an ``.fstat`` row holding a value that is not finite or is absurd."""
    rows, s, limits = snap.rows, model.scales, model.limits
    line = lambda k: f"line {snap.lines[k]}"  # noqa: E731
    limits.check(rows[:, 1:3], ("P", "I"), "number", where, rows=line)
    limits.check(rows[:, 3:5], ("cx", "cy"), "position", where, rows=line, scale=s["length"],
                 centre=np.median(position_raw, axis=0))
    limits.check(rows[:, 6:8], ("overlap", "tangential overlap"), "length", where, rows=line, scale=s["length"])
    limits.check(rows[:, 8:10], ("fn", "ft"), "force", where, rows=line, scale=s["force"])
    limits.check(rows[:, 10:16], ("nx", "ny", "nz", "tx", "ty", "tz"), "unit", where, rows=line)


def _contacts(model, position_raw, snap, where, cell=None, periodic=None):
    """The contract's contacts of an ``.fstat`` snapshot, with ``position_raw`` the centres in
    MercuryDPM's units; in a periodic ``cell`` (raw units) branches and contact points are
    minimum images."""
    s = model.scales
    _check_rows(model, position_raw, snap, where)
    rows = snap.rows
    raw, tensile = fstat_contacts(rows, model.n, len(model.wall_names), where)
    i, j, normal = raw["i"], raw["j"], raw["normal"]
    length = np.hypot(normal[:, 0], normal[:, 1])
    if np.any(np.abs(length - 1) > 1e-6):
        raise FileFormatError(f"{where}: a contact normal that is not a unit vector in the plane (a 3D run?)")
    normal = normal / length[:, None]
    force = raw["force"] * s["force"]
    tangent = np.stack([-normal[:, 1], normal[:, 0]], axis=1)
    on_wall = j >= model.n
    point_raw = raw["point"]
    centres = position_raw[np.minimum(j, model.n - 1)] - position_raw[i]
    if cell is not None:  # the images nearest particle i: of j, and of the point (computed at a ghost)
        centres = minimum_image(centres, cell, periodic)
        point_raw = position_raw[i] + minimum_image(point_raw - position_raw[i], cell, periodic)
    point = point_raw * s["length"]
    branch = np.where(on_wall[:, None], point - position_raw[i] * s["length"], centres * s["length"])
    contacts = dict(i=i.astype("i4"), j=j.astype("i4"), kind=np.ones(i.size, "i1"), normal=normal,
                    fn=np.einsum("ij,ij->i", force, normal), ft=np.einsum("ij,ij->i", force, tangent), point=point,
                    branch=branch, gap=-raw["overlap"] * s["length"])
    check_contacts(model.limits, position_raw * s["length"], contacts, where, model.name,
                   cell=None if cell is None else cell * s["length"], periodic=periodic)
    wall_force = np.zeros((len(model.wall_names), 2))
    np.add.at(wall_force, j[on_wall] - model.n, force[on_wall])
    return contacts, wall_force, tensile


def _zip(data_path, fstat_path):
    """The two files' snapshots side by side, matched by time (one line on a mismatch)."""
    data, fstat = iter_data(data_path), iter_fstat(fstat_path)
    while True:
        d, f = next(data, None), next(fstat, None)
        if d is None and f is None:
            return
        if d is None or f is None:
            longer, shorter, snap = (fstat_path, data_path, f) if d is None else (data_path, fstat_path, d)
            raise FileFormatError(f"{longer} has a snapshot at t = {snap.time:.10g} that {shorter} does not have "
                                  "(the two files must hold the same snapshots)")
        for path, snap in ((data_path, d), (fstat_path, f)):
            if not math.isfinite(snap.time):
                raise FileFormatError(f"{path}: line {snap.line}: t = {snap.time}; expected a finite time")
        if not math.isclose(d.time, f.time, rel_tol=1e-9, abs_tol=1e-12):
            raise FileFormatError(f"mismatched snapshots: {data_path} at t = {d.time:.10g} (line {d.line}), "
                                  f"{fstat_path} at t = {f.time:.10g} (line {f.line}) (the files must hold the same "
                                  "snapshots: the same saveCount)")
        yield d, f


def mercurydpm_snapshots(data, fstat=None, restart=None, *, units=None):
    """Read a MercuryDPM 2D run snapshot by snapshot, as the contract's per-snapshot arrays.

    Parameters
    ----------
    data : str or path-like
        The run's ``.data`` file.
    fstat, restart : str or path-like, optional
        Its ``.fstat`` and ``.restart`` (default: beside ``data``, with the same stem).
    units : "si" or dict
        The run's units (:func:`unit_scales`); required.

    Returns
    -------
    (static, iterator)
        ``static``: the particles' ``radius``, ``mass``, ``inertia`` (N,), ``n_walls``,
        ``wall_names``, ``wall_normal`` and ``attrs``; the iterator yields one dict per snapshot
        with ``time`` (s), ``position``, ``velocity`` (N, 2), ``angle``, ``angular_velocity``
        (N,), ``contacts``, ``box_min``, ``box_max``, ``wall_force`` (with walls) and
        ``tensile`` (the lines left out for a tensile normal force); a periodic run's static
        part holds ``periodic`` (2,) and each snapshot its ``cell`` (2, 2).

    Raises
    ------
    FileFormatError, ParameterError
        One line: missing units, a missing or truncated file, a 3D run, particles that differ
        between the files or the snapshots, snapshots that differ between ``.data`` and
        ``.fstat``, a body index out of range, a pair whose two lines disagree.
    """
    scales = unit_scales(units)
    data_path = os.fspath(data)
    fstat_path, restart_path = _sibling(data, ".fstat", fstat), _sibling(data, ".restart", restart)
    info = read_restart(restart_path)
    cell_of = _Cell(info, restart_path)
    periodic = np.array(cell_of.periodic) if any(cell_of.periodic) else None
    stream = _zip(data_path, fstat_path)
    first = next(stream, None)
    if first is None:
        raise FileFormatError(f"{data_path}: no snapshot (an empty file)")
    model = _Model(first[0], info, restart_path, data_path, scales)
    wall_normal = None
    if model.wall_names and all(axis is not None for axis in model.wall_axes):
        wall_normal = -np.array(model.wall_axes)  # into the sample
    attrs = {"source": "MercuryDPM", "mercurydpm_data": os.path.basename(data_path),
             "mercurydpm_fstat": os.path.basename(fstat_path), "mercurydpm_restart": os.path.basename(restart_path),
             "mercurydpm_units": f"1 length unit = {scales['length']:.10g} m, 1 mass unit = {scales['mass']:.10g} kg, "
                                 f"1 time unit = {scales['time']:.10g} s",
             "mercurydpm_particle_dimensions": info.particle_dimensions, "mercurydpm_inertia": model.inertia_rule,
             "thickness_m": scales["length"],
             "mercurydpm_contact_rule": "overlapping pairs with a compressive normal force, one per pair"}
    if info.version:
        attrs["mercurydpm_version"] = info.version
    static = dict(radius=model.radius, mass=model.mass, inertia=model.inertia, n_walls=len(model.wall_names),
                  wall_names=list(model.wall_names) or None, wall_normal=wall_normal, attrs=attrs)
    if periodic is not None:
        if wall_normal is not None and np.any(np.abs(wall_normal[:, periodic]) > 0):
            k = int(np.flatnonzero(np.any(np.abs(wall_normal[:, periodic]) > 0, axis=1))[0])
            raise FileFormatError(f"{restart_path}: wall {k} ({model.wall_names[k]}) stands across a periodic "
                                  "direction; expected walls only across the directions that are not periodic")
        static["periodic"] = periodic.astype("i1")
        attrs["cell_positions"] = "wrapped"
        attrs["mercurydpm_cell"] = "; ".join(cell_of.described)

    def snapshots():
        current = first
        while current is not None:
            d, f = current
            following = next(stream, None)  # read ahead: is this the last snapshot?
            where = f"{fstat_path}: t = {f.time:.10g} (line {f.line})"
            where_data = f"{data_path}: t = {d.time:.10g} (line {d.line})"
            state = _particles(model, d, where_data)
            position_raw, cell, bounds = d.values[:, 0:2], None, d.bounds
            if periodic is not None:
                bounds = cell_of.box_and_tilt(d.bounds)
                cell = restricted_cell(bounds[:2], bounds[2:], cell_of.tilt_at(d.time))
                position_raw = _wrapped(model, position_raw, bounds, cell, periodic, where_data)
                state["position"] = position_raw * scales["length"]
            try:
                contacts, wall_force, tensile = _contacts(model, position_raw, f, where, cell, periodic)
            except OneSidedPair as exc:
                if following is not None or current is first:  # not the last snapshot, or the only one
                    raise
                warnings.warn(f"{fstat_path}: its last snapshot (t = {f.time:.10g}, line {f.line}) has {exc.count} "
                              "particle pair(s) written on one side only, the mark of a file cut while it was "
                              "written: that snapshot is left out", UserWarning, stacklevel=2)
                return
            box = bounds * scales["length"]
            snap = dict(time=d.time * scales["time"], contacts=contacts, box_min=box[:2].copy(),
                        box_max=box[2:].copy(), tensile=tensile, **state)
            if cell is not None:
                snap["cell"] = cell * scales["length"]
            if model.wall_names:
                snap["wall_force"] = wall_force
            yield snap
            current = following

    return static, snapshots()


def _warn_tensile(count, snapshots):
    if count:
        warnings.warn(f"{count} touching pair(s) over {snapshots} snapshot(s) had a tensile normal force (viscous "
                      "damping as they separate) and were left out of the contacts", UserWarning, stacklevel=3)


def open_mercurydpm(data, fstat=None, restart=None, *, units=None, progress=False):
    """A MercuryDPM 2D run as an in-memory dataset of the contract.

    Arguments as :func:`mercurydpm_snapshots`; ``progress`` shows a progress bar. For a run
    too large for memory, :func:`convert_mercurydpm` writes a file snapshot by snapshot.

    Returns
    -------
    xarray.Dataset
        A dataset of the contract (docs/schema.md; the conversion's rules: docs/formats.md)
        with ``velocity``, ``angular_velocity``, ``gap`` and, with walls, ``wall_force``.
    """
    from .convert import snapshots_dataset

    static, stream = mercurydpm_snapshots(data, fstat, restart, units=units)
    if progress:
        from tqdm.auto import tqdm

        stream = tqdm(stream, desc="mercurydpm", unit=" snapshots")
    snaps = list(stream)
    _warn_tensile(sum(s["tensile"] for s in snaps), len(snaps))
    walls = ("wall_force",) if static["n_walls"] else ()
    return snapshots_dataset(static, snaps, ("velocity", "angular_velocity", *walls),
                             wall_normal=static["wall_normal"])


def parse_units(text):
    """``--units si`` or ``--units length=L,mass=M,time=T`` of ``grainview convert
    mercurydpm`` as the reader's ``units``."""
    if text.strip().lower() == "si":
        return "si"
    try:
        return {key.strip(): float(value) for key, value in (item.split("=", 1) for item in text.split(","))}
    except ValueError:
        raise ParameterError(f"--units {text}: expected si or length=L,mass=M,time=T (the SI value of one unit of "
                             "the run: m, kg, s)") from None


def convert_mercurydpm(out, data, fstat=None, restart=None, *, units=None, overwrite=False, compress=True,
                       progress=False):
    """Convert a MercuryDPM 2D run into a file of the contract, snapshot by snapshot.

    The ``.data`` and ``.fstat`` files are read one snapshot at a time and each snapshot is
    appended as it is read, so a run of any length converts in the memory of one snapshot. The
    file is written under a hidden temporary name, validated, compressed (unless
    ``compress=False``) and only then moved to ``out``: bad input anywhere leaves nothing.

    Parameters
    ----------
    out : str or path-like
        The netCDF file to write; an existing one is refused unless ``overwrite``.
    data, fstat, restart, units
        As :func:`mercurydpm_snapshots`.
    overwrite, compress, progress : bool
        Replace an existing ``out``; compress the finished file; show a progress bar.

    Returns
    -------
    int
        The number of snapshots written.

    Raises
    ------
    FileExistsError
        ``out`` exists and ``overwrite`` is False (checked before any work).
    FileFormatError, ParameterError, SchemaError
        Bad input (one line); nothing is written.
    """
    from .convert import check_out, write_snapshots

    inputs = (os.fspath(data), _sibling(data, ".fstat", fstat), _sibling(data, ".restart", restart))
    out = check_out(out, overwrite, inputs)
    static, stream = mercurydpm_snapshots(data, fstat, restart, units=units)
    optional = ("gap", "velocity", "angular_velocity") + (("wall_force",) if static["n_walls"] else ())
    tensile = []

    def prepare(snap):
        tensile.append(snap.pop("tensile"))
        return snap

    count = write_snapshots(out, static, stream, optional, overwrite=overwrite, compress=compress, progress=progress,
                            label="mercurydpm", prepare=prepare, inputs=inputs)
    _warn_tensile(sum(tensile), count)
    return count
