"""grainview: force transmission in granular packings, lazily with xarray and dask.

Open a file of the data contract (docs/schema.md) and use the ``ds.grain`` accessor::

    import grainview
    ds = grainview.open_dataset("run.nc")          # lazy, chunked along time
    ds.grain.validate()
    ds.grain.stress_invariants()["q_over_p"].plot()

The formulas follow Azema, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007), with
the corrected forms of docs/conventions.md, as each function's docstring says.

Importing the package is light: the contract and the error types load at once; xarray, dask
and the analyses load when first used (``open_dataset`` and friends are imported on first
access, and ``ds.grain`` is registered as soon as xarray is imported, :mod:`grainview._register`),
so that the solver, which writes files of the contract, does not load them.
"""

import importlib
import os

# Numba's vectorised loops may call Intel's SVML (when the icc_rt library is installed), whose
# results depend on the processor; the solver and analyses must not (docs/reproducibility.md).
# Effective when numba is first imported after grainview, as the solver does.
os.environ.setdefault("NUMBA_DISABLE_INTEL_SVML", "1")

from . import _moved, _register
from .contract.errors import ConvergenceWarning, FileFormatError, GrainviewError, OutputError, ParameterError, SchemaError
from .contract.schema import SCHEMA_VERSION

__version__ = "0.1.0"

_LAZY = {"open_dataset": "formats.opening", "validate": "contract.validation", "make_dataset": "contract.dataset",
         "SnapshotWriter": "contract.writer",
         "open_ensemble": "analysis.ensemble"}
"""Public names imported from their module on first access (PEP 562)."""

__all__ = [
    "open_dataset", "open_ensemble", "validate", "make_dataset", "SnapshotWriter", "SCHEMA_VERSION",
    "GrainviewError", "SchemaError", "FileFormatError", "OutputError", "ParameterError", "ConvergenceWarning",
    "__version__",
]

_register.register()
_moved.install()  # the modules' former names (grainview.strain, ...) still import


def __getattr__(name):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
