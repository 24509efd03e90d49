"""Other codes' files, read into datasets of the grainview contract (docs/formats.md).

Each reader is usable three ways: as a function (``open_lammps``, ``open_box2d``...), through
``grainview.open_dataset(path, format="lammps", ...)`` and ``xr.open_dataset(path,
engine="lammps", ...)``, and on the command line (``grainview convert lammps ...``).
"""

from __future__ import annotations

import importlib

from ..contract.errors import ParameterError

__all__ = ["READERS", "open_format"]

READERS = {"lammps": "grainview.formats.lammps:open_lammps", "box2d": "grainview.formats.peers:open_box2d",
           "pymunk": "grainview.formats.peers:open_pymunk", "lmgc90": "grainview.formats.lmgc90:open_lmgc90",
           "mercurydpm": "grainview.formats.mercurydpm:open_mercurydpm", "pegs": "grainview.formats.pegs:open_pegs"}
"""Format name -> the reader that opens it as an in-memory dataset of the contract."""


def open_format(format: str, path, **options):
    """Open ``path`` with the reader of ``format`` (:data:`READERS`); one line for an unknown
    format."""
    if format not in READERS:
        raise ParameterError(f"format={format!r}: expected 'grainview' or one of {', '.join(sorted(READERS))}")
    module, name = READERS[format].split(":")
    return getattr(importlib.import_module(module), name)(path, **options)
