"""Opening a packing: a grainview file, or another code's output through its reader.

:func:`open_dataset` is what ``grainview.open_dataset`` is: a file of the data contract goes
to :func:`grainview.contract.io.open_dataset`; another code's output (``format="lammps"``,
``"lmgc90"``, ...) to its reader in :mod:`grainview.formats`, and the dataset it builds is
chunked and validated the same way.
"""

from __future__ import annotations

import os

from ..contract import io
from ..contract.errors import ParameterError


def open_dataset(path, chunks: int | dict | None = "auto", validate: bool = False, format: str = "grainview",
                 **reader_options):
    """Open a grainview netCDF file, lazily; or another code's output, with ``format``.

    Parameters
    ----------
    path : str or path-like
        A netCDF file of the data contract (docs/schema.md), or the main input of ``format``'s
        reader.
    chunks : int, "auto", dict or None, default "auto"
        Snapshots per dask chunk, ``"auto"`` (see :func:`grainview.contract.io.time_chunks`),
        ``{"time": k}``, or ``None`` for eager numpy arrays. Only ``time`` is ever chunked.
    validate : bool, default False
        Run :func:`grainview.contract.validation.validate` (every value) before returning.
    format : str, default "grainview"
        ``"grainview"``: a netCDF file of the contract (:func:`grainview.contract.io.open_dataset`:
        read-only, incomplete trailing snapshots dropped). Another code's output
        (:data:`grainview.formats.READERS`, docs/formats.md), read into memory: ``"lammps"``,
        with ``path`` the particles' dump and ``contacts=``, ``walls=``, ``log=``,
        ``time_step=``... in ``reader_options`` (:func:`grainview.formats.lammps.open_lammps`);
        ``"lmgc90"``, ``"box2d"``, ``"pymunk"``.
    **reader_options
        Passed on to the reader of ``format``.

    Returns
    -------
    xarray.Dataset
        The packing's snapshots, with the ``ds.grain`` accessor.

    Raises
    ------
    FileFormatError
        No such file, not a readable netCDF file, a damaged file, or input the reader refuses.
    SchemaError
        A schema version newer than this grainview's, or (with ``validate``) any fault.
    ParameterError
        A reader's options without its ``format``, or an unknown format.
    """
    if format == "grainview":
        if reader_options:
            raise ParameterError(f"{', '.join(sorted(reader_options))}: options of another code's reader; give its "
                                 "format (format='lammps', ...) or leave them out for a grainview file")
        return io.open_dataset(path, chunks=chunks, validate=validate)
    from . import open_format

    ds = open_format(format, path, **reader_options)
    if chunks is not None:
        ds = ds.chunk(io.time_chunks(ds, chunks))
    if validate:
        from ..contract.validation import validate as check

        check(ds, source=os.fspath(path))
    return ds
