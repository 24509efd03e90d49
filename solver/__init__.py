"""A compact contact-dynamics solver for rigid disks and regular polygons between walls.

Moreau–Jean time stepping with a nonlinear Gauss–Seidel solution of Signorini's condition and
Coulomb's law (Jean 1999; Moreau 2004), polygon contacts by the shadow-overlap idea (simple
and double contacts), and the paper's protocol: geometric deposit, isotropic compaction,
biaxial compression, written as netCDF files of the grainview data contract.

    from solver import compaction_sample, isotropic_compaction, biaxial_test
    sim = compaction_sample(400, "pentagon")
    isotropic_compaction(sim)
    biaxial_test(sim, "biaxial.nc", strain=0.05)
"""

__version__ = "0.1.0"

from .scenes import (biaxial_test, compaction_sample, gravity_scene, is_equilibrium, isotropic_compaction,  # noqa: E402
                     wall_state)
from .stepper import Parameters, Simulation, StepInfo  # noqa: E402
from .walls import Walls  # noqa: E402


def __getattr__(name):
    """``load_sample`` and ``resume`` on first use (PEP 562): ``python -m solver.restart`` then
    runs the module once, not after ``import solver`` has imported it already."""
    if name in ("load_sample", "resume"):
        from . import restart

        return getattr(restart, name)
    raise AttributeError(f"module 'solver' has no attribute {name!r}")

__all__ = ["Simulation", "Parameters", "StepInfo", "Walls", "compaction_sample", "isotropic_compaction",
           "biaxial_test", "resume", "load_sample", "gravity_scene", "is_equilibrium", "wall_state", "__version__"]
