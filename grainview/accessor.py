"""The ``ds.grain`` accessor: holds the dataset and delegates to the topic modules.

Every method is a one-line call of a function of the same name in a topic module
(:mod:`grainview.stress`, :mod:`grainview.fabric`, ...), where the docstring with the formula
lives. Nothing is computed here.
"""

from __future__ import annotations

import xarray as xr

from . import stress, validation


@xr.register_dataset_accessor("grain")
class GrainAccessor:
    def __init__(self, ds: xr.Dataset):
        self._ds = ds

    def validate(self):
        """Check the dataset against the contract (:func:`grainview.validation.validate`)."""
        return validation.validate(self._ds)

    def stress_tensor(self, kind="all", walls=True):
        return stress.stress_tensor(self._ds, kind, walls)

    def stress_invariants(self, kind="all", walls=True):
        return stress.stress_invariants(self._ds, kind, walls)
