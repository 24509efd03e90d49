"""Scratch memory kept from one solve to the next.

A solve needs a few megabytes of working arrays (the Anderson history, the Delassus
diagonal, the domains' renumbered copies of the problem). Allocated afresh for every solve,
arrays of this size come from the operating system each time (the C allocator maps large
blocks directly and gives them back when freed), and touching their new pages costs more than
a sweep of a 4000-particle problem. The solvers therefore take them from a buffer that each
thread keeps, one per use, grown when a larger problem comes and never shrunk: with the default
Anderson memory m = 3, (4 m + 11) + 10 = 33 floats per contact point and (3 m + 3) + 7 = 19
per body of the largest problem solved so far (:func:`solver.acceleration.scratch_size`, and
the renumbered copies of :meth:`solver.parallel_nlgs.Decomposition.gather`), a quarter more
for growth; about 3 MB for 4000 dense pentagons.

The contents of a buffer are whatever the last user left: a solver writes every entry it reads.
Each thread has its own buffers, so simulations running in threads do not share them; within a
thread, a buffer's user must be done with it before the next call asks for the same one.
"""

from __future__ import annotations

import threading

import numpy as np

_local = threading.local()


def buffer(name: str, size: int) -> np.ndarray:
    """This thread's float64 scratch array ``name`` with at least ``size`` entries (contents
    undefined; module docstring). Grown by a quarter more than asked when too small."""
    buffers = getattr(_local, "buffers", None)
    if buffers is None:
        buffers = _local.buffers = {}
    size = int(size)
    found = buffers.get(name)
    if found is None or found.size < size:
        found = buffers[name] = np.empty(size + size // 4 + 64)
    return found
