"""Other codes' files, read into datasets of the grainview contract (docs/formats.md).

Each reader is usable three ways: as a function (``open_lammps``, ``open_box2d``...), through
``grainview.open_dataset(path, format="lammps", ...)`` and ``xr.open_dataset(path,
engine="lammps", ...)``, and on the command line (``grainview convert lammps ...``), all from
its record in the readers' registry (:mod:`grainview.formats.readers`).
"""

from __future__ import annotations

from ..contract.errors import ParameterError
from .readers import READERS, load, reader, readers

__all__ = ["READERS", "open_format"]


def open_format(format: str, path, **options):
    """Open ``path`` with the reader of ``format`` (:data:`READERS`, or another package's
    through its entry point, :func:`grainview.formats.readers.readers`); one line for an
    unknown format."""
    found = reader(format)
    if found is None:
        raise ParameterError(f"format={format!r}: expected 'grainview' or one of {', '.join(sorted(readers()))}")
    return load(found.opener)(path, **options)
