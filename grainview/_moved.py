"""The modules' former names, still importable: ``import grainview.strain`` gives
:mod:`grainview.analysis.strain` (the same module object) with a ``DeprecationWarning`` naming
the new place.

grainview's modules live in rooms by concern (docs/map.md): the analysis in
``grainview/analysis/`` (its pure array functions in ``analysis/arrays/``, its numba kernels in
``analysis/_kernels/``), other formats in ``grainview/formats/``, the writers in
``grainview/export/``, the report and the command line in ``grainview/app/``, with the
application code that once sat in the solver (``solver.ensemble``, ``solver.paper_size``).
Scripts and notebooks written against a former layout keep working through the finder below,
which serves each former name by importing the module at its new place and registering that
module under the former name as well, so that both names give one module (its functions,
classes and state are shared, nothing is copied). The flat name ``grainview.export`` is now
the writers' room itself, which holds the former module's functions.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

MOVED = {
    **{f"grainview.{name}": f"grainview.analysis.{name}" for name in (
        "_kernels", "_lift", "arrays", "coarse_graining", "connectivity", "contacts", "ensemble", "fabric",
        "force_chains", "force_networks", "force_pdf", "forces", "lifetimes", "network_topology",
        "particle_fields", "persistence", "sample", "shear_bands", "strain", "stress", "tables", "xi_network")},
    **{f"grainview.{name}": f"grainview.app.{name}" for name in (
        "cli", "convergence", "ensemble_report", "file_summary", "report", "summary", "warmup")},
    "grainview.analysis.summary": "grainview.app.summary",
    "grainview.synthetic": "grainview.datasets",
    "grainview.analysis.synthetic": "grainview.datasets",
    "grainview.opening": "grainview.formats.opening",
    "grainview.vtk_xml": "grainview.export.vtk_xml",
    "grainview.formats.export": "grainview.export",
    "grainview.formats.vtk_xml": "grainview.export.vtk_xml",
    **{f"solver.{name}": f"grainview.app.{name}" for name in ("ensemble", "paper_size")},
}
"""Former module name -> its place now; a former package's submodules follow it."""


def new_name(name: str) -> str | None:
    """The present name of the former module ``name`` (None when ``name`` did not move)."""
    for old, new in MOVED.items():
        if name == old or name.startswith(old + "."):
            return new + name[len(old):]
    return None


class MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Serves the former names of :data:`MOVED` (module docstring)."""

    def find_spec(self, fullname, path=None, target=None):
        if new_name(fullname) is None:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        return None  # a placeholder, replaced in sys.modules by the real module in exec_module

    def exec_module(self, module):
        new = new_name(module.__name__)
        warnings.warn(f"{module.__name__} is now {new}: import it from there", DeprecationWarning, stacklevel=2)
        sys.modules[module.__name__] = importlib.import_module(new)


def install():
    """Put the finder first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, MovedModules) for f in sys.meta_path):
        sys.meta_path.insert(0, MovedModules())
