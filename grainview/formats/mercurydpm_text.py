"""MercuryDPM's text output files, parsed: ``.data``, ``.fstat`` and ``.restart``.

What MercuryDPM writes (read in its sources: ``DPMBase::outputXBallsData``,
``DPMBase::outputXBallsDataParticle`` in ``DPMBaseXBalls.icc``, ``DPMBase::writeFstatHeader``,
``BaseInteraction::writeToFStat``, ``DPMBase::write``), for a 2D run:

* ``.data``, per snapshot: a header ``N t xmin ymin xmax ymax`` (the particle count, the time,
  the domain), then N lines ``x y vx vy r angleZ -omegaZ info`` (the angular velocity negated,
  for XBalls; ``info`` the species id unless set). A 3D run's header has 8 numbers and its lines
  14; :func:`iter_data` refuses it.
* ``.fstat``, per snapshot: three lines ``# t 1``, ``# xmin ymin zmin xmax ymax zmax`` and
  ``# rmin rmax 0 0 0 0``, then one line per contact and side: ``t P I cx cy cz delta
  delta_t fn ft nx ny nz tx ty tz`` (16 numbers: the particle P, the other body I, a wall as
  ``-index - 1``, the contact point, the overlap, the tangential overlap, the normal force
  ``fn``, the magnitude ``ft`` of the tangential force, the unit normal and the unit direction
  of the tangential force).
* ``.restart``: ``key value`` lines, among them ``timeStep dt time t ...``,
  ``systemDimensions 2 particleDimensions 2``, one line per species (``... id 0 density 1
  ...``), ``Walls W`` then W wall lines, ``Boundaries B`` then B boundary lines (``<type> id k
  ...``: a ``PeriodicBoundary``'s ``normal nx ny nz scaleFactor f distanceLeft L distanceRight
  R shift sx sy sz``, a ``LeesEdwardsBoundary``'s ``left L right R down D up U shift s vel v``,
  written by ``PeriodicBoundary::write`` and ``LeesEdwardsBoundary::write``; only two lines and
  ``...`` when B >= 9) and ``Particles N`` then N particle lines (``... radius r invMass m^-1
  ...``).

Every parser refuses bad input in one line (:class:`~grainview.contract.errors.FileFormatError`)
naming the file, the line and what was expected.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..contract.errors import FileFormatError
from .checks import input_file

__all__ = ["DataSnapshot", "FstatSnapshot", "RestartInfo", "iter_data", "iter_fstat", "read_restart",
           "FSTAT_COLUMNS", "DATA_COLUMNS"]

DATA_COLUMNS = ("x", "y", "vx", "vy", "radius", "angle", "minus_omega", "info")
"""The columns of a 2D ``.data`` particle line, in order (``minus_omega`` = ``-omegaZ``)."""
FSTAT_COLUMNS = ("time", "p", "i", "cx", "cy", "cz", "overlap", "tangential_overlap", "fn", "ft",
                 "nx", "ny", "nz", "tx", "ty", "tz")
"""The columns of an ``.fstat`` contact line, in order."""


@dataclass
class DataSnapshot:
    """One snapshot of a 2D ``.data`` file: ``time``, the domain ``bounds`` (xmin, ymin, xmax,
    ymax) and ``values`` (N, 8) in the order of :data:`DATA_COLUMNS`; ``line`` is the header's
    line number."""

    time: float
    bounds: np.ndarray
    values: np.ndarray
    line: int


@dataclass
class FstatSnapshot:
    """One snapshot of an ``.fstat`` file: ``time``, ``rows`` (K, 16) in the order of
    :data:`FSTAT_COLUMNS`; ``line`` is the first header line's number, ``lines`` (K,) the line
    number of each row."""

    time: float
    rows: np.ndarray
    line: int
    lines: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))


@dataclass
class RestartInfo:
    """What the reader takes from a ``.restart`` file."""

    system_dimensions: int
    particle_dimensions: int
    densities: dict = field(default_factory=dict)  # species index -> density
    walls: list = field(default_factory=list)  # (type, {key: values})
    particles: list = field(default_factory=list)  # {key: values} per particle
    version: str | None = None
    boundaries: list = field(default_factory=list)  # (type, {key: values}, line number)
    boundary_count: int = 0  # the 'Boundaries B' count (more than len(boundaries) when cut with '...')
    time: float | None = None  # the time the restart was written at ('time t')
    time_step: float | None = None  # 'timeStep dt'


def _numbers(text, path, line, count=None, what="numbers"):
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        raise FileFormatError(f"{path}: line {line}: expected {what}, found {text.strip()[:80]!r}") from None
    if count is not None and len(values) != count:
        raise FileFormatError(f"{path}: line {line}: expected {count} {what}, found {len(values)}")
    return values


def _open(path, kind):
    path = input_file(path, f"MercuryDPM's {kind} file")
    return path, open(path, encoding="utf-8", errors="replace")


def iter_data(path):
    """Yield the snapshots of a 2D MercuryDPM ``.data`` file one at a time (:class:`DataSnapshot`).

    Raises
    ------
    FileFormatError
        A missing file, a header that is not ``N t xmin ymin xmax ymax`` (a 3D run's has 8
        numbers), a particle line without its 8 numbers, a snapshot cut short.
    """
    path, handle = _open(path, ".data")
    with handle:
        number = 0
        while True:
            header = handle.readline()
            number += 1
            if not header:
                return
            if not header.strip():
                continue
            values = _numbers(header, path, number, what="a header 'N t xmin ymin xmax ymax'")
            if len(values) == 8:
                raise FileFormatError(f"{path}: line {number}: a 3D run's header (N t xmin ymin zmin xmax ymax zmax); "
                                      "only 2D runs (setDimension(2)) can be read")
            if len(values) != 6 or not (np.isfinite(values[0]) and values[0] >= 0 and values[0] == int(values[0])):
                raise FileFormatError(f"{path}: line {number}: expected a header 'N t xmin ymin xmax ymax', found "
                                      f"{header.strip()[:80]!r}")
            n = int(values[0])
            rows = []
            for k in range(n):
                line = handle.readline()
                if not line:
                    raise FileFormatError(f"{path}: truncated: the snapshot at t = {values[1]:g} (line {number}) "
                                          f"announces {n} particles and ends after {k}")
                rows.append(line)
            try:
                block = np.array(" ".join(rows).split(), float)
            except ValueError:
                block = None
            if block is None or block.size != 8 * n:
                for k, line in enumerate(rows):
                    _numbers(line, path, number + 1 + k, 8, "numbers (x y vx vy r angleZ -omegaZ info)")
            yield DataSnapshot(values[1], np.array(values[2:6]), block.reshape(n, 8), number)
            number += n


def iter_fstat(path):
    """Yield the snapshots of a MercuryDPM ``.fstat`` file one at a time (:class:`FstatSnapshot`).

    Raises
    ------
    FileFormatError
        A missing file, a file that does not start with the three ``#`` header lines, a
        header of the old layout (marker 0: centres instead of contact points), a contact line
        without its 16 numbers (a truncated file among them).
    """
    path, handle = _open(path, ".fstat")
    with handle:
        header, rows, start = None, [], 0
        for number, line in enumerate(handle, start=1):
            if line.startswith("#"):
                if header is not None and len(header) == 3:
                    yield _fstat_snapshot(path, header, rows, start)
                    header, rows = None, []
                if header is None:
                    header, start = [], number
                header.append((number, line[1:]))
                continue
            if not line.strip():
                continue
            if header is None or len(header) != 3:
                raise FileFormatError(f"{path}: line {number}: a contact line before a snapshot's three '#' header "
                                      "lines (is it an .fstat file?)")
            rows.append((number, line))
        if header is not None:
            if len(header) != 3:
                raise FileFormatError(f"{path}: truncated: the snapshot at line {start} has {len(header)} of its 3 "
                                      "header lines")
            yield _fstat_snapshot(path, header, rows, start)


def _fstat_snapshot(path, header, rows, start):
    number, text = header[0]
    first = _numbers(text, path, number, what="'# t 1'")
    if len(first) != 2:
        raise FileFormatError(f"{path}: line {number}: expected '# t 1', found {('#' + text).strip()[:80]!r}")
    if first[1] != 1:
        raise FileFormatError(f"{path}: line {number}: an .fstat file of the old layout (marker {first[1]:g}, centres "
                              "instead of contact points); write it with a MercuryDPM that marks it 1")
    _numbers(header[1][1], path, header[1][0], 6, "numbers (# xmin ymin zmin xmax ymax zmax)")
    if not rows:
        return FstatSnapshot(first[0], np.zeros((0, 16)), start)
    lines = np.array([number for number, _ in rows], np.int64)
    try:
        block = np.array(" ".join(line for _, line in rows).split(), float)
    except ValueError:
        block = None
    if block is None or block.size != 16 * len(rows):
        for number, line in rows:
            _numbers(line, path, number, 16, "numbers (t P I contact-point overlap tangential-overlap fn ft normal "
                                             "tangent)")
    return FstatSnapshot(first[0], block.reshape(len(rows), 16), start, lines)


def _pairs(tokens):
    """``key value...`` tokens as a dict key -> list of the following non-key tokens."""
    out, key = {}, None
    for token in tokens:
        try:
            value = float(token)
        except ValueError:
            key = token
            out.setdefault(key, [])
            continue
        if key is not None:
            out[key].append(value)
    return out


def _count(tokens, path, number):
    """The count of a ``Species N``, ``Walls N`` or ``Particles N`` line: a non-negative integer."""
    text = tokens[1]
    if not text.isdigit():
        raise FileFormatError(f"{path}: line {number}: '{tokens[0]} {text[:30]}'; expected '{tokens[0]} <count>', "
                              "a whole number")
    return int(text)


def _dimension(values, key, path, number):
    """``systemDimensions`` or ``particleDimensions``: 1, 2 or 3."""
    try:
        value = values[key][0]
    except (KeyError, IndexError):
        raise FileFormatError(f"{path}: line {number}: expected 'systemDimensions D particleDimensions D'") from None
    if value not in (1, 2, 3):
        raise FileFormatError(f"{path}: line {number}: {key} {value:g}; expected 1, 2 or 3")
    return int(value)


_WALL_KEYS = ("id", "indSpecies")
"""What every wall line of a ``.restart`` holds after the wall's type (``InfiniteWall id 0
indSpecies 0 position ...``)."""


def _wall(line, path, number, index, count):
    """One wall line: (type, {key: values}); one line for a line that is not a wall's or whose
    position or orientation holds a number that is not finite."""
    tokens = line.split()
    values = _pairs(tokens[1:])
    if not tokens or any(not values.get(key) for key in _WALL_KEYS):
        raise FileFormatError(f"{path}: line {number}: expected wall {index} of 'Walls {count}' ('<type> id <n> "
                              f"indSpecies <n> ...'), found {line.strip()[:60]!r} (fewer wall lines than announced?)")
    for key in ("position", "orientation"):  # what the reader takes from a wall
        numbers = values.get(key, [])
        if not np.all(np.isfinite(numbers)):
            raise FileFormatError(f"{path}: line {number}: wall {index}: {key} {' '.join(f'{v:g}' for v in numbers)}; "
                                  "expected finite numbers")
    return tokens[0], values


def read_restart(path) -> RestartInfo:
    """Read the dimensions, species densities, walls and particles of a MercuryDPM ``.restart``.

    Raises
    ------
    FileFormatError
        A missing file, no ``systemDimensions``/``particleDimensions`` line or dimensions other
        than 1, 2 or 3, a count that is not a whole number, a species without a density, fewer
        wall or particle lines than announced, a wall's position or orientation that is not finite.
    """
    path, handle = _open(path, ".restart")
    with handle:
        lines = handle.read().splitlines()
    info = None
    version = None
    clock = {}
    boundaries, boundary_count = [], 0
    k = 0
    while k < len(lines):
        tokens = lines[k].split()
        if not tokens:
            k += 1
            continue
        head = tokens[0]
        if head == "MercuryDPM" and len(tokens) > 1 and version is None:
            version = tokens[1]
        elif head == "timeStep" and not clock:
            clock = _pairs(tokens)
            for key in ("timeStep", "time"):
                if len(clock.get(key, ())) != 1 or not np.isfinite(clock[key][0]):
                    raise FileFormatError(f"{path}: line {k + 1}: expected 'timeStep dt time t ...' with finite "
                                          f"numbers, found {lines[k].strip()[:80]!r}")
        elif head == "Boundaries" and len(tokens) == 2 and info is not None:
            boundary_count = _count(tokens, path, k + 1)
            for b in range(boundary_count):
                if k + 1 + b >= len(lines):
                    raise FileFormatError(f"{path}: truncated: 'Boundaries {boundary_count}' is followed by {b} "
                                          "boundary lines")
                text = lines[k + 1 + b]
                if text.strip() == "...":  # MercuryDPM writes two boundaries and '...' when it has 9 or more
                    k += b
                    break
                words = text.split()
                boundaries.append((words[0] if words else "", _pairs(words[1:]), k + 2 + b))
            else:
                k += boundary_count
        elif head == "systemDimensions" or "systemDimensions" in tokens:
            values = _pairs(tokens)
            info = RestartInfo(_dimension(values, "systemDimensions", path, k + 1),
                               _dimension(values, "particleDimensions", path, k + 1))
        elif head == "Species" and len(tokens) == 2 and info is not None:
            count = _count(tokens, path, k + 1)
            for s in range(count):
                if k + 1 + s >= len(lines):
                    raise FileFormatError(f"{path}: truncated: 'Species {count}' is followed by {s} species lines")
                values = _pairs(lines[k + 1 + s].split())
                if "density" not in values or not values["density"]:
                    raise FileFormatError(f"{path}: line {k + 2 + s}: a species without a density")
                info.densities[s] = values["density"][0]
            k += count
        elif head == "Walls" and len(tokens) == 2 and info is not None:
            count = _count(tokens, path, k + 1)
            for w in range(count):
                if k + 1 + w >= len(lines):
                    raise FileFormatError(f"{path}: truncated: 'Walls {count}' is followed by {w} wall lines")
                info.walls.append(_wall(lines[k + 1 + w], path, k + 2 + w, w, count))
            k += count
        elif head == "Particles" and len(tokens) == 2 and info is not None:
            count = _count(tokens, path, k + 1)
            for p in range(count):
                if k + 1 + p >= len(lines):
                    raise FileFormatError(f"{path}: truncated: 'Particles {count}' is followed by {p} particle lines")
                values = _pairs(lines[k + 1 + p].split()[1:])
                if not values.get("radius") or not values.get("invMass") or "indSpecies" not in values:
                    raise FileFormatError(f"{path}: line {k + 2 + p}: a particle line without radius, invMass and "
                                          "indSpecies")
                info.particles.append(values)
            k += count
        k += 1
    if info is None:
        raise FileFormatError(f"{path}: no 'systemDimensions D particleDimensions D' line (is it a MercuryDPM "
                              ".restart file?)")
    info.version = version
    info.boundaries, info.boundary_count = boundaries, boundary_count
    if clock:
        info.time_step, info.time = clock["timeStep"][0], clock["time"][0]
    return info

