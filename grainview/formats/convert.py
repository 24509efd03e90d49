"""Writing another code's run as a file of the contract, the same way for every reader.

A reader yields its run snapshot by snapshot (the static particle data once, then one dict
per snapshot for :meth:`grainview.contract.writer.SnapshotWriter.append`); :func:`write_snapshots`
appends them to a file under a hidden temporary name, checks the finished file against the
contract, compresses it and only then gives it its name. A run of any length is written in
the memory of one snapshot, and bad input anywhere leaves nothing behind. Every snapshot is
checked for values that are not finite or are absurd (:func:`grainview.formats.checks.check_snapshot`)
before it is stored.

A conversion stopped by Ctrl-C or SIGTERM removes its temporary files before it ends; one killed
outright (SIGKILL, a power cut) leaves them, and the next conversion to the same file removes
those whose process is gone (:func:`remove_dead_temporaries`).
"""

from __future__ import annotations

import itertools
import math
import os
import re
import warnings

import numpy as np

from ..contract.errors import FileFormatError, ParameterError, SchemaError
from .checks import Limits, check_snapshot

__all__ = ["check_out", "write_snapshots", "snapshots_dataset", "remove_dead_temporaries", "LABELS"]

LABELS = ("lammps", "lmgc90", "mercurydpm", "pegs", "peer", "convert")
"""The readers' labels: a conversion to ``run.nc`` is written as ``.run.nc.<pid>.<label>``."""


def check_out(out, overwrite: bool, inputs=()) -> str:
    """``out`` as a string, refused in one line (before any work) when it is a folder or one of
    the files the conversion reads, ``inputs`` (with ``overwrite`` too: the input would be
    replaced by the output), when it exists and ``overwrite`` is False, or when its folder does
    not exist."""
    out = os.fspath(out)
    if os.path.isdir(out):
        raise FileFormatError(f"{out} is a folder; expected a file name such as {os.path.join(out, 'run.nc')}")
    for path in inputs:
        path = os.fspath(path)
        try:
            same = os.path.samefile(out, path)
        except OSError:  # either does not exist (yet)
            same = False
        if same:
            raise FileFormatError(f"{out} is an input of the conversion ({path}); expected another file name for the "
                                  "output, which would replace it")
    if os.path.exists(out) and not overwrite:
        raise FileExistsError(f"{out} exists; pass overwrite=True to replace it")
    folder = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(folder):
        raise FileFormatError(f"{out}: the folder {folder} does not exist")
    return out


def snapshots_dataset(static, snaps, per_snapshot=(), **static_optional):
    """A run read whole as an in-memory dataset of the contract (what ``open_<format>`` returns;
    :func:`write_snapshots` is the same run written to a file snapshot by snapshot).

    Parameters
    ----------
    static : dict
        The reader's static data: ``radius``, ``mass``, ``inertia`` (and ``n_vertices`` for
        polygons; disks without it), ``n_walls``, ``wall_names``, ``attrs``; for a periodic
        sample ``periodic`` (2,), the flags of the cell vectors a, b (and ``attrs`` may say
        ``cell_positions``).
    snaps : list of dict
        One dict per snapshot: ``time``, ``position``, ``box_min``, ``box_max``, ``contacts``
        and, where every snapshot has it, ``angle`` (zero otherwise); in a periodic sample each
        its ``cell`` (2, 2), the lattice vectors (:mod:`grainview.contract.cell`).
    per_snapshot : sequence of str
        Optional contract variables stacked over the snapshots where every snapshot has them.
    **static_optional
        Optional variables without a time dimension (``vertices``, ``wall_normal``); None is
        left out.

    Returns
    -------
    xarray.Dataset
        With as many contact slots as the planar bound or the fullest snapshot needs.
    """
    from ..contract.dataset import make_dataset
    from ..contract.schema import contact_slots

    limits = _limits(static)
    empty = _EmptySnapshots(static)
    periodic = static.get("periodic")
    for k, snap in enumerate(snaps):
        check_snapshot(limits, snap, _where(static, k, snap), periodic)
        empty.add(snap)
    empty.warn()
    optional = {name: np.stack([s[name] for s in snaps]) for name in per_snapshot if all(name in s for s in snaps)}
    optional.update({name: value for name, value in static_optional.items() if value is not None})
    if periodic is not None:
        optional.update(periodic=np.asarray(periodic), cell=np.stack([s["cell"] for s in snaps]))
    n = static["radius"].size
    slots = max([contact_slots(n, static["n_walls"])] + [len(s["contacts"]["i"]) for s in snaps])
    angle = np.stack([s["angle"] for s in snaps]) if all("angle" in s for s in snaps) else None
    return make_dataset(radius=static["radius"], n_vertices=static.get("n_vertices"), mass=static["mass"],
                        inertia=static["inertia"], position=np.stack([s["position"] for s in snaps]), angle=angle,
                        contacts=[s["contacts"] for s in snaps], box_min=np.stack([s["box_min"] for s in snaps]),
                        box_max=np.stack([s["box_max"] for s in snaps]), time=np.array([s["time"] for s in snaps]),
                        n_walls=static["n_walls"], wall_names=static["wall_names"], attrs=static["attrs"],
                        n_contact_slots=slots, **optional)


def write_snapshots(out, static, snapshots, optional, *, overwrite=False, compress=True, progress=False,
                    label="convert", prepare=None, validate=True, inputs=()) -> int:
    """Write a run's snapshots as the contract file ``out``.

    Parameters
    ----------
    out : str or path-like
        The file to write (:func:`check_out` is applied).
    static : dict
        ``radius``, ``mass``, ``inertia`` (N,), and optionally ``n_vertices`` (default: disks),
        ``vertices`` (N, V, 2: the polygons' own-frame vertices, :mod:`grainview.contract.shapes`;
        absent: regular polygons),
        ``n_walls``, ``wall_names``, ``wall_normal``, ``periodic`` (a periodic sample's flags of
        the cell vectors a, b) and ``attrs`` (global attributes; ``cell_positions`` for a
        periodic sample).
    snapshots : iterable of dict
        One dict per snapshot, as :meth:`~grainview.contract.writer.SnapshotWriter.append` takes it
        (after ``prepare``); in a periodic sample each with its ``cell`` (2, 2).
    optional : sequence of str
        The optional variables the snapshots hold.
    overwrite, compress : bool
        Replace an existing ``out``; compress the finished file (docs/schema.md).
    progress : bool
        A progress bar over the snapshots, labelled ``label``.
    prepare : callable, optional
        Applied to each snapshot before it is written (to take out what the reader reports
        besides the contract's variables, or to add some).
    validate : bool, default True
        Check the finished file against the contract, a few snapshots at a time, before it
        gets its name.
    inputs : sequence of path-like
        The files the conversion reads: ``out`` may be none of them (:func:`check_out`).

    Returns
    -------
    int
        The number of snapshots written.

    Raises
    ------
    FileFormatError
        A snapshot holding a value that is not finite or is absurd
        (:func:`grainview.formats.checks.check_snapshot`), or a finished run that breaks the
        contract (naming ``out``, which is not written).
    grainview.contract.locks.FileLockedError
        Another process is writing ``out``.

    Notes
    -----
    While it runs, ``out``'s writer's lock is held (:mod:`grainview.contract.locks`) and SIGTERM
    is turned into an exception, so that a stopped conversion removes its temporary files as
    Ctrl-C does; the temporary files of conversions to ``out`` whose process is gone are removed
    first.
    """
    from ..contract.signals import sigterm_raises

    from ..contract.writer import lock_file

    if label not in LABELS:
        raise ParameterError(f"label={label!r}: expected one of {', '.join(LABELS)}")
    out = check_out(out, overwrite, inputs)
    with sigterm_raises():
        lock = lock_file(out)  # one conversion or run at a time; a killed writer's temporary files removed
        try:
            remove_dead_temporaries(out)
            return _write(out, static, snapshots, optional, overwrite, compress, progress, label, prepare, validate)
        finally:
            lock.release()


def _write(out, static, snapshots, optional, overwrite, compress, progress, label, prepare, validate) -> int:
    """:func:`write_snapshots`'s work, under ``out``'s lock."""
    from ..contract.io import open_dataset
    from ..contract.writer import SnapshotWriter, _move_into_place, compress_file

    temporary = os.path.join(os.path.dirname(os.path.abspath(out)), f".{os.path.basename(out)}.{os.getpid()}.{label}")
    stream = iter(snapshots)
    if progress:
        from tqdm.auto import tqdm

        stream = tqdm(stream, desc=f"{label} -> {os.path.basename(out)}", unit=" snapshots")
    n = np.asarray(static["radius"]).size
    limits = _limits(static)
    empty = _EmptySnapshots(static)
    count = 0
    try:
        with SnapshotWriter.create(temporary, radius=static["radius"], mass=static["mass"], inertia=static["inertia"],
                                   n_vertices=static.get("n_vertices", np.zeros(n, "i4")),
                                   vertices=static.get("vertices"),
                                   n_walls=static.get("n_walls", 0), wall_names=static.get("wall_names"),
                                   wall_normal=static.get("wall_normal"), optional=tuple(optional),
                                   attrs=static.get("attrs"), periodic=static.get("periodic")) as writer:
            for snap in stream:
                snap = prepare(snap) if prepare is not None else snap
                check_snapshot(limits, snap, _where(static, count, snap), static.get("periodic"))
                empty.add(snap)
                writer.append(**snap)
                count += 1
        if validate:
            try:
                open_dataset(temporary, validate=True).close()
            except SchemaError as exc:  # named by the user's file: the temporary one is removed below
                raise FileFormatError(f"{out}: not written: the run read breaks the grainview data contract: "
                                      + "; ".join(exc.problems)) from None
        if compress:
            compress_file(temporary)
        _move_into_place(temporary, out, overwrite)
        empty.warn()
    finally:
        if progress:
            stream.close()
        if os.path.exists(temporary):
            os.remove(temporary)
    return count


class _EmptySnapshots:
    """The snapshots without a contact that follow one holding many (a quarter of the
    particles' count, at least two): the mark a contact file cut between two entries leaves
    where a code writes no end mark, reported in one warning. ``static["empty_explained"]``,
    when given, holds the indices of snapshots whose emptiness the reader reports itself."""

    def __init__(self, static):
        self.source = _source(static)
        self.explained = set(static.get("empty_explained") or ())
        self.many = max(2, math.ceil(np.asarray(static["radius"]).size / 4))
        self.previous, self.index, self.found = 0, 0, []

    def add(self, snap):
        count = len((snap.get("contacts") or {}).get("i", ()))
        if count == 0 and self.previous >= self.many and self.index not in self.explained:
            time = np.asarray(snap.get("time", np.nan), float).reshape(-1)[0]
            self.found.append((self.index, time, self.previous))
        self.previous, self.index = count, self.index + 1

    def warn(self):
        if not self.found:
            return
        shown = ", ".join(f"{k} (t = {t:.10g} s, after {m})" for k, t, m in self.found[:5])
        more = f" and {len(self.found) - 5} more" if len(self.found) > 5 else ""
        warnings.warn(f"{self.source}: {len(self.found)} snapshot(s) without a contact right after one with many: "
                      f"snapshot {shown}{more}; written as they are (a contact file cut between two entries reads "
                      "the same: check it)", UserWarning, stacklevel=3)


def _limits(static) -> Limits:
    """The bounds of a run's values (:class:`grainview.formats.checks.Limits`) from its static part."""
    attrs = static.get("attrs") or {}
    return Limits(static["radius"], float(attrs.get("thickness_m", 1.0)), _source(static), mass=static["mass"],
                  inertia=static["inertia"], n_vertices=static.get("n_vertices"))


def _source(static) -> str:
    return f"the {(static.get('attrs') or {}).get('source', 'converted')} run"


def _where(static, k, snap) -> str:
    time = np.asarray(snap.get("time", np.nan), float).reshape(-1)[0]
    return f"{_source(static)}: snapshot {k} (t = {time:.10g} s)"


def remove_dead_temporaries(out) -> list[str]:
    """Remove the temporary files that conversions to ``out`` killed outright (SIGKILL, a power
    cut) left beside it: ``.<name>.<pid>.<label>`` (:data:`LABELS`) and the files written under
    it (``..<name>.<pid>.<label>.<pid>.part`` or ``.convert``, and its lock's note ``.writer``),
    when process ``pid`` is gone. Returns their names.

    Only for a caller holding ``out``'s writer's lock.
    """
    from ..contract.locks import process_alive

    directory, base = os.path.split(os.path.abspath(os.fspath(out)))
    labels = "|".join(LABELS)
    pattern = re.compile(rf"\.(\.)?{re.escape(base)}\.(\d+)\.(?:{labels})(?(1)\.(?:writer|\d+\.(?:part|convert)))")
    try:
        names = os.listdir(directory)
    except OSError:
        return []
    removed = []
    for name in names:
        match = pattern.fullmatch(name)
        if match is None:
            continue
        pid = int(match.group(2))
        if pid == os.getpid() or process_alive(pid):
            continue
        try:
            os.remove(os.path.join(directory, name))
            removed.append(name)
        except OSError:
            pass
    return removed


def chain_first(first, rest):
    """``first`` then the items of ``rest``: a stream whose first item was read ahead."""
    return itertools.chain([first], rest)
