"""Declaring the core dimensions of a batched array function beside the function.

Every function of :mod:`grainview.analysis.arrays` works on the LAST axes of its arrays (one snapshot's
contacts, particles, a 2x2 tensor) and broadcasts over any leading ones (time). Which named
dimensions those last axes are is part of the function's definition, like the signature of a
numpy generalised ufunc ("(contact,xy),(contact)->(xy_a,xy_b)") or of an xgcm grid ufunc, so it
is declared here, once, with :func:`core_dims`; :func:`grainview.analysis._lift.apply` reads it when it
lifts the function to labelled arrays.
"""

from __future__ import annotations

CONTACT = ("contact",)
CONTACT_XY = ("contact", "xy")
PARTICLE = ("particle",)
SCALAR = ()
TENSOR = ("xy_a", "xy_b")
"""Dimension names of a 2x2 tensor (both with coordinates "x", "y")."""

SIZES = {"xy_a": 2, "xy_b": 2}
"""Sizes of the output dimensions that do not depend on the call's arguments."""


def core_dims(*inputs, out=(SCALAR,)):
    """Declare the core dimensions of each input and each output of the decorated function:
    ``@core_dims(CONTACT, CONTACT_XY, out=(TENSOR,))``. Sets ``func.core_dims`` and
    ``func.output_core_dims``; the function itself is unchanged."""
    def declare(func):
        func.core_dims = tuple(tuple(d) for d in inputs)
        func.output_core_dims = tuple(tuple(d) for d in out)
        return func
    return declare


__all__ = ["core_dims", "CONTACT", "CONTACT_XY", "PARTICLE", "SCALAR", "TENSOR", "SIZES"]
