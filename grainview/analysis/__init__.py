"""The analysis: what a force-transmission study computes from a dataset of the contract.

Three layers, one above the other:

1. :mod:`grainview.analysis.arrays` (numba kernels in :mod:`grainview.analysis._kernels`): the
   physics on plain numpy arrays, batched over time, each function declaring its core dimensions;
2. the topic modules (:mod:`~grainview.analysis.stress`, :mod:`~grainview.analysis.fabric`,
   :mod:`~grainview.analysis.forces`, ...): the same on labelled, lazy DataArrays, lifted once by
   :mod:`grainview.analysis._lift`;
3. the ``ds.grain`` accessor (:mod:`grainview.accessor`), which delegates to the topic modules.

This room imports only the data contract (:mod:`grainview.contract`); the exports, the figures
and the application build on it (``tests/test_imports.py`` checks the drawing), and it never
calls the accessor, which sits above it.
"""
