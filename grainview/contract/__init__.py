"""The data contract of a packing file, as a layer of its own.

Everything that says what a grainview file is, and nothing that analyses one:

* :mod:`~grainview.contract.schema` — names, dimensions, units and sentinels (docs/schema.md);
* :mod:`~grainview.contract.errors` — the error types every layer raises;
* :mod:`~grainview.contract.validation` — checks of a dataset against the schema;
* :mod:`~grainview.contract.file_checks` — the same checks on plain arrays, for ``info``;
* :mod:`~grainview.contract.writer` — the crash-safe netCDF writer, compression, locks' users;
* :mod:`~grainview.contract.locks` — the writer's lock on a file;
* :mod:`~grainview.contract.dataset` — building an in-memory dataset from plain arrays;
* :mod:`~grainview.contract.io` — opening a file as a lazy xarray dataset;
* :mod:`~grainview.contract.reader` — reading a file into numpy arrays with netCDF4 alone.

The solver writes and reads files through this package only (tests/test_imports.py checks
the import graph). Importing any of its modules loads numpy and nothing heavier: xarray and
dask load inside the functions that build or check a dataset, netCDF4 inside those that touch
a file. This package imports nothing of grainview outside itself.
"""
