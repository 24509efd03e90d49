"""Registering the ``ds.grain`` accessor without loading xarray before anyone needs it.

``import grainview`` must make ``ds.grain`` available on every xarray Dataset, yet the solver,
which imports ``grainview.contract.errors`` and the contract (:mod:`grainview.contract.schema`), must not pay
for xarray, pandas and dask. So :func:`register` registers the accessor at once when xarray is
already loaded, and otherwise the moment xarray's own import completes, through a one-shot
import hook (:class:`importlib.abc.MetaPathFinder`) that removes itself when it fires. A
Dataset cannot exist before xarray is imported, so ``ds.grain`` is there whenever a dataset is.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

ACCESSOR_MODULE = "grainview.accessor"


def register() -> None:
    """Register ``ds.grain`` now if xarray is loaded, else as soon as it is."""
    if "xarray" in sys.modules:
        importlib.import_module(ACCESSOR_MODULE)
    elif not any(isinstance(finder, _AfterXarrayImport) for finder in sys.meta_path):
        sys.meta_path.insert(0, _AfterXarrayImport())


class _AfterXarrayImport(importlib.abc.MetaPathFinder):
    """Finds xarray with the other finders, and makes its loader import the accessor module
    right after xarray's module has run."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname != "xarray":
            return None
        sys.meta_path.remove(self)  # one shot; also keeps the search below from finding us
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None:
            return spec
        run_xarray = spec.loader.exec_module

        def exec_module(module):
            run_xarray(module)
            importlib.import_module(ACCESSOR_MODULE)

        spec.loader.exec_module = exec_module
        return spec
