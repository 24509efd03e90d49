"""Shared fixtures: eager and chunked versions of the hand-built datasets, and a dask
scheduler that raises on compute (as xarray's own tests do) to prove laziness."""

from __future__ import annotations

import contextlib

import dask
import pytest

from . import builders


class CountingScheduler:
    """A dask scheduler that counts computes and raises once more than ``max_computes``."""

    def __init__(self, max_computes=0):
        self.total_computes = 0
        self.max_computes = max_computes

    def __call__(self, dsk, keys, **kwargs):
        self.total_computes += 1
        if self.total_computes > self.max_computes:
            raise RuntimeError(f"Too many computes. Total: {self.total_computes} > max: {self.max_computes}.")
        return dask.get(dsk, keys, **kwargs)


@contextlib.contextmanager
def raise_if_dask_computes(max_computes=0):
    """Fail if anything computes a dask graph inside the block (xarray's test helper idea)."""
    scheduler = CountingScheduler(max_computes)
    with dask.config.set(scheduler=scheduler):
        yield scheduler


@pytest.fixture(params=["eager", "chunked"])
def backend(request):
    """Run a test on numpy-backed and on dask-backed (chunked along time) datasets."""
    return request.param


def as_backend(ds, backend):
    """``ds`` itself (eager) or chunked one snapshot per chunk, under no compute."""
    return ds if backend == "eager" else ds.chunk({"time": 1})


@pytest.fixture
def prepare(backend):
    """Turn an eager dataset into the current backend's dataset."""
    return lambda ds: as_backend(ds, backend)
