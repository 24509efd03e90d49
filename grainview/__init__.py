"""grainview: force transmission in granular packings, lazily with xarray and dask.

Open a file of the data contract (docs/schema.md) and use the ``ds.grain`` accessor::

    import grainview
    ds = grainview.open_dataset("run.nc")          # lazy, chunked along time
    ds.grain.validate()
    ds.grain.stress_invariants()["q_over_p"].plot()

The formulas follow Azema, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007), with
the corrected forms of docs/conventions.md, as each function's docstring says.
"""

from . import accessor as _accessor  # noqa: F401  (registers ds.grain)
from .errors import ConvergenceWarning, FileFormatError, GrainviewError, ParameterError, SchemaError
from .io import open_dataset
from .schema import SCHEMA_VERSION, SnapshotWriter, make_dataset
from .validation import validate

__version__ = "0.1.0"

__all__ = [
    "open_dataset", "validate", "make_dataset", "SnapshotWriter", "SCHEMA_VERSION",
    "GrainviewError", "SchemaError", "FileFormatError", "ParameterError", "ConvergenceWarning",
    "__version__",
]
