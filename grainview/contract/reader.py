"""Reading a file of the contract into numpy arrays, with netCDF4 alone.

:class:`ContractFile` is the plain reader: what the solver uses to resume a run or start a test
from a saved snapshot, without loading xarray, dask or pandas. It makes the same checks as
:func:`grainview.contract.io.open_dataset` — a netCDF-3 file shorter than its header says or
hiding records, a schema version newer than this one, an incomplete snapshot before complete
ones — and, like it, counts only the leading complete snapshots (a writer killed while writing
the last one leaves it incomplete), and opens again a file replaced while it was opened (a
finished run compressed under its name).

Example::

    with ContractFile("run.nc") as f:
        positions = f.snapshot("position", -1)   # (N, 2) in m, the last complete snapshot
        radius = f.static("radius")              # (N,) in m
"""

from __future__ import annotations

import os

import numpy as np

from .errors import FileFormatError, ParameterError
from .file_checks import check_version, checked_variables, damaged_snapshots
from .netcdf3 import check_netcdf3_length
from .schema import complete_snapshots


def _attribute(value):
    """A global attribute as plain Python: strings as str, one-element arrays as scalars."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray) and value.size == 1:
        return value.reshape(()).item()
    if isinstance(value, np.generic):
        return value.item()
    return value


class ContractFile:
    """A grainview file opened read-only with netCDF4, its complete snapshots as numpy arrays.

    Parameters
    ----------
    path : str or path-like
        A netCDF file of the contract (netCDF-3 or compressed, docs/schema.md).

    Attributes
    ----------
    source : str
        The path.
    attrs : dict
        Global attributes, as plain Python values.
    variables : frozenset of str
        The names of the file's variables.
    sizes : dict
        Dimension lengths; ``sizes["time"]`` counts the leading complete snapshots only.
    n_snapshots : int
        The leading complete snapshots (those :meth:`snapshot` reads).
    wall_names : tuple of str
        The walls' names, in the order of the ``wall`` dimension (empty without walls).

    Raises
    ------
    FileFormatError
        No such file, not a readable netCDF file, a netCDF-3 file cut short or hiding records,
        an incomplete snapshot before complete ones; and, from the methods that read, stored
        data the netCDF library refuses (a chunk of a finished file that fails its checksum).
    SchemaError
        A schema version newer than this grainview's.
    """

    REOPEN_ATTEMPTS = 3

    def __init__(self, path):
        import netCDF4

        self.source = source = os.fspath(path)
        if not os.path.exists(source):
            raise FileFormatError(f"{source}: no such file")
        for attempt in range(self.REOPEN_ATTEMPTS):
            before = os.stat(source)
            try:
                check_netcdf3_length(source)
                self._nc = netCDF4.Dataset(source, "r")
                break
            except (OSError, RuntimeError, ValueError) as exc:
                try:
                    replaced = not os.path.samestat(before, os.stat(source))
                except OSError:
                    replaced = False
                if replaced and attempt + 1 < self.REOPEN_ATTEMPTS:
                    continue
                if isinstance(exc, FileFormatError):
                    raise
                raise FileFormatError(f"{source}: not a readable netCDF file ({exc})") from exc
        nc = self._nc
        try:
            nc.set_auto_maskandscale(False)  # fill values as stored: NaN for floats, sentinels for integers
            self.attrs = {name: _attribute(nc.getncattr(name)) for name in nc.ncattrs()}
            check_version(self.attrs.get("grainview_schema_version"), source)
            self.variables = frozenset(nc.variables)
            self._checked = checked_variables(nc.variables, source)  # a damaged chunk: one line naming the file
            self.sizes = {name: len(dim) for name, dim in nc.dimensions.items()}
            self.n_snapshots = 0
            if "time" in nc.variables and "time" in nc.dimensions:
                self.n_snapshots = damaged_snapshots(complete_snapshots(self._checked), source)
                self.sizes["time"] = self.n_snapshots
            self.wall_names = ()
            if "wall" in nc.variables:
                names = self._checked["wall"]
                names.set_auto_chartostring(False)
                chars = np.asarray(names[:])
                self.wall_names = tuple(b"".join(row).decode().strip() for row in chars.reshape(len(chars), -1)) \
                    if chars.dtype.kind == "S" else tuple(str(name).strip() for name in chars)
        except BaseException:
            nc.close()
            raise

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Close the file."""
        self._nc.close()

    def _variable(self, name):
        if name not in self.variables:
            raise FileFormatError(f"{self.source}: the file has no variable {name!r}")
        return self._checked[name]

    def static(self, name) -> np.ndarray:
        """The whole of variable ``name`` (one without a ``time`` dimension: ``radius``, ``wall_normal``...)."""
        var = self._variable(name)
        if var.dimensions[:1] == ("time",):
            raise ParameterError(f"{name} varies with time: read it with snapshot({name!r}, index) or series({name!r})")
        return np.asarray(var[:])

    def snapshot(self, name, index=-1) -> np.ndarray:
        """Variable ``name`` at complete snapshot ``index`` (negative from the last), its
        ``time`` dimension dropped."""
        var = self._variable(name)
        if var.dimensions[:1] != ("time",):
            raise ParameterError(f"{name} does not vary with time: read it with static({name!r})")
        return np.asarray(var[self._index(index)])

    def series(self, name) -> np.ndarray:
        """Variable ``name`` over every complete snapshot (``time`` first)."""
        var = self._variable(name)
        if var.dimensions[:1] != ("time",):
            raise ParameterError(f"{name} does not vary with time: read it with static({name!r})")
        return np.asarray(var[:self.n_snapshots])

    def _index(self, index) -> int:
        n = self.n_snapshots
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not -n <= index < n:
            raise FileFormatError(f"{self.source}: index={index!r} is outside its {n} complete snapshots")
        return int(index) % n
