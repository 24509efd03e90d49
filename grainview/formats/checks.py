"""What every reader accepts: paths that are what they should be, and numbers that are finite and
physically plausible.

A reader refuses, in one line naming the file, the row and the quantity, any value that is not
a finite number or whose size no granular sample could have. "Absurd" is decided here, once,
in SI units (the contract's, docs/schema.md), from the sample's own particles:

* a **coordinate** (a position, a contact point, a wall or box bound) lies within
  :data:`LENGTH_SPAN` particle diameters (the largest particle's) of the sample's middle (the
  median of its particles' positions), and a **length** (a branch, an overlap, a displacement,
  a radius) is at most that many diameters;
* a **force** is at most what a stress of :data:`STRESS_LIMIT_PA` (well beyond the strength
  of any material) exerts on the largest particle's diameter times the slab's thickness; the
  total force on a wall at most that many times the number of particles;
* a **speed** is below that of light, and so is the rim speed of a turning particle;
* a **time** is at most :data:`TIME_LIMIT_S`, a run's **gravity** at most
  :data:`ACCELERATION_LIMIT_M_S2`, an **angle** at most :data:`ANGLE_LIMIT_RAD`, a
  component of a unit vector (a normal) at most 1 (within :data:`UNIT_TOLERANCE`);
* the particles' **radii** are finite and > 0, the largest at most :data:`SIZE_RATIO` times the
  smallest, and their **masses** finite and > 0, of a density (mass over the disk's area times
  the thickness) at most :data:`DENSITY_LIMIT_KG_M3`;
* a **contact** is possible for its bodies' positions and sizes (:func:`check_contacts`): two
  particles' centres are at most ``r_i + r_j`` apart, an overlap is shallower than a radius, a
  gap is not open, and the contact point lies on both bodies, each to within
  :data:`CONTACT_TOLERANCE` of the smaller radius (a polygon's radius is its circumscribed
  one).

Readers check their raw columns with :meth:`Limits.check`, where they still know the line a
value came from, and their contacts with :func:`check_contacts`, where they still know the file
and the bodies' own names; :func:`check_snapshot` checks every snapshot once more before it is
written or returned (:mod:`grainview.formats.convert`), so that nothing absurd or impossible is
ever stored.
"""

from __future__ import annotations

import errno
import os

import numpy as np

from ..contract.errors import FileFormatError
from ..contract.schema import MAX_STEP_INDEX

__all__ = ["Limits", "check_snapshot", "check_contacts", "check_step", "input_file", "input_folder", "LENGTH_SPAN",
           "STRESS_LIMIT_PA", "SPEED_LIMIT_M_S", "TIME_LIMIT_S", "ACCELERATION_LIMIT_M_S2", "ANGLE_LIMIT_RAD",
           "UNIT_TOLERANCE", "SIZE_RATIO", "DENSITY_LIMIT_KG_M3", "CONTACT_TOLERANCE"]

LENGTH_SPAN = 1e6
"""Particle diameters (the largest particle's) a coordinate may lie from the sample's middle,
and a length may measure: a 2D packing a million diameters across holds 10^12 particles."""
STRESS_LIMIT_PA = 1e12
"""Pa: ten times the compressive strength of diamond. A contact force is at most this stress
on the largest particle's diameter times the slab's thickness."""
SPEED_LIMIT_M_S = 299_792_458.0
"""m/s: the speed of light, above which no particle moves (nor a particle's rim turns)."""
TIME_LIMIT_S = 1e18
"""s: about twice the age of the universe."""
ACCELERATION_LIMIT_M_S2 = 1e13
"""m/s^2: beyond the gravity at a neutron star's surface (a run's gravity)."""
ANGLE_LIMIT_RAD = 1e12
"""rad: beyond it a float64 holds a particle's orientation to worse than 1e-4 rad."""
SIZE_RATIO = 1e6
"""The largest radius over the smallest."""
DENSITY_LIMIT_KG_M3 = 1e6
"""kg/m^3: about 40 times the densest element's; a particle's mass over its disk's area
times the slab's thickness is at most this."""

UNIT_TOLERANCE = 1e-6
"""How far beyond 1 a component of a unit vector may be (the files' rounding)."""
CONTACT_TOLERANCE = 0.5
"""How far a contact's geometry may stray from touching, in radii of the smaller of its two
bodies (of the particle, for a wall contact): the centres of two particles further apart than
``r_i + r_j`` by more, a gap open wider, or a contact point further outside a body. Real runs
stay far within it: soft contacts overlap by a hundredth of a radius, a rigid code's contact
point lies outside a polygon's circumscribed circle by about as little, and photoelastic
images, whose radii and centres are fitted to pixels, leave touching disks apart by up to a
seventh of the smaller radius."""


def _kind(path) -> str | None:
    """What ``path`` is when it is not a readable file or folder: None when it exists."""
    try:
        os.stat(path)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return "a symbolic link that loops back on itself"
        if os.path.islink(path):
            return f"a symbolic link to {os.readlink(path)}, which does not exist"
        if exc.errno == errno.ENOENT:
            return "no such file or folder"
        return f"cannot be read ({exc.strerror or exc})"
    return None


def input_file(path, what: str) -> str:
    """``path`` as a string when it is a file; else one line saying what it is instead.

    Parameters
    ----------
    path : str or path-like
        The file a reader is about to read.
    what : str
        What the file should be, for the message (``"a LAMMPS dump"``).

    Raises
    ------
    FileFormatError
        ``path`` does not exist, is a folder, a broken symbolic link, a symbolic link that loops,
        or something other than a regular file.
    """
    path = os.fspath(path)
    problem = _kind(path)
    if problem is None and os.path.isdir(path):
        problem = "a folder, not a file"
    elif problem is None and not os.path.isfile(path):
        problem = "not a regular file"
    elif problem == "no such file or folder":
        problem = "no such file"
    if problem is not None:
        raise FileFormatError(f"{path}: {problem} (expected {what})")
    return path


def input_folder(path, what: str) -> str:
    """``path`` as a string when it is a folder; else one line saying what it is instead
    (:func:`input_file`'s counterpart)."""
    path = os.fspath(path)
    problem = _kind(path)
    if problem is None and not os.path.isdir(path):
        problem = "a file, not a folder"
    elif problem == "no such file or folder":
        problem = "no such folder"
    if problem is not None:
        raise FileFormatError(f"{path}: {problem} (expected {what})")
    return path


def _row_name(rows, k: int) -> str:
    if rows is None:
        return f"row {k + 1}"
    if callable(rows):
        return rows(k)
    return str(rows[k])


class Limits:
    """The bounds of :mod:`this module <grainview.formats.checks>` for one sample.

    Parameters
    ----------
    radius : array_like, (N,)
        The particles' radii, m.
    thickness : float, default 1
        The slab's thickness, m (the contract's ``thickness_m``).
    where : str
        The file the radii come from, for the messages.
    mass : array_like, (N,), optional
        The particles' masses, kg (checked: finite, > 0, of a plausible density).
    inertia : array_like, (N,), optional
        Their moments of inertia, kg m^2 (checked: finite and > 0).
    names : callable or sequence, optional
        Particle k's name in the messages (default ``"particle k"``).
    n_vertices : array_like, (N,), optional
        The particles' vertex counts (0: a disk; default: disks), for :func:`check_contacts`.

    Raises
    ------
    FileFormatError
        A radius, mass or moment of inertia that is not finite and > 0, radii spanning more
        than :data:`SIZE_RATIO`, a mass of an impossible density.
    """

    def __init__(self, radius, thickness=1.0, where="", mass=None, inertia=None, names=None, n_vertices=None):
        radius = np.asarray(radius, float).reshape(-1)
        self.n_vertices = (np.zeros(radius.size, np.int64) if n_vertices is None else
                           np.asarray(n_vertices, np.int64).reshape(-1))
        self.where = where
        self._bounds = None
        names = names if names is not None else (lambda k: f"particle {k}")
        for name, values in (("radius", radius), ("mass", mass), ("inertia", inertia)):
            if values is None:
                continue
            values = np.asarray(values, float).reshape(-1)
            bad = ~(np.isfinite(values) & (values > 0))
            if bad.any():
                k = int(np.flatnonzero(bad)[0])
                raise FileFormatError(f"{where}: {_row_name(names, k)}: {name} = {values[k]:.6g}; expected a finite "
                                      f"{name} > 0")
        if radius.size and radius.max() > SIZE_RATIO * radius.min():
            raise FileFormatError(f"{where}: radii from {radius.min():.6g} to {radius.max():.6g} m; expected the "
                                  f"largest at most {SIZE_RATIO:g} times the smallest")
        self.thickness = float(thickness)
        self.radius = radius
        self.diameter = 2 * float(radius.max()) if radius.size else 1.0
        self.smallest = float(radius.min()) if radius.size else 0.5
        if mass is not None:
            mass = np.asarray(mass, float).reshape(-1)
            density = mass / (np.pi * radius**2 * self.thickness)
            if density.max() > DENSITY_LIMIT_KG_M3:
                k = int(np.argmax(density))
                raise FileFormatError(f"{where}: {_row_name(names, k)}: mass = {mass[k]:.6g} kg, a "
                                      f"density of {density[k]:.3g} kg/m^3 over its disk; expected at most "
                                      f"{DENSITY_LIMIT_KG_M3:g} kg/m^3")

    def bound(self, kind: str) -> tuple:
        """``(limit, expected)``: the largest magnitude of a quantity of ``kind`` in SI units, and
        the words that say so. ``kind`` is one of ``position``, ``length``, ``force``, ``speed``,
        ``angular_velocity``, ``time``, ``acceleration``, ``angle``, ``unit`` (a component of a
        unit vector) or ``number`` (finite only)."""
        if self._bounds is None:
            self._bounds = self._table()
        return self._bounds[kind]

    def _table(self) -> dict:
        length = LENGTH_SPAN * self.diameter
        force = STRESS_LIMIT_PA * self.diameter * self.thickness
        return {
            "position": (length, f"a finite coordinate within {LENGTH_SPAN:g} particle diameters ({length:.3g} m) of "
                                 "the sample's middle"),
            "length": (length, f"a finite length of at most {LENGTH_SPAN:g} particle diameters ({length:.3g} m)"),
            "force": (force, f"a finite force of at most {force:.3g} N (a stress of {STRESS_LIMIT_PA:g} Pa on the "
                             "largest particle's diameter)"),
            "speed": (SPEED_LIMIT_M_S, "a finite speed below the speed of light"),
            "angular_velocity": (SPEED_LIMIT_M_S / self.smallest,
                                 "a finite angular velocity whose rim speed is below the speed of light"),
            "time": (TIME_LIMIT_S, f"a finite time of at most {TIME_LIMIT_S:g} s"),
            "acceleration": (ACCELERATION_LIMIT_M_S2, f"a finite acceleration of at most {ACCELERATION_LIMIT_M_S2:g} "
                                                      "m/s^2"),
            "angle": (ANGLE_LIMIT_RAD, f"a finite angle of at most {ANGLE_LIMIT_RAD:g} rad"),
            "unit": (1 + UNIT_TOLERANCE, "a component of a unit vector, from -1 to 1"),
            "number": (np.inf, "a finite number"),
        }

    def check(self, values, quantity: str, kind: str, where: str, rows=None, scale=1.0, centre=None,
              limit=None) -> None:
        """Refuse the first value of ``values`` that is not finite or beyond the bound of ``kind``.

        Parameters
        ----------
        values : array_like, (K,) or (K, C)
            The values as the file holds them, one row per line or entry of the file.
        quantity : str or sequence of str
            The name of the quantity, or one name per column, for the message (``"fx"``,
            ``("x", "y")``).
        kind : str
            Which bound applies (:meth:`bound`).
        where : str
            The file and the snapshot, for the message.
        rows : callable, sequence or None
            Row k's name in the message (``rows(k)`` or ``rows[k]``: ``"line 1234"``,
            ``"body 7"``); default ``"row k+1"``.
        scale : float, default 1
            The SI value of one unit of ``values`` (a run in other units).
        centre : array_like, optional
            For ``position``: the sample's middle, in the units of ``values`` (default: the
            median of the finite rows of ``values``).
        limit : float, optional
            A bound other than :meth:`bound`'s, in SI units (the expectation's words are kept).

        Raises
        ------
        FileFormatError
            ``"<where>: <row>: <quantity> = <value>; expected <what>"``.
        """
        values = np.asarray(values, float)
        if values.size == 0:
            return
        shaped = values.reshape(values.shape[0], -1)
        bad = ~np.isfinite(shaped)
        if not bad.any():
            bound, _ = self.bound(kind)
            bound = bound if limit is None else limit
            if np.isfinite(bound):
                size = shaped
                if kind == "position":
                    middle = np.median(shaped, axis=0) if centre is None else np.asarray(centre, float).reshape(-1)
                    size = shaped - middle
                with np.errstate(over="ignore"):
                    bad = np.abs(size) * abs(scale) > bound
        if bad.any():
            k, c = (int(x[0]) for x in np.nonzero(bad))
            name = quantity if isinstance(quantity, str) else quantity[c]
            expected = self.bound(kind)[1]
            raise FileFormatError(f"{where}: {_row_name(rows, k)}: {name} = {shaped[k, c]:.6g}; expected {expected}")


_SNAPSHOT_VALUES = (("time", "time", None, 1), ("position", "position", "particle", 2),
                    ("angle", "angle", "particle", 1), ("velocity", "speed", "particle", 2),
                    ("angular_velocity", "angular_velocity", "particle", 1), ("box_min", "position", None, 2),
                    ("box_max", "position", None, 2), ("wall_position", "position", "wall", 2),
                    ("wall_velocity", "speed", "wall", 2), ("wall_force", "wall_force", "wall", 2),
                    ("cell", "length", None, 4))
"""A snapshot's values: (name, kind of bound, what a row is (None: the snapshot's one value), width)."""
_CONTACT_KINDS = {"fn": "force", "ft": "force", "point": "position", "branch": "length", "gap": "length",
                  "normal": "unit"}


def check_snapshot(limits: Limits, snap: dict, where: str, periodic=None) -> None:
    """Refuse a snapshot (the dict a reader yields for
    :meth:`grainview.contract.writer.SnapshotWriter.append`) holding a value that is not finite or
    is beyond its bound: the last check before anything is stored. In a periodic sample
    (``periodic``, the run's flags per cell vector, and the snapshot's ``cell``) the contacts are
    checked against the minimum images of the centres (:func:`check_contacts`).

    Raises
    ------
    FileFormatError
        Naming ``where``, the quantity, the particle or contact, and what was expected.
    """
    position = np.asarray(snap["position"], float)
    middle = np.median(position, axis=0) if position.size and np.isfinite(position).all() else None
    for name, kind, row, width in _SNAPSHOT_VALUES:
        if name not in snap:
            continue
        values = np.asarray(snap[name], float).reshape(-1, width)
        limit = None
        if kind == "wall_force":  # a sum over the particles touching the wall
            kind, limit = "force", limits.bound("force")[0] * max(position.shape[0], 1)
        limits.check(values, name, kind, where, rows=(lambda k: "the snapshot") if row is None else
                     (lambda k, row=row: f"{row} {k}"), centre=middle if kind == "position" else None, limit=limit)
    if "step" in snap:
        check_step(snap["step"], where)
    contacts = snap.get("contacts") or {}
    for name, kind in _CONTACT_KINDS.items():
        if name in contacts:
            limits.check(contacts[name], name, kind, where, rows=lambda k: f"contact {k}",
                         centre=middle if kind == "position" else None)
    if contacts:
        cell = snap.get("cell") if periodic is not None else None
        check_contacts(limits, position, contacts, where, cell=cell, periodic=periodic if cell is not None else None)


def check_step(step, where: str) -> None:
    """Refuse a step index the contract's ``step`` (a 32-bit integer) cannot hold.

    Raises
    ------
    FileFormatError
        ``"<where>: step = <step>; expected an integer from 0 to 2147483647 ..."``.
    """
    if not (isinstance(step, (int, np.integer)) and 0 <= int(step) <= MAX_STEP_INDEX):
        raise FileFormatError(f"{where}: step = {step}; expected an integer from 0 to {MAX_STEP_INDEX} (the contract "
                              "stores the step index as a 32-bit integer; renumber the run's steps from 0, e.g. "
                              "LAMMPS's reset_timestep, to read it)")


def _bodies(n_particles):
    """Body k's default name in a message: a particle or a wall (``N + w``)."""
    return lambda k: f"particle {k}" if k < n_particles else f"wall {k - n_particles}"


def check_contacts(limits: Limits, position, contacts: dict, where: str, names=None, cell=None,
                   periodic=None) -> None:
    """Refuse a contact that cannot exist for its bodies' positions and sizes.

    Each contact of bodies ``i < j`` (``j >= N`` a wall) must touch: the tolerance ``tol`` is
    :data:`CONTACT_TOLERANCE` times the smaller radius of the two particles (the particle's, for
    a wall contact), the radii those of ``limits`` (a polygon's circumscribed radius), and

    * two particles' centres are at most ``r_i + r_j + tol`` apart, and their ``branch`` is
      ``x_j - x_i`` to within ``tol``;
    * a wall contact's ``branch`` (from the centre to the contact point) is at most
      ``r_i + tol`` long;
    * the ``point`` is at most ``r + tol`` from the centre of each particle of the contact;
    * a ``gap`` is at most ``tol`` (a contact carrying a force is closed) and at least ``-r``
      (an overlap shallower than the smaller radius); for two disks it is ``|x_j - x_i| - r_i -
      r_j`` to within ``tol``.

    Parameters
    ----------
    limits : Limits
        The sample's bounds (its ``radius`` and ``n_vertices``).
    position : array_like, (N, 2)
        The particles' positions, m.
    contacts : dict
        The contract's contact arrays: ``i``, ``j`` and any of ``point``, ``branch``, ``gap``.
    where : str
        The file and the snapshot, for the message.
    names : callable, optional
        Body k's name in the message (default ``"particle k"``, ``"wall w"`` for ``k = N + w``).
    cell : array_like, (2, 2), optional
        A periodic sample's lattice vectors (:mod:`grainview.contract.cell`), with ``periodic``
        (2,), the cell vectors along which it repeats: particle j is then the image of j nearest
        i, ``x_i + minimum_image(x_j - x_i)``, wherever the cell's boundary lies between them
        (its ``branch`` the minimum image, its contact point near that image).

    Raises
    ------
    FileFormatError
        ``"<where>: the contact of <body> and <body>: <what is impossible>; expected ..."``.
    """
    i = np.asarray(contacts.get("i", ()), np.int64).reshape(-1)
    if i.size == 0:
        return
    j = np.asarray(contacts["j"], np.int64).reshape(-1)
    position = np.asarray(position, float).reshape(-1, 2)
    radius = limits.radius
    n = radius.size
    if i.min() < 0 or i.max() >= n or j.min() < 0 or np.any(j <= i):
        k = int(np.flatnonzero((i < 0) | (i >= n) | (j <= i))[0])
        raise FileFormatError(f"{where}: contact {k} of bodies {i[k]} and {j[k]}; expected a particle 0..{n - 1} "
                              "and a body of a higher index")
    names = names if names is not None else _bodies(n)
    pair = j < n
    jp = np.minimum(j, n - 1)
    r_i, r_j = radius[i], np.where(pair, radius[jp], np.inf)
    small = np.minimum(r_i, r_j)
    tol = CONTACT_TOLERANCE * small
    centres = position[jp] - position[i]
    if cell is not None and periodic is not None and np.any(periodic):
        from ..contract.cell import minimum_image

        centres = minimum_image(centres, np.asarray(cell, float), np.asarray(periodic).astype(bool))
    image_j = position[i] + centres  # particle j, or its image nearest i in a periodic cell
    distance = np.hypot(centres[:, 0], centres[:, 1])
    shown = f"{CONTACT_TOLERANCE:g} of the smaller radius"
    problems = []  # (mask, message of contact k)
    problems.append((pair & (distance > r_i + r_j + tol), lambda k: (
        f"the centres are {distance[k]:.6g} m apart, the radii sum to {r_i[k] + r_j[k]:.6g} m; expected bodies that "
        f"touch (centres at most the sum of the radii and {shown} apart)")))
    branch = contacts.get("branch")
    if branch is not None:
        branch = np.asarray(branch, float).reshape(-1, 2)
        off = np.hypot(*(branch - centres).T)
        length = np.hypot(branch[:, 0], branch[:, 1])
        problems.append((pair & (off > tol), lambda k: (
            f"branch = ({branch[k, 0]:.6g}, {branch[k, 1]:.6g}) m, but the centres are at ({centres[k, 0]:.6g}, "
            f"{centres[k, 1]:.6g}) m from one another; expected the branch x_j - x_i"
            + (" (its minimum image in the periodic cell)" if cell is not None else ""))))
        problems.append((~pair & (length > r_i + tol), lambda k: (
            f"the contact point is {length[k]:.6g} m from the centre of {names(i[k])}, whose radius is {r_i[k]:.6g} m; "
            f"expected a point on the particle (at most {shown} outside it)")))
    point = contacts.get("point")
    if point is not None:
        point = np.asarray(point, float).reshape(-1, 2)
        for body, centre, r, which in ((i, position[i], r_i, np.ones(i.size, bool)), (jp, image_j, r_j, pair)):
            away = np.hypot(*(point - centre).T)
            problems.append((which & (away > r + tol), lambda k, away=away, body=body, r=r: (
                f"the contact point ({point[k, 0]:.6g}, {point[k, 1]:.6g}) m is {away[k]:.6g} m from the centre of "
                f"{names(body[k])}, whose radius is {r[k]:.6g} m; expected a point on both bodies (at most {shown} "
                "outside each)")))
    gap = contacts.get("gap")
    if gap is not None:
        gap = np.asarray(gap, float).reshape(-1)
        problems.append((gap < -small, lambda k: (
            f"an overlap of {-gap[k]:.6g} m (gap {gap[k]:.6g} m), deeper than the radius {small[k]:.6g} m of "
            f"{names(i[k]) if r_i[k] <= r_j[k] else names(j[k])}; expected an overlap shallower than a radius")))
        problems.append((gap > tol, lambda k: (
            f"a gap of {gap[k]:.6g} m between bodies in contact; expected a closed contact (a gap of at most {shown}, "
            f"{tol[k]:.3g} m)")))
        disks = pair & (limits.n_vertices[i] == 0) & (limits.n_vertices[jp] == 0)
        between = distance - r_i - np.where(pair, radius[jp], 0.0)
        problems.append((disks & (np.abs(between - gap) > tol), lambda k: (
            f"gap = {gap[k]:.6g} m, but the disks' centres are {distance[k]:.6g} m apart, a gap of {between[k]:.6g} m; "
            f"expected the same gap to within {shown}")))
    for bad, message in problems:
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise FileFormatError(f"{where}: the contact of {names(i[k])} and {names(j[k])}: {message(k)}")
