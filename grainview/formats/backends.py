"""The readers as xarray backends: ``xr.open_dataset(path, engine="lammps", ...)``.

Registered through the ``xarray.backends`` entry point (pyproject.toml), so xarray finds them
once grainview is installed. A backend opens a run only when asked by name (``engine=``):
other codes' text dumps carry no signature that would let xarray guess them safely.

Each reader's backend is :class:`ReaderBackend` with the reader's record
(:data:`grainview.formats.READERS`): the class its entry point names (``LammpsBackend``,
``Lmgc90Backend``...) is made from the record when first asked for. A reader of another
package subclasses :class:`ReaderBackend` with its own record.
"""

from __future__ import annotations

from xarray.backends import BackendEntrypoint

__all__ = ["ReaderBackend"]


class ReaderBackend(BackendEntrypoint):
    """The xarray backend of a reader: ``reader`` (its
    :class:`grainview.formats.readers.Reader`) says which options it passes on to the reader's
    opener (``reader.backend.options``), which of them it cannot do without, and xarray's line
    for it. A reader of another package subclasses it, setting ``reader``; its class's
    ``xarray.backends`` entry point makes it found by grainview too
    (:func:`grainview.formats.readers.readers`)."""

    reader = None
    open_dataset_parameters = ("filename_or_obj", "drop_variables")

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.reader is not None:
            cls.open_dataset_parameters = ("filename_or_obj", "drop_variables", *cls.reader.backend.options)
            cls.description = cls.reader.backend.description
            cls.url = cls.reader.backend.url

    def open_dataset(self, filename_or_obj, *, drop_variables=None, **options):
        from ..contract.errors import ParameterError
        from .readers import load

        for option, said in self.reader.backend.needs.items():
            if options.get(option) is None:
                raise ParameterError(f"engine={self.reader.name!r} needs {said}")
        ds = load(self.reader.opener)(filename_or_obj, **options)
        return ds.drop_vars(list(drop_variables or []), errors="ignore")

    def guess_can_open(self, filename_or_obj) -> bool:
        return False


def __getattr__(name):
    """The backend class of the reader whose record names ``name`` here, made once."""
    from .readers import READERS

    found = next((r for r in READERS.values() if r.backend.target == f"{__name__}:{name}"), None)
    if found is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    backend = type(name, (ReaderBackend,), {
        "reader": found, "__module__": __name__, "__qualname__": name,
        "__doc__": f"{found.backend.description} (:func:`{found.opener.replace(':', '.')}`); "
                   f"``xr.open_dataset(path, engine={found.name!r}, ...)``."})
    globals()[name] = backend
    return backend
