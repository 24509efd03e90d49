"""LMGC90 2D rigid runs (disks, polygons, walls) as datasets of the grainview contract.

An LMGC90 run folder holds ``DATBOX/`` (the model: ``BODIES.DAT``, ``BULK_BEHAV.DAT``) and
``OUTBOX/`` (``DOF.OUT.n`` and ``Vloc_Rloc.OUT.n``, one snapshot each; the file layer is
:mod:`grainview.formats.lmgc90_text`). The reader takes RBDY2 bodies with one contactor each:
``DISKx`` (a disk), ``POLYG`` (a convex polygon) or ``JONCx`` (a wall), and the
contact families ``DKDKx``, ``DKJCx``, ``PLPLx``, ``PLJCx`` and ``DKPLx``.

How the contract's quantities are made (docs/formats.md states the same for users):

* Particles are the DISKx and POLYG bodies in the order of BODIES.DAT; the JONCx bodies are the
  walls ``N + w``. Four axis-aligned JONCx around the particles are named ``bottom, right, top,
  left`` (in that order) and their inner faces are the sample box; other walls are named
  ``jonc<number>`` in file order, and the box is then the particles' bounding box.
* ``position = reference + X(1:2)`` (DOF.OUT's displacement from BODIES.DAT's node),
  ``velocity = V(1:2)``, ``angular_velocity = V(3)``. A disk's ``angle`` is ``X(3)``.
* A POLYG lists its vertices ``u_k`` relative to the body's node in the reference frame, and
  LMGC90 puts vertex k at ``reference + X(1:2) + Rot(X(3)) u_k``. A regular one (centred on
  the node, :func:`regular_polygon`) is the contract's regular n-gon: ``angle`` is the angle of
  its first vertex in BODIES.DAT plus ``X(3)``, so that vertex k lies at
  ``angle + 2 pi k / n``; its ``radius`` is the distance of the vertices from the centre. Any
  other convex POLYG is stored by its vertices (``vertices``, :mod:`grainview.contract.shapes`):
  with ``g`` the centroid of the ``u_k`` (counter-clockwise; a clockwise list is reversed), the
  own-frame vertices are ``u_k - g``, ``angle = X(3)`` and ``position = reference + X(1:2) +
  Rot(X(3)) g`` (the centroid: LMGC90's node usually is it, to BODIES.DAT's 8 digits), so that
  ``position + Rot(angle) (u_k - g)`` is LMGC90's vertex k; ``radius`` is the farthest vertex
  from ``g``. A file with such a polygon holds the vertices of every polygon (the regular
  ones' :func:`grainview.contract.shapes.regular_vertices`). A POLYG that is not convex is
  refused.
* ``mass = density pi avrd^2`` (``density`` the bulk behaviour's ``Umas``), ``inertia = mass
  gyrd^2``; LMGC90's 2D bodies are slabs of unit thickness (``thickness_m = 1``).
* LMGC90 writes, for each candidate-antagonist entry, the unit normal ``n = (n(1), n(2))``
  pointing from the antagonist to the candidate, ``t = (n_y, -n_x)``, and the mean forces over
  the step ``rln/H``, ``rlt/H``: the force exerted on the candidate by the antagonist is
  ``rln n + rlt t``. For a contract contact of bodies ``i < j`` (a particle and a wall: ``i``
  the particle) the normal is the unit vector from ``i`` to ``j`` (``-n`` when ``i`` is the
  candidate, ``n`` otherwise), the force exerted by ``i`` on ``j`` follows by Newton's third
  law, and ``fn``, ``ft`` are its components along the normal and ``(-normal_y, normal_x)``:
  ``fn = rln`` and ``ft = -rlt`` in both cases.
* Two entries of the same body pair (two PLPLx, or two PLJCx, points of a face-to-face contact)
  are one double contact (``kind = 2``): the resultant force, applied at the mean of the two
  points weighted by their normal forces (their midpoint when both are zero). Every other pair
  is simple (``kind = 1``). A pair is written when its normal force is compressive
  (``fn > 0``); LMGC90's entries within the alert distance that carry nothing are left out.
* ``branch = x_j - x_i`` for particle pairs, the contact point minus ``x_i`` for wall contacts;
  ``gap`` is the smallest ``gapTT`` of the pair's points; ``point`` is LMGC90's contact point
  (``coo1, coo2``). ``wall_force`` is the total force exerted by the particles on each wall.
* ``time`` and ``step`` are DOF.OUT's header's.
* **Periodic runs.** LMGC90's 2D rigid runs repeat along x only, with a period set in the
  computation script (``chipy.SetPeriodicCondition(xperiod=L)``, or ``RBDY2_SetPeriodicCondition``
  with the contact families'), which no DATBOX or OUTBOX file records: the reader takes it as
  ``x_period=L``. The cell is then ``a = (L, 0)``, ``b = (0, h)``, periodic along ``a`` only
  (``periodic = (1, 0)``), from x = 0 (LMGC90 moves a body whose ``reference + X(1)`` leaves
  ``[0, L]`` by one period, every step); ``box_min``, ``box_max`` span x from 0 to L and, in y,
  the inner faces of two horizontal JONCx (named ``bottom`` and ``top``: walls across the
  periodic direction are refused) or else the particles' extent. A pair across the boundary is
  detected on the antagonist's image: ``branch`` is the minimum image of ``x_j - x_i``,
  ``point`` LMGC90's contact point moved by whole periods to its image nearest ``x_i`` (a
  wall's arm likewise); positions are wrapped into ``[0, L)`` (``cell_positions = wrapped``).
  A centre more than its diameter outside ``[0, L]`` (the wrong period) is refused.

Every function checks its input first and refuses bad input in one line
(:class:`grainview.contract.errors.FileFormatError`).

A value that is not finite or is absurd (:mod:`grainview.formats.checks`) is refused naming
the file and the body or the line of the entry, and so is a body number beyond 2^31 - 1 or an
``$icdan`` entry written twice. The pairs left out for a tensile normal force (``rln/H < 0``)
are counted in one warning.
"""

from __future__ import annotations

import math
import os
import warnings

import numpy as np

from ..contract import portable_math
from ..contract.cell import minimum_image, restricted_cell
from ..contract.errors import FileFormatError, ParameterError
from ..contract.shapes import polygon_properties, regular_vertices, shape_problems, vertex_phases
from .checks import Limits, check_contacts, check_step, input_folder
from .lmgc90_text import output_files, read_bodies, read_bulk_behav, read_dof, read_vloc_rloc

__all__ = ["lmgc90_snapshots", "open_lmgc90", "convert_lmgc90", "FAMILIES", "BOX_WALLS", "regular_polygon",
           "centred_polygon"]

FAMILIES = ("DKDKx", "DKJCx", "PLPLx", "PLJCx", "DKPLx")
"""The contact families the reader takes (candidate contactor, then antagonist)."""
BOX_WALLS = ("bottom", "right", "top", "left")
"""Names (and order) of the walls of a box of four JONCx."""
_PARTICLE_CONTACTORS = {"DISKx", "POLYG"}
_FAMILY_CONTACTORS = {"DKDKx": ("DISKx", "DISKx"), "DKJCx": ("DISKx", "JONCx"), "PLPLx": ("POLYG", "POLYG"),
                      "PLJCx": ("POLYG", "JONCx"), "DKPLx": ("DISKx", "POLYG")}
"""The contactors of each family's candidate and antagonist."""
_DOUBLE_FAMILIES = {"PLPLx", "PLJCx"}
"""The families whose pairs may have two points (a polygon's face on a face or a wall)."""
_NOT_CONVEX = "a POLYG whose vertices are not a convex polygon (the contract holds convex polygons only)"


def regular_polygon(vertices, rtol=1e-5):
    """Radius, vertex count and first-vertex angle of a regular polygon centred on the origin.

    Parameters
    ----------
    vertices : array_like, (n, 2)
        The vertices (m), in any rotational order.
    rtol : float
        Relative tolerance on the distances and the angular spacing (BODIES.DAT writes 8
        significant digits).

    Returns
    -------
    (float, int, float) or None
        ``(R, n, phi)``: vertex k at ``R (cos(phi + 2 pi k/n), sin(phi + 2 pi k/n))``; None when
        the vertices are not those of a regular polygon centred on the origin.
    """
    v = np.asarray(vertices, float)
    n = v.shape[0]
    if n < 3:
        return None
    r = np.hypot(v[:, 0], v[:, 1])
    radius = float(r.mean())
    if radius <= 0 or np.abs(r - radius).max() > rtol * radius or np.abs(v.mean(axis=0)).max() > rtol * radius:
        return None
    phi = math.atan2(v[0, 1], v[0, 0])
    offset = np.sort(np.mod(portable_math.arctan2(v[:, 1], v[:, 0]) - phi + rtol, 2 * np.pi) - rtol)
    if np.abs(offset - vertex_phases(n)).max() > rtol * 2 * np.pi:
        return None
    return radius, n, phi


def centred_polygon(vertices):
    """A convex polygon's vertices in its own frame: counter-clockwise (a clockwise list
    reversed) and shifted so that their centroid is the origin.

    Parameters
    ----------
    vertices : array_like, (n, 2)
        The vertices (m) relative to any point, in the order of the outline.

    Returns
    -------
    (ndarray, ndarray) or None
        ``(v, g)``: the (n, 2) vertices ``u_k - g`` and the centroid ``g`` (2,) of the given
        ones; None when they are not a convex polygon.
    """
    u = np.asarray(vertices, float)
    if u.ndim != 2 or u.shape[0] < 3:
        return None
    if polygon_properties(u[None])["area"][0] < 0:
        u = u[::-1]
    g = polygon_properties(u[None])["centroid"][0]
    v = u - g
    radius = float(np.hypot(v[:, 0], v[:, 1]).max())
    if shape_problems([radius], [len(v)], v[None]):
        return None
    return v, g


def _check_datbox(bodies_path, particles, walls, behav_path, density, gravity):
    """One line for a value of DATBOX that is not finite or is absurd (:mod:`grainview.formats.checks`),
    before any shape is computed from them: lengths are measured against the particles' mean
    radii ``avrd``."""
    avrd = np.array([body.avrd for body in particles])
    limits = Limits(avrd, 1.0, bodies_path, names=lambda k: f"body {particles[k].number}: avrd")
    bodies = particles + walls
    reference = np.array([body.reference for body in bodies])
    name = lambda k: f"body {bodies[k].number}"  # noqa: E731
    limits.check(reference[:, :2], ("coo1", "coo2"), "number", bodies_path, rows=name)
    limits.check(reference[:, :2], ("coo1", "coo2"), "position", bodies_path, rows=name,
                 centre=np.median(reference[:len(particles), :2], axis=0))
    limits.check(reference[:, 2], "coo3", "angle", bodies_path, rows=name)
    limits.check([body.gyrd for body in particles], "gyrd", "length", bodies_path,
                 rows=lambda k: f"body {particles[k].number}")
    for body in bodies:
        tact = body.contactors[0]
        limits.check([list(tact.values.values())], list(tact.values), "length", bodies_path,
                     rows=lambda k, body=body: f"body {body.number}: {body.contactors[0].kind}")
        limits.check(np.reshape(tact.vertices, (-1, 2)), ("coo1", "coo2"), "length", bodies_path,
                     rows=lambda k, body=body: f"body {body.number}: vertex {k + 1}")
    behaviours = list(density)
    limits.check([density[b] for b in behaviours], "Umas", "number", behav_path,
                 rows=lambda k: f"behaviour {behaviours[k]}")
    limits.check(gravity[None], ("grv1", "grv2", "grv3"), "acceleration", behav_path, rows=lambda k: "gravity")


class _Model:
    """The static part of a run, from DATBOX: particles, walls and how bodies map to them."""

    def __init__(self, datbox):
        bodies_path = os.path.join(datbox, "BODIES.DAT")
        behav_path = os.path.join(datbox, "BULK_BEHAV.DAT")
        for path in (bodies_path, behav_path):
            if not os.path.isfile(path):
                raise FileFormatError(f"{datbox}: no {os.path.basename(path)} (an LMGC90 run folder holds "
                                      "DATBOX/BODIES.DAT and DATBOX/BULK_BEHAV.DAT, and OUTBOX/)")
        bodies = read_bodies(bodies_path)
        density, self.gravity = read_bulk_behav(behav_path)
        particles, walls = [], []
        for body in bodies:
            where = f"{bodies_path}: body {body.number}"
            if body.model != "RBDY2":
                raise FileFormatError(f"{where}: a {body.model} body; only 2D rigid bodies (RBDY2) can be read")
            if len(body.contactors) != 1:
                raise FileFormatError(f"{where}: {len(body.contactors)} contactors; the contract holds one shape per "
                                      "body (DISKx, POLYG or JONCx)")
            kind = body.contactors[0].kind
            if kind in _PARTICLE_CONTACTORS:
                particles.append(body)
            elif kind == "JONCx":
                walls.append(body)
            else:
                raise FileFormatError(f"{where}: unknown contactor type {kind!r}; expected DISKx, POLYG or JONCx")
        if not particles:
            raise FileFormatError(f"{bodies_path}: no DISKx or POLYG body (no particles)")
        _check_datbox(bodies_path, particles, walls, behav_path, density, self.gravity)
        n = len(particles)
        self.radius, self.n_vertices, self.angle0 = np.zeros(n), np.zeros(n, "i4"), np.zeros(n)
        self.mass, self.inertia = np.zeros(n), np.zeros(n)
        self.offset = np.zeros((n, 2))  # the centroid of an irregular POLYG relative to its node
        own = {}  # particle -> own-frame vertices, for the irregular POLYGs
        for k, body in enumerate(particles):
            where = f"{bodies_path}: body {body.number}"
            tact = body.contactors[0]
            if tact.kind == "DISKx":
                self.radius[k] = tact.values.get("byrd", float("nan"))
            else:
                shape = regular_polygon(tact.vertices)
                if shape is not None:
                    self.radius[k], self.n_vertices[k], self.angle0[k] = shape
                else:
                    centred = centred_polygon(tact.vertices)
                    if centred is None:
                        raise FileFormatError(f"{where}: {_NOT_CONVEX}")
                    own[k], self.offset[k] = centred
                    self.radius[k], self.n_vertices[k] = np.hypot(*own[k].T).max(), len(own[k])
            if body.behav not in density:
                raise FileFormatError(f"{where}: bulk behaviour {body.behav!r} is not in {behav_path}")
            if not (self.radius[k] > 0 and body.avrd > 0 and body.gyrd > 0):
                raise FileFormatError(f"{where}: radius, avrd and gyrd must be > 0")
            self.mass[k] = density[body.behav] * math.pi * body.avrd ** 2
            self.inertia[k] = self.mass[k] * body.gyrd ** 2
        self.limits = Limits(self.radius, 1.0, bodies_path, mass=self.mass, inertia=self.inertia,
                             names=lambda k: f"body {particles[k].number}", n_vertices=self.n_vertices)
        self.contactor = {int(body.number): body.contactors[0].kind for body in particles + walls}
        self.vertices = None  # regular polygons only
        if own:
            self.vertices = np.full((n, int(self.n_vertices.max()), 2), np.nan)
            for k in np.flatnonzero(self.n_vertices >= 3):
                count = int(self.n_vertices[k])
                self.vertices[k, :count] = own[k] if k in own else regular_vertices(self.radius[k], count)
        self.reference = np.array([body.reference[:2] for body in particles])
        self.numbers = np.array([body.number for body in particles], np.int64)
        self.kinds = [body.contactors[0].kind for body in particles]
        self.wall_bodies = walls
        self.source = bodies_path
        self.box_walls = False  # set by name_walls on the first snapshot
        self.walls, self.wall_names = [], []

    @property
    def n(self):
        return self.radius.size

    def name(self, k):
        """Particle or wall k's name in a message: its body number (and the wall's name)."""
        if k < self.n:
            return f"body {self.numbers[k]}"
        return f"body {self.walls[k - self.n].number} ({self.wall_names[k - self.n]})"

    def name_walls(self, dof, x_period=None):
        """Name the walls from their place in the first snapshot; four axis-aligned JONCx
        around the particles make a box (:data:`BOX_WALLS`); in a run periodic in x
        (``x_period``), two horizontal ones below and above the particles bound it in y."""
        walls = self.wall_bodies
        self.body_index = {int(b): k for k, b in enumerate(self.numbers)}
        self.box_walls = False
        if not walls:
            return
        state = {int(b): x for b, x in zip(dof.numbers, dof.X)}
        missing = [int(b.number) for b in walls if int(b.number) not in state]
        missing += [int(b) for b in self.numbers if int(b) not in state]
        if missing:
            raise FileFormatError(f"body {missing[0]} of {self.source} is not in the first DOF.OUT")
        centre = (self.reference + np.array([state[int(b)][:2] for b in self.numbers])).mean(axis=0)
        named = {}
        for body in walls:
            x = body.reference + state[int(body.number)]
            angle = math.remainder(x[2], math.pi)
            if abs(angle) < 1e-6:
                name = "bottom" if x[1] < centre[1] else "top"
            elif abs(abs(angle) - math.pi / 2) < 1e-6:
                name = "left" if x[0] < centre[0] else "right"
            else:
                break
            named.setdefault(name, body)
        if x_period is not None and ({"left", "right"} & set(named)):
            body = named["left"] if "left" in named else named["right"]
            raise FileFormatError(f"{self.source}: body {body.number}, a vertical JONCx, stands across x, the periodic "
                                  "direction (x_period); expected walls only across y in a run periodic in x")
        if x_period is not None and len(walls) == 2 and set(named) == {"bottom", "top"}:
            self.walls = [named["bottom"], named["top"]]
            self.wall_names = ["bottom", "top"]
            self.box_walls = "y"
        elif len(walls) == 4 and len(named) == 4:
            self.walls = [named[name] for name in BOX_WALLS]
            self.wall_names = list(BOX_WALLS)
            self.box_walls = True
        else:
            self.walls = list(walls)
            self.wall_names = [f"jonc{body.number}" for body in walls]
            self.box_walls = False
        self.body_index.update({int(body.number): self.n + w for w, body in enumerate(self.walls)})


def _state(model, dof, where):
    """Positions, angles, velocities of the particles and the walls' positions from a DOF record;
    one line for a value that is not finite or is absurd."""
    body = lambda k: f"body {dof.numbers[k]}"  # noqa: E731
    model.limits.check([[dof.time]], "time", "time", where, rows=lambda k: "$steps")
    model.limits.check(dof.X[:, :2], ("X(1)", "X(2)"), "length", where, rows=body)
    model.limits.check(dof.X[:, 2], "X(3)", "angle", where, rows=body)
    model.limits.check(dof.V[:, :2], ("V(1)", "V(2)"), "speed", where, rows=body)
    model.limits.check(dof.V[:, 2], "V(3)", "angular_velocity", where, rows=body)
    row = {int(b): k for k, b in enumerate(dof.numbers)}
    missing = [int(b) for b in model.numbers if int(b) not in row]
    missing += [int(w.number) for w in model.wall_bodies if int(w.number) not in row]
    if missing:
        raise FileFormatError(f"{where}: body {missing[0]} of BODIES.DAT is not in the file")
    unknown = [b for b in row if b not in model.contactor]
    if unknown:
        raise FileFormatError(f"{where}: body {unknown[0]} is not in {model.source} (files of another run?); expected "
                              "the bodies of BODIES.DAT")
    k = np.array([row[int(b)] for b in model.numbers])
    X, V = dof.X[k], dof.V[k]
    walls = np.array([w.reference + dof.X[row[int(w.number)]] for w in model.walls]).reshape(-1, 3)
    c, s = np.cos(X[:, 2]), np.sin(X[:, 2])
    g = model.offset  # an irregular POLYG's centroid, turned with the body
    centroid = np.stack([c * g[:, 0] - s * g[:, 1], s * g[:, 0] + c * g[:, 1]], -1)
    return (model.reference + X[:, :2] + centroid, model.angle0 + X[:, 2], V[:, :2].copy(), V[:, 2].copy(),
            walls)


def _box(model, position, walls, x_period=None):
    if x_period is not None:  # x from 0 to the period; y between two walls, or the particles' extent
        low, high = (position - model.radius[:, None]).min(axis=0), (position + model.radius[:, None]).max(axis=0)
        if model.box_walls == "y":
            half = [w.contactors[0].values.get("axe2", 0.0) for w in model.walls]
            low[1], high[1] = walls[0, 1] + half[0], walls[1, 1] - half[1]
        low[0], high[0] = 0.0, x_period
        return low, high
    if model.box_walls:
        half = [w.contactors[0].values.get("axe2", 0.0) for w in model.walls]
        bottom, right, top, left = walls[:, :2]
        return (np.array([left[0] + half[3], bottom[1] + half[0]]),
                np.array([right[0] - half[1], top[1] - half[2]]))
    return (position - model.radius[:, None]).min(axis=0), (position + model.radius[:, None]).max(axis=0)


def _check_entries(model, position, entries, where):
    """One line for an entry holding a value that is not finite or is absurd, or repeating
    another (the same ``$icdan`` family and number)."""
    if not entries:
        return
    line = lambda k: f"line {entries[k].line}"  # noqa: E731
    limits = model.limits
    limits.check([(e.rln, e.rlt) for e in entries], ("rln/H", "rlt/H"), "force", where, rows=line)
    limits.check([e.gap for e in entries], "gapTT", "length", where, rows=line)
    limits.check([e.normal for e in entries], ("n(1)", "n(2)"), "unit", where, rows=line)
    limits.check([e.point for e in entries], ("coo1", "coo2"), "position", where, rows=line,
                 centre=np.median(position, axis=0))
    seen = {}
    for entry in entries:
        key = (entry.family, entry.index)
        if entry.index >= 0 and key in seen:
            raise FileFormatError(f"{where}: line {entry.line}: a second '$icdan {entry.family} {entry.index}' (the "
                                  f"first at line {seen[key]}); each entry is written once")
        seen[key] = entry.line


def _contacts(model, position, vloc, where, cell=None, periodic=None):
    """Contract contacts (dict of arrays), the total force on each wall and the number of pairs
    left out for a tensile normal force, from one Vloc_Rloc record; in a periodic ``cell``,
    branches and contact points are minimum images."""
    n = model.n
    image = (lambda d: d) if cell is None else (lambda d: minimum_image(d, cell, periodic))  # noqa: E731
    _check_entries(model, position, vloc.entries, where)
    pairs = {}
    for entry in vloc.entries:
        if entry.family not in FAMILIES:
            raise FileFormatError(f"{where}: unknown contactor type: contact family {entry.family!r} "
                                  f"({entry.cd_kind} on {entry.an_kind}); expected one of {', '.join(FAMILIES)}")
        try:
            cd, an = model.body_index[entry.cd], model.body_index[entry.an]
        except KeyError as exc:
            raise FileFormatError(f"{where}: {entry.family} entry on body {exc.args[0]}, which is not a body of "
                                  f"{model.source}") from None
        if cd >= n:
            raise FileFormatError(f"{where}: {entry.family} entry whose candidate (body {entry.cd}) is a wall")
        expected = _FAMILY_CONTACTORS[entry.family]
        found = (model.contactor[entry.cd], model.contactor[entry.an])
        if found != expected or (entry.cd_kind, entry.an_kind) != expected:
            raise FileFormatError(f"{where}: line {entry.line}: a {entry.family} entry (a {expected[0]} on a "
                                  f"{expected[1]}) on body {entry.cd}, a {found[0]}, and body {entry.an}, a {found[1]} "
                                  f"in {os.path.basename(model.source)} ({entry.cd_kind} on {entry.an_kind} in the "
                                  "entry): files of another run?")
        pairs.setdefault((min(cd, an), max(cd, an)), []).append((entry, cd))
    out = {k: [] for k in ("i", "j", "kind", "normal", "fn", "ft", "point", "branch", "gap")}
    wall_force = np.zeros((len(model.wall_names), 2))
    tensile = 0
    for (i, j), points in pairs.items():
        if len(points) > 2:
            raise FileFormatError(f"{where}: {len(points)} entries on the pair of bodies {points[0][0].cd} and "
                                  f"{points[0][0].an}; a 2D contact has at most two points")
        if len(points) == 2:
            a, b = points[0][0], points[1][0]
            if not (a.family in _DOUBLE_FAMILIES and b.family in _DOUBLE_FAMILIES):
                raise FileFormatError(f"{where}: line {b.line}: a second {b.family} entry on the bodies {b.cd} and "
                                      f"{b.an} (the first at line {a.line}); a disk touches another body at one "
                                      "point")
            if a.point == b.point:
                raise FileFormatError(f"{where}: line {b.line}: a second {b.family} entry on the bodies {b.cd} and "
                                      f"{b.an} at the point of the first (line {a.line}); the two points of a double "
                                      "contact are apart")
        force = np.zeros(2)
        fn_points, xy = [], []
        first = points[0][0]
        nuc = np.array(first.normal)
        normal = -nuc if points[0][1] == i else nuc  # from i to j
        for entry, cd in points:
            e_n = np.array(entry.normal)
            e_t = np.array([e_n[1], -e_n[0]])
            on_cd = entry.rln * e_n + entry.rlt * e_t  # exerted by the antagonist on the candidate
            force += -on_cd if cd == i else on_cd  # exerted by i on j
            fn_points.append(entry.rln)
            xy.append(entry.point)
        fn = float(force[0] * normal[0] + force[1] * normal[1])  # not np.dot: BLAS's kernel may fuse
        if fn < 0:
            tensile += 1
        if not fn > 0:
            continue
        tangent = np.array([-normal[1], normal[0]])
        weights = np.array(fn_points)
        xy = np.array(xy)
        point = (weights[:, None] * xy).sum(axis=0) / weights.sum() if weights.sum() > 0 else xy.mean(axis=0)
        point = position[i] + image(point - position[i])  # at the antagonist's image: its image nearest i
        out["i"].append(i)
        out["j"].append(j)
        out["kind"].append(len(points))
        out["normal"].append(normal)
        out["fn"].append(fn)
        out["ft"].append(float(force[0] * tangent[0] + force[1] * tangent[1]))
        out["point"].append(point)
        out["branch"].append(image(position[j] - position[i]) if j < n else point - position[i])
        out["gap"].append(min(entry.gap for entry, _ in points))
        if j >= n:
            wall_force[j - n] += force
    dtypes = {"i": "i4", "j": "i4", "kind": "i1"}
    contacts = {k: np.array(v, dtypes.get(k, "f8")) for k, v in out.items()}
    for k in ("normal", "point", "branch"):
        contacts[k] = contacts[k].reshape(-1, 2)
    check_contacts(model.limits, position, contacts, where, model.name, cell=cell, periodic=periodic)
    return contacts, wall_force, tensile


def _run_folders(run):
    run = input_folder(run, "an LMGC90 run folder holding DATBOX/ and OUTBOX/")
    datbox, outbox = os.path.join(run, "DATBOX"), os.path.join(run, "OUTBOX")
    if not os.path.isdir(datbox) or not os.path.isfile(os.path.join(datbox, "BODIES.DAT")):
        raise FileFormatError(f"{run}: no DATBOX/BODIES.DAT (expected an LMGC90 run folder holding DATBOX/ and "
                              "OUTBOX/)")
    return run, datbox, outbox


def _run_files(run):
    """The files of a run folder's DATBOX/ and OUTBOX/ (what a conversion may read, and must not
    write over)."""
    files = []
    for folder in ("DATBOX", "OUTBOX"):
        folder = os.path.join(os.fspath(run), folder)
        try:
            files += [os.path.join(folder, name) for name in sorted(os.listdir(folder))]
        except OSError:
            pass
    return files


def _x_period(x_period):
    """``x_period`` as a float > 0, or None; one line for anything else."""
    if x_period is None:
        return None
    try:
        value = float(x_period)
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(x_period, bool) or not (math.isfinite(value) and value > 0):
        raise ParameterError(f"x_period={x_period!r}: expected the period in x of a periodic run (m, a finite number "
                             "> 0, the xperiod of its chipy.SetPeriodicCondition), or None")
    return value


def _wrapped(model, position, x_period, where):
    """Centres wrapped into [0, x_period) in x; one line for one more than its diameter outside
    [0, x_period] (LMGC90 moves bodies back every step: the wrong period?)."""
    slack = 2 * model.radius
    out = (position[:, 0] < -slack) | (position[:, 0] > x_period + slack)
    if out.any():
        k = int(np.flatnonzero(out)[0])
        raise FileFormatError(f"{where}: {model.name(k)} at x = {position[k, 0]:.10g} lies outside the periodic cell "
                              f"(x from 0 to x_period = {x_period:.10g}) by more than its diameter; expected the "
                              "period of the run's chipy.SetPeriodicCondition")
    shifted = position.copy()
    shifted[:, 0] -= x_period * np.floor(position[:, 0] / x_period)
    return shifted


def lmgc90_snapshots(run, *, x_period=None):
    """Read an LMGC90 2D run snapshot by snapshot, as the contract's per-snapshot arrays.

    Parameters
    ----------
    run : str or path-like
        The run folder, holding ``DATBOX/BODIES.DAT``, ``DATBOX/BULK_BEHAV.DAT`` and
        ``OUTBOX/DOF.OUT.n``, ``OUTBOX/Vloc_Rloc.OUT.n``.
    x_period : float, optional
        The run's period in x (m) when it is periodic (``chipy.SetPeriodicCondition(xperiod=L)``
        in its computation script; no output file records it); None for a bounded run.

    Returns
    -------
    (static, iterator)
        ``static``: a dict of the particles' ``radius``, ``n_vertices``, ``mass``, ``inertia``
        (arrays, (N,)), ``vertices`` ((N, V, 2), or None when every POLYG is regular),
        ``n_walls``, ``wall_names`` and ``attrs`` (the conversion's provenance);
        the iterator yields one dict per snapshot with ``time`` (s), ``step``, ``position``
        (N, 2), ``angle`` (N,), ``velocity`` (N, 2), ``angular_velocity`` (N,), ``contacts``
        (dict of contract contact arrays), ``box_min``, ``box_max`` (2,) and, with walls,
        ``wall_force`` (W, 2). DATBOX and the first snapshot are read at once; the iterator
        reads the rest one snapshot at a time.

    Raises
    ------
    FileFormatError
        One line naming what is wrong: a missing DATBOX or OUTBOX file, a body with another
        contactor than DISKx, POLYG or JONCx, a POLYG that is not convex, an unknown contact family, a
        truncated file, DOF.OUT and Vloc_Rloc.OUT of different steps.
    """
    x_period = _x_period(x_period)
    run, datbox, outbox = _run_folders(run)
    model = _Model(datbox)
    files = output_files(outbox)
    n_first, dof_path, vloc_path = files[0]
    first = read_dof(dof_path)
    model.name_walls(first, x_period)
    periodic = None if x_period is None else np.array([True, False])
    attrs = {"source": "LMGC90", "lmgc90_run": os.path.basename(os.path.abspath(run)), "thickness_m": 1.0,
             "lmgc90_gravity_m_s2": np.asarray(model.gravity[:2], float),
             "lmgc90_contact_rule": "body pairs with a compressive normal force; two points on a pair make a double "
                                    "contact"}
    static = dict(radius=model.radius, n_vertices=model.n_vertices, mass=model.mass, inertia=model.inertia,
                  vertices=model.vertices,
                  n_walls=len(model.wall_names), wall_names=list(model.wall_names) or None, attrs=attrs)
    if periodic is not None:
        static["periodic"] = periodic.astype("i1")
        attrs["cell_positions"] = "wrapped"
        attrs["lmgc90_x_period_m"] = x_period

    def snapshots():
        for k, (number, dof_file, vloc_file) in enumerate(files):
            dof = first if k == 0 else read_dof(dof_file)
            vloc = read_vloc_rloc(vloc_file)
            if vloc.step != dof.step:
                raise FileFormatError(f"{vloc_file}: step {vloc.step}, but {os.path.basename(dof_file)} is at step "
                                      f"{dof.step} (a snapshot's two files must be of the same step)")
            if not math.isclose(vloc.time, dof.time, rel_tol=1e-6, abs_tol=1e-12):
                raise FileFormatError(f"{vloc_file}: step {vloc.step} at time {vloc.time:.7g} s, but "
                                      f"{os.path.basename(dof_file)} has step {dof.step} at time {dof.time:.7g} s (a "
                                      "snapshot's two files must be of the same step, of the same run)")
            check_step(dof.step, dof_file)
            position, angle, velocity, omega, walls = _state(model, dof, dof_file)
            cell = None
            if periodic is not None:
                position = _wrapped(model, position, x_period, dof_file)
            box_min, box_max = _box(model, position, walls, x_period)
            if periodic is not None:
                cell = restricted_cell(box_min, box_max)
            contacts, wall_force, tensile = _contacts(model, position, vloc, vloc_file, cell, periodic)
            snap = dict(time=dof.time, step=dof.step, position=position, angle=angle, velocity=velocity,
                        angular_velocity=omega, contacts=contacts, box_min=box_min, box_max=box_max, tensile=tensile)
            if cell is not None:
                snap["cell"] = cell
            if model.wall_names:
                snap["wall_force"] = wall_force
            yield snap

    return static, snapshots()


def open_lmgc90(run, *, x_period=None, progress=False):
    """An LMGC90 2D run as an in-memory dataset of the contract.

    Parameters
    ----------
    run : str or path-like
        The run folder (:func:`lmgc90_snapshots`).
    x_period : float, optional
        A periodic run's period in x, m (:func:`lmgc90_snapshots`).
    progress : bool, default False
        Show a progress bar over the snapshots.

    Returns
    -------
    xarray.Dataset
        A dataset of the contract (docs/schema.md; the conversion's rules: docs/formats.md)
        with ``velocity``, ``angular_velocity``, ``step``, ``gap`` and, with walls,
        ``wall_force``. For a run too large for memory, :func:`convert_lmgc90` writes a file
        snapshot by snapshot instead.
    """
    from .convert import snapshots_dataset

    static, stream = lmgc90_snapshots(run, x_period=x_period)
    if progress:
        from tqdm.auto import tqdm

        stream = tqdm(stream, desc="lmgc90", unit=" snapshots")
    snaps = list(stream)
    _warn_tensile(sum(s.pop("tensile") for s in snaps), len(snaps))
    walls = ("wall_force",) if static["n_walls"] else ()
    return snapshots_dataset(static, snaps, ("step", "velocity", "angular_velocity", *walls),
                             vertices=static["vertices"])


def _warn_tensile(count, snapshots):
    if count:
        warnings.warn(f"{count} contact(s) over {snapshots} snapshot(s) had a tensile normal force (rln/H < 0, which "
                      "the contract's fn >= 0 cannot hold) and were left out of the contacts", UserWarning,
                      stacklevel=3)


def convert_lmgc90(out, run, *, x_period=None, overwrite=False, compress=True, progress=False):
    """Convert an LMGC90 2D run into a file of the contract, snapshot by snapshot.

    Each snapshot (a DOF.OUT.n and its Vloc_Rloc.OUT.n) is read and appended to the file in
    turn (:class:`grainview.contract.writer.SnapshotWriter`), so a run of any length converts in the
    memory of one snapshot. The file is written under a hidden temporary name, validated,
    compressed (unless ``compress=False``) and only then moved to ``out``: bad input anywhere
    leaves nothing behind.

    Parameters
    ----------
    out : str or path-like
        The netCDF file to write; an existing one is refused unless ``overwrite``.
    run : str or path-like
        The LMGC90 run folder (:func:`lmgc90_snapshots`).
    x_period : float, optional
        A periodic run's period in x, m (:func:`lmgc90_snapshots`).
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
    FileFormatError, SchemaError
        Bad input (one line); nothing is written.
    """
    from .convert import check_out, write_snapshots

    inputs = _run_files(run)
    out = check_out(out, overwrite, inputs)
    static, stream = lmgc90_snapshots(run, x_period=x_period)
    optional = ("step", "gap", "velocity", "angular_velocity") + (("wall_force",) if static["n_walls"] else ())
    tensile = []

    def prepare(snap):
        tensile.append(snap.pop("tensile"))
        return snap

    count = write_snapshots(out, static, stream, optional, overwrite=overwrite, compress=compress, progress=progress,
                            label="lmgc90", prepare=prepare, inputs=inputs)
    _warn_tensile(sum(tensile), count)
    return count
