"""Writers: a dataset's snapshots in the files other tools read (``grainview export``).

VTK for ParaView and OVITO (:mod:`~grainview.export.vtk`, through the XML writer
:mod:`~grainview.export.vtk_xml`) and the contact table as CSV for pandas and spreadsheets
(:mod:`~grainview.export.contacts_csv`). The room sits on the analysis (the exported fields and
force classes are its results), beside the figures; the readers of other codes' files
(:mod:`grainview.formats`) sit below it and write nothing but the contract.
"""

from __future__ import annotations

from ..analysis.snapshots import snapshot_indices
from ..contract.writer import write_atomically
from .contacts_csv import CSV_COLUMNS, KIND_NAMES, write_csv
from .vtk import VTK_BLOCKS, write_vtk

__all__ = ["write_vtk", "write_csv", "snapshot_indices", "write_atomically", "CSV_COLUMNS", "VTK_BLOCKS",
           "KIND_NAMES"]
