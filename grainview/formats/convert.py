"""Writing another code's run as a file of the contract, the same way for every reader.

A reader yields its run snapshot by snapshot (the static particle data once, then one dict
per snapshot for :meth:`grainview.contract.writer.SnapshotWriter.append`); :func:`write_snapshots`
appends them to a file under a hidden temporary name, checks the finished file against the
contract, compresses it and only then gives it its name. A run of any length is written in
the memory of one snapshot, and bad input anywhere leaves nothing behind.
"""

from __future__ import annotations

import itertools
import os

import numpy as np

from ..contract.errors import FileFormatError

__all__ = ["check_out", "write_snapshots", "snapshots_dataset"]


def check_out(out, overwrite: bool) -> str:
    """``out`` as a string, refused in one line (before any work) when it is a folder (with
    ``overwrite`` too), when it exists and ``overwrite`` is False, or when its folder does not
    exist."""
    out = os.fspath(out)
    if os.path.isdir(out):
        raise FileFormatError(f"{out} is a folder; expected a file name such as {os.path.join(out, 'run.nc')}")
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
        polygons; disks without it), ``n_walls``, ``wall_names``, ``attrs``.
    snaps : list of dict
        One dict per snapshot: ``time``, ``position``, ``box_min``, ``box_max``, ``contacts``
        and, where every snapshot has it, ``angle`` (zero otherwise).
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

    optional = {name: np.stack([s[name] for s in snaps]) for name in per_snapshot if all(name in s for s in snaps)}
    optional.update({name: value for name, value in static_optional.items() if value is not None})
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
                    label="convert", prepare=None, validate=True) -> int:
    """Write a run's snapshots as the contract file ``out``.

    Parameters
    ----------
    out : str or path-like
        The file to write (:func:`check_out` is applied).
    static : dict
        ``radius``, ``mass``, ``inertia`` (N,), and optionally ``n_vertices`` (default: disks),
        ``vertices`` (N, V, 2: the polygons' own-frame vertices, :mod:`grainview.contract.shapes`;
        absent: regular polygons),
        ``n_walls``, ``wall_names``, ``wall_normal`` and ``attrs`` (global attributes).
    snapshots : iterable of dict
        One dict per snapshot, as :meth:`~grainview.contract.writer.SnapshotWriter.append` takes it
        (after ``prepare``).
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

    Returns
    -------
    int
        The number of snapshots written.
    """
    from ..contract.io import open_dataset
    from ..contract.writer import SnapshotWriter, _move_into_place, compress_file

    out = check_out(out, overwrite)
    temporary = os.path.join(os.path.dirname(os.path.abspath(out)), f".{os.path.basename(out)}.{os.getpid()}.{label}")
    stream = iter(snapshots)
    if progress:
        from tqdm.auto import tqdm

        stream = tqdm(stream, desc=f"{label} -> {os.path.basename(out)}", unit=" snapshots")
    n = np.asarray(static["radius"]).size
    count = 0
    try:
        with SnapshotWriter.create(temporary, radius=static["radius"], mass=static["mass"], inertia=static["inertia"],
                                   n_vertices=static.get("n_vertices", np.zeros(n, "i4")),
                                   vertices=static.get("vertices"),
                                   n_walls=static.get("n_walls", 0), wall_names=static.get("wall_names"),
                                   wall_normal=static.get("wall_normal"), optional=tuple(optional),
                                   attrs=static.get("attrs")) as writer:
            for snap in stream:
                writer.append(**(prepare(snap) if prepare is not None else snap))
                count += 1
        if validate:
            open_dataset(temporary, validate=True).close()
        if compress:
            compress_file(temporary)
        _move_into_place(temporary, out, overwrite)
    finally:
        if progress:
            stream.close()
        if os.path.exists(temporary):
            os.remove(temporary)
    return count


def chain_first(first, rest):
    """``first`` then the items of ``rest``: a stream whose first item was read ahead."""
    return itertools.chain([first], rest)
