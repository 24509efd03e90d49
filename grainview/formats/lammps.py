"""LAMMPS 2D granular runs as datasets of the grainview contract.

A 2D granular LAMMPS run (``dimension 2``, ``atom_style sphere``, a granular pair style) gives
its particles and its contacts in two text dumps, and optionally its wall contacts in a third:

* **particles**: a ``dump custom`` with columns (found by name) ``id``, ``radius``, ``mass``,
  ``x``, ``y`` (or the unwrapped ``xu``, ``yu`` of a periodic run, or the scaled ``xs ys``,
  ``xsu ysu``), and optionally ``vx``, ``vy``, ``omegaz``;
* **contacts**: a ``dump local`` of ``compute property/local patom1 patom2`` and
  ``compute pair/local fx fy fz p1 p2 p3``: one row per neighbour pair, with the force on
  ``patom1`` from ``patom2``. For the granular pair styles ``fx, fy, fz`` is only the central
  (normal) part of that force, and ``p1, p2, p3`` its tangential part (the pair styles'
  ``single()`` puts the tangential force there), so the force is ``(fx + p1, fy + p2)``.
  LAMMPS names these columns ``c_ID[k]``; which is which is read from the run's log (the compute
  definitions), from names given by ``dump_modify colname`` (``patom1``, ``patom2``, ``fx``,
  ``fy``, ``p1``, ``p2``), or from an explicit mapping;
* **walls** (optional): a ``dump custom`` of the per-atom arrays of ``fix wall/gran ...
  contacts`` (columns ``f_ID[1]`` to ``f_ID[8]``: touching flag, force on the particle, contact
  point, radius), for plane walls (``xplane``, ``yplane``).

How the contract's quantities are made (docs/formats.md states the same for users):

* Particles are numbered by increasing LAMMPS id; the same particles must be in every snapshot.
* A pair is a contact when its disks overlap (``r_i + r_j > |x_j - x_i|``) and its normal
  force is compressive (``fn > 0``); the neighbour list's other pairs are dropped, and so are
  touching pairs pulled together by viscous damping as they separate (counted in the
  ``tensile`` entry of each snapshot, reported by :func:`open_lammps` and the converter). Bodies ``i < j``; ``normal`` is the unit
  vector from the centre of i to the centre of j; the force exerted by i on j is minus the force
  on ``patom1`` when ``patom1`` is i (Newton's third law), the force itself otherwise;
  ``fn = f . n``, ``ft = f . t`` with ``t = (-n_y, n_x)``; ``branch = x_j - x_i``; ``point`` is
  the middle of the overlap, ``x_i + (r_i - delta/2) n``; ``gap = -delta``.
* A wall contact joins particle i to wall body ``N + w`` (walls ``bottom, right, top, left``,
  told apart by the direction from the particle to the contact point); ``normal`` points from
  the particle to the wall, ``branch`` is from the centre to the contact point, and the force
  exerted by the particle on the wall is minus the force the fix reports on the particle.
* ``time = step x time step``; the box is each snapshot's ``BOX BOUNDS`` (x and y; a
  triclinic header's bounding box undone, :mod:`grainview.formats.lammps_dump`), except where
  the log defines a plane ``fix wall/gran`` of the walls dump: there the box's side is the
  wall, where it stands at that step (moved by the fix's ``wiggle``,
  ``lo + A - A cos(2 pi (step - step0) dt / P)``, step0 the step the fix was defined at), and
  every contact point of that wall must lie on it; with all four walls known, ``wall_position``.
  A wall the log does not place (``fix wall/gran/region``, or no log) stands where its contact
  points lie in the snapshots where particles touch it (a note names those it leaves at the
  ``BOX BOUNDS`` in others);
* **periodic** boxes (``boundary p ...`` in x and/or y) give the contract's cell
  (:mod:`grainview.contract.cell`): ``a = (l, 0)``, ``b = (xy, h)`` with ``xy`` the triclinic
  tilt (``change_box all triclinic``, ``fix deform ... xy ... remap v``, box flips included:
  each snapshot's own tilt is taken), ``periodic`` the flags of x and y; separations of centres
  are minimum images, so ``branch``, ``normal``, overlap and ``point`` (which may lie outside
  the cell) are those of the nearest images; positions ``x y`` are wrapped into the cell
  (LAMMPS wraps atoms only when it rebuilds its neighbour lists; the contact points move with
  them), ``xu yu`` are kept unwrapped (``cell_positions``). A tilt is read only in a cell
  periodic in x and y, no wall may stand across a periodic direction, and ``xz = yz = 0``;
  ``inertia = m r^2 / 2`` for disks (``fix nve/sphere ... disc``; ``2 m r^2 / 5`` when the log
  shows ``nve/sphere`` without ``disc``).
* LAMMPS's 2D forces are taken as forces per unit thickness: ``thickness_m = 1``, so stresses
  come out in N/m = Pa over a 1 m slab.

Every function checks its input first and refuses bad input in one line
(:class:`grainview.contract.errors.FileFormatError` or :class:`~grainview.contract.errors.ParameterError`).

A value that is not finite or is absurd (:mod:`grainview.formats.checks`) in a column the
reader reads is refused naming the dump, the step, the line and the column; so is a snapshot
with more or fewer rows than its count. The pairs left out for a tensile normal force are
counted in one warning.
"""

from __future__ import annotations

import math
import os
import re
import warnings

import numpy as np

from ..contract.cell import fractional, minimum_image, restricted_cell, wrap
from ..contract.errors import FileFormatError, ParameterError
from .checks import Limits, check_contacts, check_step
from .lammps_dump import LammpsLog, iter_dump, read_log

__all__ = ["lammps_snapshots", "open_lammps", "convert_lammps", "WALL_NAMES", "PARTICLE_COLUMNS", "PAIR_COLUMNS"]

WALL_NAMES = ("bottom", "right", "top", "left")
"""The walls a wall contact can belong to, in the contract's order (bodies N .. N+3)."""
_WALL_DIRECTIONS = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
"""Direction from a particle to each wall of :data:`WALL_NAMES`."""

PARTICLE_COLUMNS = {"required": ("id", "radius", "mass", "x", "y"), "optional": ("vx", "vy", "omegaz"),
                    "unwrapped": ("xu", "yu"), "scaled": ("xs", "ys"), "scaled_unwrapped": ("xsu", "ysu")}
"""Columns of the particles' ``dump custom``, by LAMMPS's own names; ``xu yu`` (unwrapped
positions of a periodic run), or the scaled ``xs ys`` and ``xsu ysu`` (the positions in the
box's own coordinates, ``x = xlo + xs l + ys xy``, ``y = ylo + ys h``) may stand for ``x y``."""
_UNWRAPPED = (PARTICLE_COLUMNS["unwrapped"], PARTICLE_COLUMNS["scaled_unwrapped"])
_SCALED = (PARTICLE_COLUMNS["scaled"], PARTICLE_COLUMNS["scaled_unwrapped"])
PAIR_COLUMNS = ("patom1", "patom2", "fx", "fy", "p1", "p2")
"""Quantities the reader needs from the pairs' ``dump local``: the atom ids, and the force on
``patom1`` from ``patom2`` as LAMMPS's granular pair styles give it, a central part ``fx, fy``
and a tangential part ``p1, p2``."""
_PAIR_KEYWORDS = {"property/local": ("patom1", "patom2"), "pair/local": ("fx", "fy", "p1", "p2")}
_WALL_ARRAY = 8  # flag, fx, fy, fz, x, y, z, radius: fix wall/gran's per-atom contacts array
_INDEXED = re.compile(r"^c_([^\[\]]+)(?:\[(\d+)\])?$")


def pair_columns(columns, log: LammpsLog | None = None, mapping: dict | None = None, source="contacts") -> dict:
    """Which column of a pairs' ``dump local`` holds each of :data:`PAIR_COLUMNS`.

    In order: the explicit ``mapping`` (quantity -> column name); a column named after the
    quantity itself (``dump_modify colname``); a column ``c_ID[k]`` (or ``c_ID``) whose compute
    ``ID`` the log defines as ``property/local`` or ``pair/local`` with that quantity as its
    k-th keyword.

    Returns
    -------
    dict
        quantity -> column index.

    Raises
    ------
    ParameterError
        A mapped column that the dump does not have, or a quantity found nowhere (naming it,
        with the dump's columns and what would resolve it).
    """
    columns = tuple(columns)
    mapping = dict(mapping or {})
    unknown = set(mapping) - set(PAIR_COLUMNS)
    if unknown:
        raise ParameterError(f"columns: unknown quantity {sorted(unknown)[0]!r}; expected some of "
                             f"{', '.join(PAIR_COLUMNS)}")
    found = {}
    for quantity, name in mapping.items():
        if name not in columns:
            raise ParameterError(f"{source}: column {name!r} (given for {quantity}) is not in the dump's columns "
                                 f"{' '.join(columns)}")
        found[quantity] = columns.index(name)
    for quantity in PAIR_COLUMNS:
        if quantity not in found and quantity in columns:
            found[quantity] = columns.index(quantity)
    if log is not None:
        for index, name in enumerate(columns):
            match = _INDEXED.match(name)
            if match is None or match.group(1) not in log.computes:
                continue
            style, keywords = log.computes[match.group(1)]
            k = int(match.group(2) or 1) - 1
            if style in _PAIR_KEYWORDS and k < len(keywords) and keywords[k] in _PAIR_KEYWORDS[style]:
                found.setdefault(keywords[k], index)
    missing = [q for q in PAIR_COLUMNS if q not in found]
    if missing:
        hint = ("dump them (compute property/local patom1 patom2; compute pair/local fx fy fz p1 p2 p3, p1 p2 "
                "being the tangential force of granular pair styles) or map them (columns={'patom1': 'c_ID[1]', "
                "...}; --columns patom1=c_ID[1],...)" if log is not None
                else "give the run's LAMMPS log (log=..., --log), which defines the computes, or map them")
        raise ParameterError(f"{source}: cannot tell which column holds {', '.join(missing)} among "
                             f"{' '.join(columns)}: {hint}")
    return found


def _position_columns(columns):
    """The position columns of a particles' dump: ``x y`` (wrapped into a periodic cell by
    LAMMPS), else ``xu yu`` (unwrapped), else the scaled ``xs ys`` or ``xsu ysu``, else None."""
    for pair in (("x", "y"), *_UNWRAPPED, PARTICLE_COLUMNS["scaled"]):
        if all(name in columns for name in pair):
            return pair
    return None


def _check_particle_columns(snap, source):
    missing = [c for c in PARTICLE_COLUMNS["required"][:3] if c not in snap.columns]
    if _position_columns(snap.columns) is None:
        missing += ["x", "y"]
    if missing:
        raise FileFormatError(f"{source}: step {snap.timestep}: no column {', '.join(missing)} (has "
                              f"{' '.join(snap.columns)}); dump custom needs id radius mass x y (or xu yu, xs ys, "
                              "xsu ysu)")
    _check_ids(snap.column("id"), "id", f"{source}: step {snap.timestep}", snap)


def _lines(snap):
    """Row k of a snapshot named by its line in the dump."""
    return lambda k: f"line {snap.line + k}"


def _check_ids(values, name, where, snap):
    """Atom ids: positive integers (a float column holds them exactly up to 2**53)."""
    bad = ~(np.isfinite(values) & (values >= 1) & (values <= 2**53) & (values == np.round(values)))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise FileFormatError(f"{where}: line {snap.line + k}: {name} = {values[k]:.6g}; expected an atom id, an "
                              "integer >= 1")


def _wall_fixes(columns, source):
    """Fix ID -> the indices of its 8 columns ``f_ID[1..8]`` in a walls dump."""
    fixes = {}
    for index, name in enumerate(columns):
        match = re.match(r"^f_([^\[\]]+)\[(\d+)\]$", name)
        if match:
            fixes.setdefault(match.group(1), {})[int(match.group(2))] = index
    if "id" not in columns or not fixes:
        raise FileFormatError(f"{source}: expected columns id and f_ID[1] .. f_ID[8] of fix wall/gran ... contacts, "
                              f"found {' '.join(columns)}")
    out = {}
    for fix, found in fixes.items():
        if sorted(found) != list(range(1, _WALL_ARRAY + 1)):
            raise FileFormatError(f"{source}: fix {fix}: expected its {_WALL_ARRAY} columns f_{fix}[1] .. "
                                  f"f_{fix}[{_WALL_ARRAY}] (fix wall/gran ... contacts), found "
                                  f"{len(found)}")
        out[fix] = [found[k] for k in range(1, _WALL_ARRAY + 1)]
    return out


def _inertia_factor(inertia, log):
    """The factor k of I = k m r^2."""
    if inertia == "disc":
        return 0.5, "disc: m r^2 / 2"
    if inertia == "sphere":
        return 0.4, "sphere: 2 m r^2 / 5"
    if inertia != "auto":
        raise ParameterError(f"inertia={inertia!r}: expected 'auto', 'disc' or 'sphere'")
    if log is not None:
        for style, args in log.fixes.values():
            if style.startswith("nve/sphere"):
                return (0.5, "disc: m r^2 / 2 (fix nve/sphere ... disc)") if "disc" in args else \
                    (0.4, "sphere: 2 m r^2 / 5 (fix nve/sphere without disc)")
    return 0.5, "disc: m r^2 / 2 (assumed: no fix nve/sphere in a log)"


class _Particles:
    """The static data of the particles, from the first snapshot, and their index by id."""

    def __init__(self, snap, source, inertia_factor):
        _check_particle_columns(snap, source)
        if snap.data.shape[0] == 0:
            raise FileFormatError(f"{source}: step {snap.timestep}: no atoms (NUMBER OF ATOMS 0); expected the "
                                  "particles of the run in every snapshot")
        ids = snap.column("id").astype(np.int64)
        self.order = np.argsort(ids, kind="stable")
        self.ids = ids[self.order]
        if np.any(np.diff(self.ids) == 0):
            raise FileFormatError(f"{source}: step {snap.timestep}: an atom id appears twice")
        where = f"{source}: step {snap.timestep}"
        for name in ("radius", "mass"):
            values = snap.column(name)
            bad = ~(np.isfinite(values) & (values > 0))
            if bad.any():
                k = int(np.flatnonzero(bad)[0])
                raise FileFormatError(f"{where}: line {snap.line + k}: {name} = {values[k]:.6g}; radii and masses "
                                      "must be finite and > 0 (atom_style sphere, dump custom ... radius mass)")
        self.radius = snap.column("radius")[self.order].copy()
        self.mass = snap.column("mass")[self.order].copy()
        self.inertia = inertia_factor * self.mass * self.radius**2
        self.limits = Limits(self.radius, 1.0, where, mass=self.mass, inertia=self.inertia)
        self.source = source
        self.xy = _position_columns(snap.columns)

    def name(self, k):
        """Particle k's name in a message: its LAMMPS atom id."""
        return f"atom {self.ids[k]}" if k < self.ids.size else "a wall"

    def index(self, ids, where):
        """Particle indices of LAMMPS atom ids; one line naming an unknown id."""
        ids = np.asarray(ids).astype(np.int64)
        k = np.searchsorted(self.ids, ids)
        bad = (k >= self.ids.size) | (self.ids[np.minimum(k, self.ids.size - 1)] != ids)
        if bad.any():
            raise FileFormatError(f"{where}: atom id {ids[bad][0]} is not among the particles of {self.source}")
        return k

    def state(self, snap):
        """Positions (N, 2) and the optional velocities of a snapshot, in particle order; one
        line for a value that is not finite or is absurd (:mod:`grainview.formats.checks`)."""
        _check_particle_columns(snap, self.source)
        ids = snap.column("id").astype(np.int64)
        order = np.argsort(ids, kind="stable")
        if ids.size != self.ids.size or np.any(ids[order] != self.ids):
            raise FileFormatError(f"{self.source}: step {snap.timestep}: the atoms differ from the first snapshot's "
                                  f"({ids.size} against {self.ids.size}); the contract needs the same particles "
                                  "throughout")
        where = f"{self.source}: step {snap.timestep}"
        self.limits.check(snap.column("radius"), "radius", "length", where, rows=_lines(snap))
        self.limits.check(snap.column("mass"), "mass", "number", where, rows=_lines(snap))
        if _position_columns(snap.columns) != self.xy:
            raise FileFormatError(f"{where}: positions in columns {' '.join(_position_columns(snap.columns))}, the "
                                  f"first snapshot's in {' '.join(self.xy)}; expected the same columns throughout")
        self.limits.check(snap.data[:, [snap.columns.index(self.xy[0]), snap.columns.index(self.xy[1])]], self.xy,
                          "number" if self.xy in _SCALED else "position", where, rows=_lines(snap))
        kinds = {"vx": "speed", "vy": "speed", "omegaz": "angular_velocity"}
        for name in PARTICLE_COLUMNS["optional"]:
            if name in snap.columns:
                self.limits.check(snap.column(name), name, kinds[name], where, rows=_lines(snap))
        radius = snap.column("radius")[order]
        if not np.allclose(radius, self.radius, rtol=1e-12, atol=0):
            raise FileFormatError(f"{self.source}: step {snap.timestep}: radii changed during the run; the "
                                  "contract holds one radius per particle")
        if not np.allclose(snap.column("mass")[order], self.mass, rtol=1e-12, atol=0):
            raise FileFormatError(f"{self.source}: step {snap.timestep}: masses changed during the run; the "
                                  "contract holds one mass per particle")
        position = np.stack([snap.column(self.xy[0])[order], snap.column(self.xy[1])[order]], axis=1)
        if self.xy in _SCALED:  # the box's own coordinates: x = xlo + xs l + ys xy, y = ylo + ys h
            (xlo, xhi), (ylo, yhi) = snap.bounds[0], snap.bounds[1]
            xs, ys = position[:, 0], position[:, 1]
            position = np.stack([xlo + xs * (xhi - xlo) + ys * snap.tilt[0], ylo + ys * (yhi - ylo)], axis=1)
            self.limits.check(position, ("x from " + self.xy[0], "y from " + self.xy[1]), "position", where,
                              rows=lambda k: f"atom {self.ids[k]}")
        extra = {}
        if "vx" in snap.columns and "vy" in snap.columns:
            extra["velocity"] = np.stack([snap.column("vx")[order], snap.column("vy")[order]], axis=1)
        if "omegaz" in snap.columns:
            extra["angular_velocity"] = snap.column("omegaz")[order].copy()
        return position, extra


def _pair_contacts(particles, position, snap, columns, where, cell=None, periodic=None):
    """Contract contacts (dict of arrays) of the touching, compressed pairs of one pairs
    snapshot, the number of touching pairs left out for a tensile normal force, and the number
    of pairs that do not touch but carry a force (left out). In a periodic cell (``cell``,
    ``periodic``) the separation of two centres is its minimum image."""
    for name in ("patom1", "patom2"):
        _check_ids(snap.data[:, columns[name]], name, where, snap)
    for name in ("fx", "fy", "p1", "p2"):
        particles.limits.check(snap.data[:, columns[name]], name, "force", where, rows=_lines(snap))
    a = particles.index(snap.data[:, columns["patom1"]], where)
    b = particles.index(snap.data[:, columns["patom2"]], where)
    force = np.stack([snap.data[:, columns["fx"]] + snap.data[:, columns["p1"]],
                      snap.data[:, columns["fy"]] + snap.data[:, columns["p2"]]], axis=1)  # on a, from b
    if np.any(a == b):
        k = int(np.flatnonzero(a == b)[0])
        raise FileFormatError(f"{where}: line {snap.line + k}: a pair of atom {particles.ids[a[k]]} with itself; "
                              "expected pairs of two atoms")
    radius = particles.radius
    d = _separation(position[b] - position[a], cell, periodic)
    overlap = radius[a] + radius[b] - np.hypot(d[:, 0], d[:, 1])
    touching = overlap > 0
    apart = int(np.count_nonzero(~touching & np.any(force != 0, axis=1)))
    a, b, force, overlap = a[touching], b[touching], force[touching], overlap[touching]
    i, j = np.minimum(a, b), np.maximum(a, b)
    on_j = np.where((a == i)[:, None], -force, force)  # exerted by i on j
    # a pair listed twice (newton off across processors) is one contact
    key = i * np.int64(particles.ids.size) + j
    unique, first = np.unique(key, return_index=True)
    if unique.size != key.size:
        same = np.isclose(on_j, on_j[first[np.searchsorted(unique, key)]], rtol=1e-9, atol=0).all(axis=1)
        if not same.all():
            k = np.flatnonzero(~same)[0]
            raise FileFormatError(f"{where}: pair {particles.ids[i[k]]}-{particles.ids[j[k]]} is listed twice "
                                  "with different forces")
        i, j, on_j, overlap = i[first], j[first], on_j[first], overlap[first]
    check_contacts(particles.limits, position, dict(i=i, j=j, gap=-overlap), where, particles.name, cell=cell,
                   periodic=periodic)
    branch = _separation(position[j] - position[i], cell, periodic)
    n = branch / np.hypot(branch[:, 0], branch[:, 1])[:, None]
    fn = np.einsum("ij,ij->i", on_j, n)
    loaded = fn > 0
    i, j, on_j, overlap, branch, n, fn = (x[loaded] for x in (i, j, on_j, overlap, branch, n, fn))
    t = np.stack([-n[:, 1], n[:, 0]], axis=1)
    point = position[i] + n * (radius[i] - overlap / 2)[:, None]
    contacts = dict(i=i, j=j, kind=np.ones(i.size, "i1"), normal=n, fn=fn, ft=np.einsum("ij,ij->i", on_j, t),
                    point=point, branch=branch, gap=-overlap)
    return contacts, int((~loaded).sum()), apart


def _separation(d, cell, periodic):
    """``d`` itself, or its minimum image in a periodic cell."""
    if cell is None or periodic is None or not np.any(periodic):
        return d
    return minimum_image(d, cell, periodic)


def _wall_contacts(particles, position, snap, fixes, where, periodic=(False, False), walls_at=None):
    """Contract contacts of one walls snapshot (fix wall/gran ... contacts arrays).

    ``periodic``: the directions x, y along which the cell repeats (no wall may stand across
    them); ``walls_at``: wall index -> its coordinate (x of left and right, y of bottom and
    top) where the run's log defines it, against which every contact point is checked.

    Returns the contacts (None without any), the number left out for a tensile normal force,
    and wall index -> (fix ID, the coordinates of its contact points across the wall)."""
    n_particles = particles.ids.size
    _check_ids(snap.column("id"), "id", where, snap)
    for fix, cols in fixes.items():
        names = [f"f_{fix}[{k}]" for k in range(1, _WALL_ARRAY + 1)]
        values = snap.data[:, cols]
        limits = particles.limits
        limits.check(values[:, 1:4], names[1:4], "force", where, rows=_lines(snap))
        limits.check(values, names, "number", where, rows=_lines(snap))
        touching = np.flatnonzero(values[:, 0] != 0)
        limits.check(values[touching][:, 4:7], names[4:7], "position", where,
                     rows=lambda k, touching=touching: f"line {snap.line + touching[k]}",
                     centre=np.r_[np.median(position, axis=0), 0.0])
    index = particles.index(snap.column("id"), where)
    if np.unique(index).size != index.size:
        ids = np.sort(snap.column("id").astype(np.int64))
        twice = ids[np.flatnonzero(np.diff(ids) == 0)[0]]
        raise FileFormatError(f"{where}: atom id {twice} appears twice; expected each atom once")
    out = {k: [] for k in ("i", "j", "normal", "fn", "ft", "point", "branch", "gap")}
    tensile = 0
    seen = {}
    for fix, cols in fixes.items():
        values = snap.data[:, cols]
        touching = values[:, 0] != 0
        if not touching.any():
            continue
        p = index[touching]
        on_particle = values[touching][:, 1:3]
        point = values[touching][:, 4:6]
        arm = point - position[p]
        length = np.hypot(arm[:, 0], arm[:, 1])
        if np.any(length == 0):
            raise FileFormatError(f"{where}: fix {fix}: a wall contact point at a particle centre")
        check_contacts(particles.limits, position, dict(i=p, j=np.full(p.size, n_particles), point=point, branch=arm,
                                                        gap=length - particles.radius[p]), where,
                       lambda k, fix=fix: particles.name(k) if k < n_particles else f"the wall of fix {fix}")
        n = arm / length[:, None]
        wall = np.argmax(n[:, :1] * _WALL_DIRECTIONS[:, 0] + n[:, 1:] * _WALL_DIRECTIONS[:, 1], axis=1)
        if not np.allclose(n, _WALL_DIRECTIONS[wall], atol=1e-6):
            raise FileFormatError(f"{where}: fix {fix}: a wall that is not an x or y plane (only fix wall/gran "
                                  "xplane and yplane walls can be read)")
        n = _WALL_DIRECTIONS[wall]
        normal_axis = 1 - wall % 2  # the coordinate a wall bounds: y for bottom and top, x for right and left
        across = np.flatnonzero(np.asarray(periodic, bool)[normal_axis])
        if across.size:
            k = int(across[0])
            raise FileFormatError(f"{where}: fix {fix}: atom {particles.ids[p[k]]} touches the {WALL_NAMES[wall[k]]} "
                                  f"wall, across {'xy'[normal_axis[k]]}, a periodic direction; expected walls only "
                                  "across directions that are not periodic (LAMMPS refuses a wall in a periodic "
                                  "dimension)")
        for w in np.unique(wall):
            seen.setdefault(int(w), (fix, []))[1].append(point[wall == w, 1 - w % 2])
        if walls_at:
            for w, at in walls_at.items():
                on = wall == w
                axis = 1 - w % 2
                off = np.abs(point[on, axis] - at) > 1e-9 * max(particles.limits.diameter, abs(at))
                if off.any():
                    k = int(np.flatnonzero(on)[np.flatnonzero(off)[0]])
                    raise FileFormatError(
                        f"{where}: fix {fix}: atom {particles.ids[p[k]]} touches the {WALL_NAMES[w]} wall at "
                        f"{'xy'[axis]} = {point[k, axis]:.17g}, but the log's definition of the wall puts it at "
                        f"{'xy'[axis]} = {at:.17g} at this step; expected the wall the log describes (a wall moved "
                        "otherwise than by the fix's wiggle, e.g. fix wall/gran/region, cannot be placed)")
        on_wall = -on_particle
        loaded = np.einsum("ij,ij->i", on_wall, n) > 0
        tensile += int((~loaded).sum())
        p, n, wall, on_wall, point, arm, length = (x[loaded] for x in (p, n, wall, on_wall, point, arm, length))
        t = np.stack([-n[:, 1], n[:, 0]], axis=1)
        out["i"].append(p)
        out["j"].append(n_particles + wall)
        out["normal"].append(n)
        out["fn"].append(np.einsum("ij,ij->i", on_wall, n))
        out["ft"].append(np.einsum("ij,ij->i", on_wall, t))
        out["point"].append(point)
        out["branch"].append(arm)
        out["gap"].append(length - particles.radius[p])
    seen = {w: (fix, np.concatenate(at)) for w, (fix, at) in seen.items()}
    if not out["i"]:
        return None, tensile, seen
    joined = {k: np.concatenate(v) for k, v in out.items()}
    joined["kind"] = np.ones(joined["i"].size, "i1")
    return joined, tensile, seen


def _walls_touched(seen, walls_at, where, diameter):
    """Wall index -> coordinate of the walls the log does not place but particles touch in this
    snapshot: where their contact points lie (LAMMPS reports the point on the wall's plane).
    One line when a wall's points are not on one line across it."""
    out = {}
    for w, (fix, at) in seen.items():
        if w in walls_at:
            continue
        low, high = float(at.min()), float(at.max())
        if high - low > 1e-9 * max(diameter, abs(high)):
            raise FileFormatError(f"{where}: fix {fix}: the contact points of the {WALL_NAMES[w]} wall lie from "
                                  f"{'yxyx'[w]} = {low:.17g} to {high:.17g}; expected a plane wall, its points on one "
                                  "line")
        out[w] = float(np.median(at))
    return out


def _check_box(particles, position, snap, source, box_min, box_max, cell=None, periodic=(False, False),
               unwrapped=False, walls=False):
    """One line for a particle whose centre lies outside the sample by more than the largest
    diameter (LAMMPS lets atoms stray a little beyond a fixed boundary, and beyond a periodic
    cell's edge, between two rebuilds of its neighbour lists). Along a bounded direction the
    sample is ``box_min .. box_max`` (the box, or the region between the walls: the volume of
    the solid fraction and the stresses); along a periodic one the cell, in its own coordinates
    (a tilted cell's edges are tilted), unless the positions are ``unwrapped`` (``xu yu``)."""
    margin = particles.limits.diameter
    for axis, name in enumerate("xy"):
        low, high = box_min[axis], box_max[axis]
        if not low <= high:  # not a box at all: the contract's check of the finished run says so
            continue
        if periodic[axis]:
            if unwrapped:
                continue
            st = fractional(position - box_min, cell)[:, axis]
            outside = (st < -margin / (high - low)) | (st > 1 + margin / (high - low))
            if outside.any():
                k = int(np.flatnonzero(outside)[0])
                raise FileFormatError(
                    f"{source}: step {snap.timestep}: atom {particles.ids[k]} at ({position[k, 0]:.6g}, "
                    f"{position[k, 1]:.6g}) lies outside the periodic cell along {name} by more than a particle "
                    f"diameter (cell coordinate {st[k]:.6g}, expected 0 to 1); expected positions wrapped into the "
                    "cell (dump custom ... x y), or unwrapped ones named xu yu")
            continue
        outside = (position[:, axis] < low - margin) | (position[:, axis] > high + margin)
        if outside.any():
            k = int(np.flatnonzero(outside)[0])
            if walls:
                raise FileFormatError(f"{source}: step {snap.timestep}: atom {particles.ids[k]} at {name} = "
                                      f"{position[k, axis]:.6g} lies outside the region between the walls, {name} = "
                                      f"{low:.6g} .. {high:.6g} (where the log's fix wall/gran puts them at this "
                                      "step); expected the particles between the walls, the volume of the solid "
                                      "fraction and the stresses")
            raise FileFormatError(f"{source}: step {snap.timestep}: atom {particles.ids[k]} at {name} = "
                                  f"{position[k, axis]:.6g} lies outside the box's {name} range {low:.6g} .. "
                                  f"{high:.6g} (ITEM: BOX BOUNDS); expected the particles inside the box, the volume "
                                  "of the solid fraction and the stresses")


_PLANES = {"xplane": (0, 3, 1), "yplane": (1, 0, 2)}
"""A plane wall style -> (the coordinate it bounds, the wall index of its lo and of its hi plane)."""


def _wall_planes(log, fixes, periodic, source):
    """What the log says of the plane walls of the walls dump's fixes: fix ID -> (axis, lo,
    hi, wiggle, defined at step), ``lo``/``hi`` None where the fix sets it NULL, ``wiggle``
    (amplitude, period) when the fix moves its planes along their own axis (``wiggle``), else
    None. A fix the log does not define, or not a plane of ``fix wall/gran``, is left out; one
    that stands across a periodic direction is refused."""
    planes = {}
    if log is None or not fixes:
        return planes
    for fix in fixes:
        style, args = log.fixes.get(fix, (None, ()))
        if style != "wall/gran":
            continue
        found = [k for k, word in enumerate(args) if word in _PLANES]
        if not found or found[0] + 2 >= len(args):
            continue
        k = found[0]
        axis = _PLANES[args[k]][0]
        if periodic[axis]:
            raise FileFormatError(f"{source}: fix {fix} is a wall/gran {args[k]}, a wall across {'xy'[axis]}, but the "
                                  f"box is periodic in {'xy'[axis]}; expected walls only across directions that are "
                                  "not periodic")
        try:
            lo, hi = (None if args[k + m] == "NULL" else float(args[k + m]) for m in (1, 2))
        except ValueError:  # a position the log does not give as a number
            continue
        wiggle = None
        rest = list(args[k + 3:])
        if "wiggle" in rest:
            w = rest.index("wiggle")
            try:
                if rest[w + 1] == "xy"[axis]:
                    wiggle = (float(rest[w + 2]), float(rest[w + 3]))
            except (IndexError, ValueError):
                continue
        planes[fix] = (axis, lo, hi, wiggle, log.fix_steps.get(fix, 0))
    return planes


def _walls_at(planes, step, time_step):
    """Wall index -> its coordinate at ``step``, from :func:`_wall_planes`: a plane at ``lo``
    (``hi``), moved by a wiggle of amplitude A and period P as LAMMPS's fix wall/gran moves it,
    ``lo + A - A cos(2 pi / P (step - step0) dt)``, step0 the step the fix was defined at."""
    out = {}
    for axis, lo, hi, wiggle, step0 in planes.values():
        _, lo_wall, hi_wall = _PLANES[("xplane", "yplane")[axis]]
        for value, index in ((lo, lo_wall), (hi, hi_wall)):
            if value is None:
                continue
            if wiggle is not None:
                amplitude, period = wiggle
                arg = 2.0 * math.pi / period * (step - step0) * time_step
                value = value + amplitude - amplitude * math.cos(arg)
            out[index] = value
    return out


def _box(snap, boundary, periodic, source):
    """``box_min``, ``box_max`` (x, y) and the tilt ``xy`` of a particles' snapshot; one line
    for a boundary that changed since the first snapshot, a tilt in 2D that LAMMPS's 2D runs do
    not have (``xz``, ``yz``), or an ``xy`` tilt of a cell not periodic in both x and y."""
    where = f"{source}: step {snap.timestep}"
    if tuple(snap.boundary) != boundary:
        raise FileFormatError(f"{where}: boundary {' '.join(snap.boundary)}, the first snapshot's "
                              f"{' '.join(boundary)}; expected the same boundaries throughout")
    xy, xz, yz = (float(t) for t in snap.tilt)
    if xz != 0 or yz != 0:
        raise FileFormatError(f"{where}: a triclinic box with tilts xz = {xz:.6g}, yz = {yz:.6g}; a 2D run has "
                              "only xy (LAMMPS keeps xz = yz = 0 in 2D)")
    if xy != 0 and not all(periodic):
        raise FileFormatError(f"{where}: a triclinic box with tilt xy = {xy:.6g} but boundary "
                              f"{' '.join(boundary)}; expected a tilt only in a cell periodic in both x and y (a tilt "
                              "across walls has no sample region)")
    return snap.bounds[:2, 0].copy(), snap.bounds[:2, 1].copy(), xy


def _between_walls(walls_at, box_min, box_max, boundary) -> bool:
    """Move the sides of the box (``box_min``, ``box_max``, in place) to the walls of
    ``walls_at`` (wall index -> coordinate): a wall replaces the box's side where it lies within
    the box (LAMMPS's fixed boundaries hold every atom, so a wall that holds them stands inside
    the box or on its edge), or where that side is shrink-wrapped (``s``, ``m``: the box follows
    the atoms, the wall holds them). A wall outside a fixed box holds nothing and is left out;
    a box that is not one (lo above hi) is left to the contract's check. Returns whether a
    side moved."""
    moved = False
    for index, at in walls_at.items():
        axis, side = 1 - index % 2, (0 if index in (0, 3) else 1)
        low, high = box_min[axis], box_max[axis]
        if not low < high:
            continue
        slack = 1e-9 * (high - low)
        if boundary[axis][side] in "sm" or low - slack <= at <= high + slack:
            (box_min if side == 0 else box_max)[axis] = at
            moved = True
    return moved


def _wall_points(walls_at, box_min, box_max):
    """A point of each wall line (bottom, right, top, left): the wall's coordinate and the
    middle of the sample along the wall."""
    middle = (np.asarray(box_min) + np.asarray(box_max)) / 2
    return np.array([[middle[0], walls_at[0]], [walls_at[1], middle[1]], [middle[0], walls_at[2]],
                     [walls_at[3], middle[1]]])


def _join(pairs, walls):
    if walls is None:
        return pairs
    return {k: np.concatenate([pairs[k], walls[k]]) for k in pairs}


def _zip_dumps(particles_path, contacts_path, walls_path):
    """The three dumps' snapshots side by side, matched by step (one line on a mismatch)."""
    streams = [iter_dump(particles_path), iter_dump(contacts_path)]
    if walls_path is not None:
        streams.append(iter_dump(walls_path))
    names = [os.fspath(p) for p in (particles_path, contacts_path, walls_path) if p is not None]
    while True:
        snaps = [next(s, None) for s in streams]
        if all(s is None for s in snaps):
            return
        if any(s is None for s in snaps):
            longer = [n for n, s in zip(names, snaps) if s is not None]
            step = next(s.timestep for s in snaps if s is not None)
            shorter = [n for n, s in zip(names, snaps) if s is None]
            raise FileFormatError(f"{longer[0]} has a snapshot at step {step} that {shorter[0]} does not have "
                                  "(the dumps must hold the same steps)")
        steps = [s.timestep for s in snaps]
        if len(set(steps)) > 1:
            raise FileFormatError(f"mismatched steps: {names[0]} at step {steps[0]}, "
                                  + ", ".join(f"{n} at step {s}" for n, s in zip(names[1:], steps[1:]))
                                  + " (the dumps must hold the same steps, e.g. the same dump interval)")
        yield snaps


def lammps_snapshots(particles, contacts, walls=None, *, log=None, time_step=None, columns=None,
                     inertia="auto"):
    """Read a LAMMPS run snapshot by snapshot, as the contract's per-snapshot arrays.

    Parameters
    ----------
    particles : str or path-like
        The particles' ``dump custom`` (columns ``id radius mass x y`` and optionally
        ``vx vy omegaz``).
    contacts : str or path-like
        The pairs' ``dump local`` (``compute property/local patom1 patom2`` and
        ``compute pair/local fx fy fz p1 p2 p3``).
    walls : str or path-like, optional
        A ``dump custom`` of ``id`` and the arrays ``f_ID[1..8]`` of ``fix wall/gran ...
        contacts`` (plane walls).
    log : str or path-like, optional
        The run's ``log.lammps`` (or input script): the time step, the computes' definitions,
        and the walls' fixes (where the walls stand, and how they move: the sample's box).
    time_step : float, optional
        The time step, s (overrides the log's).
    columns : dict, optional
        quantity -> column name for the pairs' dump (:func:`pair_columns`).
    inertia : {"auto", "disc", "sphere"}
        Moments of inertia: ``m r^2 / 2``, ``2 m r^2 / 5``, or what the log's
        ``fix nve/sphere`` says (``disc`` when there is no log).

    Returns
    -------
    (static, iterator)
        ``static``: a dict of the particles' ``radius``, ``mass``, ``inertia`` (arrays, (N,)),
        ``n_walls``, ``wall_names`` and ``attrs`` (the conversion's provenance); the iterator
        yields one dict per snapshot with ``time`` (s), ``position`` (N, 2), ``angle`` (N,),
        ``contacts`` (dict of contract contact arrays), ``box_min``, ``box_max`` (2,) and,
        when the dump has them, ``velocity`` and ``angular_velocity``; a periodic run's static
        part holds ``periodic`` (2,) and each snapshot its ``cell`` (2, 2); a run whose four
        walls the log places, ``wall_position`` (4, 2). The static part is read
        from the first snapshot at once; the iterator reads the rest one snapshot at a time.

    Raises
    ------
    FileFormatError, ParameterError
        One line naming what is wrong: a file that is not a LAMMPS dump, a truncated dump, a
        missing column, steps that differ between the dumps, unknown atom ids, a time step
        known from neither ``time_step`` nor the log.
    """
    log_info = read_log(log) if log is not None else None
    if log_info is not None and log_info.units is None:
        raise ParameterError(f"{os.fspath(log)}: no 'units' command, so the run is in LAMMPS's default units, lj "
                             "(reduced units); only runs in SI units (units si) can be read")
    if log_info is not None and log_info.units != "si":
        raise ParameterError(f"{os.fspath(log)}: the run is in LAMMPS units {log_info.units!r}; only runs in SI units "
                             "(units si) can be read")
    if time_step is None and log_info is not None:
        time_step = log_info.time_step
    if time_step is None:
        raise ParameterError("the time step is unknown: give it (time_step=..., --time-step) or the run's LAMMPS "
                             "log (log=..., --log)")
    if isinstance(time_step, bool) or not np.isfinite(float(time_step)) or float(time_step) <= 0:
        raise ParameterError(f"time_step={time_step!r}: expected a time step > 0 in s")
    time_step = float(time_step)
    factor, inertia_rule = _inertia_factor(inertia, log_info)
    stream = _zip_dumps(particles, contacts, walls)
    first = next(stream, None)
    if first is None:
        raise FileFormatError(f"{os.fspath(particles)}: no snapshot (an empty dump)")
    source = os.fspath(particles)
    static_particles = _Particles(first[0], source, factor)
    pair_index = pair_columns(first[1].columns, log_info, columns, source=os.fspath(contacts))
    fixes = _wall_fixes(first[2].columns, os.fspath(walls)) if walls is not None else None
    boundary = tuple(first[0].boundary)
    periodic = tuple(flag.startswith("p") for flag in boundary[:2])
    unwrapped = static_particles.xy in _UNWRAPPED
    planes = _wall_planes(log_info, fixes, periodic, os.fspath(log) if log is not None else source)
    attrs = {"source": "LAMMPS", "lammps_particles": os.path.basename(os.fspath(particles)),
             "lammps_contacts": os.path.basename(os.fspath(contacts)), "lammps_time_step_s": time_step,
             "lammps_inertia": inertia_rule, "thickness_m": 1.0,
             "lammps_contact_rule": "pairs that overlap with a compressive normal force"}
    if walls is not None:
        attrs["lammps_walls"] = os.path.basename(os.fspath(walls))
    if log_info is not None and log_info.version:
        attrs["lammps_version"] = log_info.version
    attrs["lammps_boundary"] = " ".join(boundary)
    if walls is not None:
        attrs["lammps_sample_box"] = (("between the walls of " + ", ".join(f"fix {fix}" for fix in planes)
                                       + " where the log places them (moved by wiggle where it does), " if planes
                                       else "")
                                      + "between the other walls where particles touch them, elsewhere the dump's "
                                        "BOX BOUNDS")
    static = dict(radius=static_particles.radius, mass=static_particles.mass, inertia=static_particles.inertia,
                  n_walls=len(WALL_NAMES) if walls is not None else 0,
                  wall_names=list(WALL_NAMES) if walls is not None else None, attrs=attrs)
    static["deforming"] = log_info is not None and any(style.split("/")[0] == "deform"  # deform, deform/pressure
                                                       for style, _ in log_info.fixes.values())
    if any(periodic):
        static["periodic"] = np.array(periodic, "i1")
        attrs["cell_positions"] = "unwrapped" if unwrapped else "wrapped"

    def snapshots():
        from .convert import chain_first

        for snaps in chain_first(first, stream):
            part, pairs = snaps[0], snaps[1]
            where = f"{os.fspath(contacts)}: step {part.timestep}"
            check_step(part.timestep, source)
            position, extra = static_particles.state(part)
            static_particles.limits.check(part.bounds[:2].T, ("x", "y"), "position", f"{source}: step {part.timestep}",
                                          rows=lambda k: ("the lower", "the upper")[k] + " BOX BOUNDS",
                                          centre=np.median(position, axis=0))
            box_min, box_max, tilt = _box(part, boundary, periodic, source)
            cell = restricted_cell(box_min, box_max, tilt) if any(periodic) else None
            _check_box(static_particles, position, part, source, box_min, box_max, cell, periodic, unwrapped)
            # minimum images along the periodic directions, which the walls (across the others) leave unchanged
            contacts_now, tensile, apart = _pair_contacts(static_particles, position, pairs, pair_index, where, cell,
                                                          periodic)
            logged = _walls_at(planes, part.timestep, time_step)
            walls_at, touched, on_walls, tensile_walls = logged, {}, None, 0
            if fixes is not None:
                where_walls = f"{os.fspath(walls)}: step {part.timestep}"
                on_walls, tensile_walls, seen = _wall_contacts(static_particles, position, snaps[2], fixes,
                                                               where_walls, periodic, walls_at)
                touched = _walls_touched(seen, walls_at, where_walls, static_particles.limits.diameter)
                walls_at = {**walls_at, **touched}
            bounds = (box_min.copy(), box_max.copy())
            if _between_walls(walls_at, box_min, box_max, boundary):  # the region between the walls
                cell = restricted_cell(box_min, box_max, tilt) if any(periodic) else None
                _check_box(static_particles, position, part, source, box_min, box_max, cell, periodic, unwrapped,
                           walls=True)
            if fixes is not None:
                contacts_now, tensile = _join(contacts_now, on_walls), tensile + tensile_walls
            if cell is not None and not unwrapped:  # wrapped into the cell: LAMMPS wraps only at re-neighbouring
                moved = wrap(position, box_min, cell, periodic)
                contacts_now["point"] = contacts_now["point"] + (moved - position)[contacts_now["i"]]
                position = moved
            snapshot = dict(time=part.timestep * time_step, step=part.timestep, tensile=tensile, apart=apart,
                            touched=_touched_moved(touched, bounds, box_min, box_max),
                            position=position, angle=np.zeros(position.shape[0]), contacts=contacts_now,
                            box_min=box_min, box_max=box_max, **extra)
            if cell is not None:
                snapshot["cell"] = cell
            if fixes is not None and len(logged) == len(WALL_NAMES):  # the same in every snapshot
                snapshot["wall_position"] = _wall_points(logged, box_min, box_max)
            yield snapshot

    return static, snapshots()


def open_lammps(particles, contacts, walls=None, *, log=None, time_step=None, columns=None, inertia="auto",
                progress=False):
    """A LAMMPS 2D granular run as an in-memory dataset of the contract.

    Arguments as :func:`lammps_snapshots`; ``progress`` shows a progress bar over the
    snapshots. For a run too large for memory, :func:`convert_lammps` writes a file snapshot by
    snapshot instead.

    Returns
    -------
    xarray.Dataset
        A dataset of the contract (docs/schema.md; the conversion's rules: docs/formats.md),
        with ``velocity`` and ``angular_velocity`` when the particles' dump has them, and
        ``step``.
    """
    from .convert import snapshots_dataset

    static, stream = lammps_snapshots(particles, contacts, walls, log=log, time_step=time_step, columns=columns,
                                      inertia=inertia)
    if progress:
        from tqdm.auto import tqdm

        stream = tqdm(stream, desc="lammps", unit=" snapshots")
    snaps = list(stream)
    _warn_left_out(sum(s.pop("tensile") for s in snaps), sum(s.pop("apart") for s in snaps), len(snaps),
                   static["deforming"])
    _warn_touched([s.pop("touched") for s in snaps], static)
    _warn_no_log(log)
    return snapshots_dataset(static, snaps, ("step", "velocity", "angular_velocity", "wall_position"))


def _warn_left_out(tensile, apart, snapshots, deforming=False):
    """One note per kind of pair left out of the contacts (``deforming``: the log has a fix
    deform, whose dumps are a step's deformation ahead of the forces)."""
    if tensile:
        warnings.warn(f"{tensile} touching pair(s) over {snapshots} snapshot(s) had a tensile normal force (viscous "
                      "damping as they separate) and were left out of the contacts", UserWarning, stacklevel=3)
    if apart:
        warnings.warn(f"{apart} pair(s) over {snapshots} snapshot(s) whose disks do not overlap at the dumped "
                      "positions carried a force and were left out of the contacts (LAMMPS's granular pair styles "
                      "give no force to pairs that do not touch: positions dumped with too few digits? dump_modify "
                      "format float %.17g" + ("; or the run's fix deform, which changes the box (and, with remap x, "
                                              "the positions) after the forces and before the dumps of each step"
                                              if deforming else "") + ")", UserWarning, stacklevel=3)


def _touched_moved(touched, bounds, box_min, box_max):
    """(the walls placed by their contact points, those of them that moved the box's side off
    the dump's BOX BOUNDS)."""
    moved = [w for w in touched if (box_min if w in (0, 3) else box_max)[1 - w % 2]
             != (bounds[0] if w in (0, 3) else bounds[1])[1 - w % 2]]
    return set(touched), set(moved)


def _warn_touched(touched, static):
    """One note naming the walls placed by their contact points (the log does not place them)
    that moved the sample's side off the dump's BOX BOUNDS in some snapshots and touched nothing
    in others, where the side is the BOX BOUNDS."""
    moved = set().union(*(m for _, m in touched)) if touched else set()
    counts = {w: sum(w in t for t, _ in touched) for w in moved}
    partial = [f"{WALL_NAMES[w]} ({n} of {len(touched)})" for w, n in sorted(counts.items()) if n < len(touched)]
    if partial:
        warnings.warn(f"{static['attrs']['lammps_particles']}: walls the log does not place (fix wall/gran/region, or "
                      f"no log) are placed where particles touch them: {', '.join(partial)} snapshot(s); in the "
                      "others the sample's side is the dump's BOX BOUNDS (give the log of a fix wall/gran, whose "
                      "walls it places at every step)", UserWarning, stacklevel=3)


def _warn_no_log(log):
    if log is None:
        warnings.warn("no LAMMPS log given: the run is taken to be in SI units (units si), which only its log can "
                      "confirm (log=..., --log)", UserWarning, stacklevel=3)


def parse_columns(text):
    """``--columns QUANTITY=COLUMN,...`` of ``grainview convert lammps`` as ``columns``
    (None for none given)."""
    if not text:
        return None
    try:
        return dict(item.split("=", 1) for item in text.split(","))
    except ValueError:
        raise ParameterError(f"--columns {text}: expected QUANTITY=COLUMN,... (e.g. "
                             "patom1=c_pairs[1],patom2=c_pairs[2])") from None


def convert_lammps(out, particles, contacts, walls=None, *, log=None, time_step=None, columns=None, inertia="auto",
                   overwrite=False, compress=True, progress=False):
    """Convert a LAMMPS 2D granular run into a file of the contract, snapshot by snapshot.

    The dumps are read one snapshot at a time and each snapshot is appended to the file as it
    is read (:class:`grainview.contract.writer.SnapshotWriter`), so a run of any length converts in the
    memory of one snapshot. The file is written under a hidden temporary name, validated,
    compressed (unless ``compress=False``) and only then moved to ``out``: bad input anywhere
    in the dumps leaves nothing behind.

    Parameters
    ----------
    out : str or path-like
        The netCDF file to write; an existing one is refused unless ``overwrite``.
    particles, contacts, walls, log, time_step, columns, inertia
        As :func:`lammps_snapshots`.
    overwrite : bool, default False
        Replace an existing ``out``.
    compress : bool, default True
        Write the finished file compressed (docs/schema.md, "Compression").
    progress : bool, default False
        Show a progress bar over the snapshots.

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
    from .convert import chain_first, check_out, write_snapshots

    out = check_out(out, overwrite, inputs=[path for path in (particles, contacts, walls, log) if path is not None])
    static, stream = lammps_snapshots(particles, contacts, walls, log=log, time_step=time_step, columns=columns,
                                      inertia=inertia)
    first = next(stream)
    optional = ("step", "gap") + tuple(name for name in ("velocity", "angular_velocity", "wall_position")
                                       if name in first)
    tensile, apart, touched = [], [], []

    def prepare(snap):
        tensile.append(snap.pop("tensile"))
        apart.append(snap.pop("apart"))
        touched.append(snap.pop("touched"))
        return snap

    count = write_snapshots(out, static, chain_first(first, stream), optional, overwrite=overwrite,
                            compress=compress, progress=progress, label="lammps", prepare=prepare,
                            inputs=[path for path in (particles, contacts, walls, log) if path is not None])
    _warn_left_out(sum(tensile), sum(apart), count, static["deforming"])
    _warn_touched(touched, static)
    _warn_no_log(log)
    return count
