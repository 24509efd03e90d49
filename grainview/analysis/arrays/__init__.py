"""The physics of grainview as pure functions on numpy arrays (no xarray, no dask).

Each function takes batched arrays whose trailing axes are the contact (or particle) axis and,
for vectors, a last axis of length 2 (x, y); any leading axes (usually time) are broadcast.
Empty or unselected slots are excluded through a boolean ``mask``. The topic modules of
:mod:`grainview` lift these functions to labelled, lazy DataArrays.
"""
