"""LAMMPS text dumps and logs, parsed into arrays: the file layer of the LAMMPS reader.

A LAMMPS text dump (``dump custom`` or ``dump local``, written by LAMMPS's ``dump_custom.cpp``
and ``dump_local.cpp``) is a series of snapshots, each::

    ITEM: TIMESTEP
    <step>
    ITEM: NUMBER OF ATOMS            (dump custom; ``NUMBER OF ENTRIES`` for dump local)
    <n>
    ITEM: BOX BOUNDS ff ff pp        (boundary flags of x, y, z)
    <xlo> <xhi>
    <ylo> <yhi>
    <zlo> <zhi>
    ITEM: ATOMS id type x y ...      (``ITEM: ENTRIES c_ID[1] ...`` for dump local)
    <n rows of numbers>

:func:`iter_dump` reads one snapshot at a time, so a dump of any length is read in the memory
of one snapshot. A triclinic box (``ITEM: BOX BOUNDS xy xz yz pp pp pp``) has a third number on
each bounds line, the tilts ``xy``, ``xz``, ``yz``, and its first two are the **bounding box** of
the tilted cell, not its edges: LAMMPS's ``Domain::set_global_box`` writes
``xlo_bound = min(xlo, xlo + xy, xlo + xz, xlo + xy + xz)``, ``xhi_bound = max(xhi, xhi + xy,
xhi + xz, xhi + xy + xz)``, ``ylo_bound = min(ylo, ylo + yz)``, ``yhi_bound = max(yhi, yhi + yz)``,
``z`` unchanged, and the dump prints those (``Dump::write`` takes ``boxlo_bound`` for a triclinic
box). :func:`iter_dump` undoes it, so that :attr:`DumpSnapshot.bounds` always holds the box's own
``xlo xhi`` (the cell's edges) and :attr:`DumpSnapshot.tilt` the tilts.

:func:`read_log` takes from a LAMMPS log (or input script) what a dump does not say: the time
step, the definitions of the computes and fixes whose columns a dump names only ``c_ID[k]`` and
``f_ID[k]``, and the step at which each fix was defined (a moving wall's origin in time).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..contract.errors import FileFormatError
from .checks import input_file

_BOM = "\ufffd" * 3
"""A UTF-8 byte-order mark as the dump's ASCII reading sees it."""
_LARGEST = 2**53
"""The largest step or row count read: floats hold integers exactly up to it."""

__all__ = ["DumpSnapshot", "LammpsLog", "iter_dump", "read_log", "box_from_bounds"]


@dataclass(frozen=True)
class DumpSnapshot:
    """One snapshot of a LAMMPS text dump.

    Attributes
    ----------
    timestep : int
        The step index (``ITEM: TIMESTEP``).
    bounds : numpy.ndarray, (3, 2)
        ``[[xlo, xhi], [ylo, yhi], [zlo, zhi]]`` of the box, in the run's distance units.
    boundary : tuple of str
        The boundary flags of x, y, z (``ff``, ``pp``, ``fs``, ...).
    columns : tuple of str
        The column names of the ``ITEM: ATOMS`` or ``ITEM: ENTRIES`` line.
    data : numpy.ndarray, (n, len(columns))
        The rows, as floats (ids are exact up to 2**53).
    line : int
        The line number of the first row in the file (row k is on line ``line + k``).
    tilt : numpy.ndarray, (3,)
        The tilts ``xy, xz, yz`` of a triclinic box (zero for an orthogonal one). ``bounds``
        then holds the box's own ``lo, hi``, the bounding box of the dump's header undone
        (:func:`box_from_bounds`).
    triclinic : bool
        The header said ``xy xz yz``.
    """

    timestep: int
    bounds: np.ndarray
    boundary: tuple
    columns: tuple
    data: np.ndarray
    line: int = 0
    tilt: np.ndarray = field(default_factory=lambda: np.zeros(3))
    triclinic: bool = False

    def column(self, name: str) -> np.ndarray:
        """The values of column ``name``."""
        return self.data[:, self.columns.index(name)]


def box_from_bounds(bounding, tilt) -> np.ndarray:
    """The box ``[[xlo, xhi], [ylo, yhi], [zlo, zhi]]`` of a triclinic dump's bounding box
    ``bounding`` (3, 2) and tilts ``xy, xz, yz``: LAMMPS's ``Domain::set_global_box`` rule
    undone, ``xlo = xlo_bound - min(0, xy, xz, xy + xz)``, ``xhi = xhi_bound - max(0, xy, xz,
    xy + xz)``, ``ylo = ylo_bound - min(0, yz)``, ``yhi = yhi_bound - max(0, yz)``."""
    xy, xz, yz = (float(t) for t in tilt)
    box = np.array(bounding, float).copy()
    box[0, 0] -= min(0.0, xy, xz, xy + xz)
    box[0, 1] -= max(0.0, xy, xz, xy + xz)
    box[1, 0] -= min(0.0, yz)
    box[1, 1] -= max(0.0, yz)
    return box


class _Lines:
    """A text file read line by line, counting the lines (for the messages)."""

    def __init__(self, fh):
        self._fh = fh
        self.number = 0

    def readline(self) -> str:
        line = self._fh.readline()
        if line:
            self.number += 1
        return line


def _read_item(fh, path, expect, where):
    line = fh.readline()
    if not line.startswith("ITEM: " + expect):
        found = line.strip()[:60] or "the end of the file"
        raise FileFormatError(f"{path}: line {fh.number}: {where}: expected 'ITEM: {expect}', found {found!r} "
                              "(not a LAMMPS text dump, or a truncated one)")
    return line


def _read_numbers(fh, path, count, where):
    line = fh.readline()
    try:
        values = [float(v) for v in line.split()]
    except ValueError:
        values = []
    if len(values) < count:
        raise FileFormatError(f"{path}: line {fh.number}: {where}: expected {count} number(s), found "
                              f"{line.strip()[:60]!r}")
    return values


def _read_count(fh, path, what, where):
    """A non-negative integer on a line of its own (a step, a number of rows)."""
    value = _read_numbers(fh, path, 1, where)[0]
    if not (np.isfinite(value) and value >= 0 and value == int(value) and value <= _LARGEST):
        raise FileFormatError(f"{path}: line {fh.number}: {where}: {what} {value:g}; expected an integer from 0 to "
                              f"{_LARGEST}")
    return int(value)


def _read_rows(fh, path, rows, where):
    """The ``rows`` lines of a snapshot; one line when the file ends first, without reading on
    for the rows a damaged header announces beyond its end."""
    lines = []
    for _ in range(rows):
        line = fh.readline()
        if not line:
            raise FileFormatError(f"{path}: {where}: {rows} rows announced, {len(lines)} found (a truncated dump)")
        lines.append(line)
    if lines and not lines[-1].endswith("\n"):
        raise FileFormatError(f"{path}: line {fh.number}: {where}: the last row ends without a newline (a truncated "
                              "dump: LAMMPS ends every row with one, and a cut row may have lost digits)")
    return lines


def iter_dump(path):
    """Iterate over the snapshots of a LAMMPS text dump, one :class:`DumpSnapshot` at a time.

    Parameters
    ----------
    path : str or path-like
        A ``dump custom`` or ``dump local`` file in LAMMPS's text format (not binary, not
        gzipped).

    Yields
    ------
    DumpSnapshot

    Raises
    ------
    FileFormatError
        A missing or unreadable file (or a folder), a header that is not LAMMPS's, a step or a
        row count that is not an integer, a triclinic box's bounds line without its tilt, or a
        snapshot with fewer or more rows than announced, a row of the wrong length or a file ending inside a row (a
        truncated or damaged dump), naming the file, the line and the snapshot.
    """
    path = input_file(path, "a LAMMPS text dump")
    try:
        handle = open(path, encoding="ascii", errors="replace")
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    with handle:
        fh = _Lines(handle)
        index = 0
        line = fh.readline()
        while True:
            if not line:
                return
            if not line.strip():
                line = fh.readline()
                continue
            where = f"snapshot {index}"
            if fh.number == 1 and line.startswith(_BOM):
                raise FileFormatError(f"{path}: line 1: a byte-order mark before 'ITEM: TIMESTEP' (an editor's; "
                                      "LAMMPS writes none): save the dump without it")
            if not line.startswith("ITEM: TIMESTEP"):
                raise FileFormatError(f"{path}: line {fh.number}: {where}: expected 'ITEM: TIMESTEP', found "
                                      f"{line.strip()[:60]!r} (not a LAMMPS text dump)")
            timestep = _read_count(fh, path, "step", where)
            where = f"snapshot {index} (step {timestep})"
            _read_item(fh, path, "NUMBER OF", where)
            rows = _read_count(fh, path, "row count", where)
            header = _read_item(fh, path, "BOX BOUNDS", where)
            flags = header.split()[3:]
            if flags[:2] == ["abc", "origin"]:
                raise FileFormatError(f"{path}: {where}: a general triclinic box (ITEM: BOX BOUNDS abc origin, "
                                      "dump_modify triclinic/general yes); expected LAMMPS's restricted triclinic "
                                      "form, its default (ITEM: BOX BOUNDS xy xz yz)")
            triclinic = flags[:3] == ["xy", "xz", "yz"]
            if triclinic:
                flags = flags[3:]
                rows3 = np.array([_read_numbers(fh, path, 3, where)[:3] for _ in range(3)])
                tilt = rows3[:, 2].copy()
                bounds = box_from_bounds(rows3[:, :2], tilt)
            else:
                tilt = np.zeros(3)
                bounds = np.array([_read_numbers(fh, path, 2, where)[:2] for _ in range(3)])
            header = fh.readline()
            if not (header.startswith("ITEM: ATOMS") or header.startswith("ITEM: ENTRIES")):
                raise FileFormatError(f"{path}: line {fh.number}: {where}: expected 'ITEM: ATOMS' or 'ITEM: ENTRIES', "
                                      f"found {header.strip()[:60]!r}")
            columns = tuple(header.split()[2:])
            first_row = fh.number + 1
            lines = _read_rows(fh, path, rows, where)
            try:
                values = np.array(" ".join(lines).split(), dtype=np.float64)
            except ValueError:
                raise FileFormatError(f"{path}: {where}: a row holds something other than numbers") from None
            if values.size != rows * len(columns):
                raise FileFormatError(f"{path}: {where}: {values.size} values in {rows} rows of "
                                      f"{len(columns)} columns (a damaged dump)")
            line = fh.readline()  # read ahead: a row beyond the count is this snapshot's fault
            while line and not line.strip():
                line = fh.readline()
            if line and not line.startswith("ITEM:"):
                raise FileFormatError(f"{path}: line {fh.number}: {where}: more rows than the {rows} announced (a "
                                      "damaged dump)")
            yield DumpSnapshot(timestep, bounds, tuple(flags), columns, values.reshape(rows, len(columns)), first_row,
                               tilt, triclinic)
            index += 1


@dataclass
class LammpsLog:
    """What a LAMMPS log or input script says about a run's output.

    Attributes
    ----------
    time_step : float or None
        The last ``timestep`` command's value, in the run's time units.
    computes : dict
        compute ID -> (style, keywords), e.g. ``"forces" -> ("pair/local", ["dist", "fx", ...])``.
    fixes : dict
        fix ID -> (style, arguments).
    version : str or None
        The LAMMPS version line (``LAMMPS (22 Jul 2025 - Update 4)``).
    units : str or None
        The ``units`` command's style (``si``, ``lj``, ...).
    fix_steps : dict
        fix ID -> the step at which its (last) definition was read: the steps of the runs
        before it (the log's ``Loop time of ... for N steps`` lines, and ``reset_timestep``).
        An input script, which has no such lines, gives the steps set by ``reset_timestep``
        only (0 without one). A ``fix wall/gran ... wiggle`` moves from that step on.
    """

    time_step: float | None = None
    units: str | None = None
    computes: dict = field(default_factory=dict)
    fixes: dict = field(default_factory=dict)
    version: str | None = None
    fix_steps: dict = field(default_factory=dict)


_COMMAND = re.compile(r"^\s*(compute|fix|timestep|units|reset_timestep|unfix)\s+(.*)$")
_LOOP = re.compile(r"^Loop time of \S+ on \d+ procs for (\d+) steps")


def read_log(path) -> LammpsLog:
    """The time step and the compute and fix definitions of a LAMMPS log or input script.

    Lines still holding a variable (``${name}``, ``$x``) are skipped: LAMMPS echoes each such
    command a second time with the variable substituted, and that line is the one read. A
    command given twice (a compute redefined, a second ``timestep``) keeps its last form.

    Raises
    ------
    FileFormatError
        The file cannot be read (or is a folder).
    """
    path = input_file(path, "a LAMMPS log or input script")
    log = LammpsLog()
    try:
        fh = open(path, encoding="utf-8", errors="replace")
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    step = 0
    with fh:
        for line in fh:
            if log.version is None and line.startswith("LAMMPS ("):
                log.version = line.strip()
            loop = _LOOP.match(line)
            if loop is not None:
                step += int(loop.group(1))
                continue
            match = _COMMAND.match(line.split("#", 1)[0])
            if match is None or "$" in line:
                continue
            command, words = match.group(1), match.group(2).split()
            if command == "units" and words:
                log.units = words[0]
            elif command == "reset_timestep" and words:
                try:
                    step = int(float(words[0]))
                except ValueError:
                    pass
            elif command == "unfix" and words:
                log.fixes.pop(words[0], None)
                log.fix_steps.pop(words[0], None)
            elif command == "timestep":
                try:
                    log.time_step = float(words[0])
                except (ValueError, IndexError):
                    pass
            elif len(words) >= 3:  # ID group style args...
                target = log.computes if command == "compute" else log.fixes
                target[words[0]] = (words[2], words[3:])
                if command == "fix":
                    log.fix_steps[words[0]] = step
    return log
